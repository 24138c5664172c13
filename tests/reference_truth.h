// A rendered reference as the truth of scenes without an exact answer (the Cornell box): its
// radiance and the variance of its own estimate, read from the EXR photonbound wrote, and the
// accuracy of a render's pixels and bounds against it. Shared by the slow tests and the bounds
// study tool; analytic.h is the same for the scenes with an exact answer.
#pragma once

#include "estimator/error_model.h"
#include "estimator/film.h"
#include "gltf/gltf_loader.h"
#include "io/image_io.h"
#include "render/camera_pass.h"
#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb::reference {

struct Truth {
  int width = 0, height = 0;
  std::vector<double> value;     // 3 per pixel: the reference's radiance
  std::vector<double> variance;  // 3 per pixel: the variance of its mean (its noise, squared)
};

inline Truth load(const std::string& path) {
  const ExrImage img = read_exr(path);
  const char* names[] = {"R", "G", "B", "Variance.R", "Variance.G", "Variance.B"};
  int at[6];
  for (int k = 0; k < 6; ++k)
    if ((at[k] = img.channel_index(names[k])) < 0)
      throw std::runtime_error(path + ": no channel " + names[k]);
  Truth t;
  t.width = img.width;
  t.height = img.height;
  const size_t pixels = size_t(img.width) * size_t(img.height), stride = img.channels.size();
  t.value.resize(3 * pixels);
  t.variance.resize(3 * pixels);
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) {
      t.value[3 * p + size_t(c)] = img.pixels[p * stride + size_t(at[c])];
      t.variance[3 * p + size_t(c)] = img.pixels[p * stride + size_t(at[3 + c])];
    }
  return t;
}

// Per pixel, whether the surface its pixel-centre camera path ends on (the first non-delta hit,
// through mirrors and glass as the camera pass follows them) lies within `radii` current search
// radii of a place where that surface ends for the gather (BoundaryIndex: its border edges,
// creases, and geometry rising through it): 1 within, 0 farther, -1 without such a point.
// Distances reach at most the initial radius, the farthest the index looks.
inline std::vector<int> edge_band(const Renderer& r, double radii) {
  const bool ppm = r.options().method == Method::PPM;
  const CameraPassResult eye_sppm =
      ppm ? CameraPassResult{} : run_camera_pass(r.world(), r.camera(), r.options().max_depth);
  const CameraPassResult& eye = ppm ? r.camera_pass() : eye_sppm;
  const size_t pixels = size_t(eye.width) * size_t(eye.height);
  const double r0 = r.initial_radius();
  std::vector<int> band(pixels, -1);
  for (size_t p = 0; p < pixels; ++p) {
    if (eye.pixel_begin[p] == eye.pixel_begin[p + 1]) continue;
    const VisiblePoint& m = eye.points[eye.pixel_begin[p]];
    const size_t state = ppm ? size_t(eye.pixel_begin[p]) : p;
    const float reach = float(std::min(radii * std::sqrt(r.states()[state].r2), r0));
    band[p] = r.boundary().clearance(m.triangle, m.position, reach) < reach ? 1 : 0;
  }
  return band;
}

struct Accuracy {
  double mean_abs_error = 0.0;     // mean over pixel-channels of |L - L_reference|
  double mean_rel_error = 0.0;     // of |L - L_ref| / max(L_ref, 0.01): brightness aside
  double mean_signed_error = 0.0;  // of L - L_ref: below 0 where the image is darker
  double mean_bound = 0.0;         // mean over the same of the render's bound
  double coverage = 0.0;           // fraction with |L - L_reference| <= bound
  // The same with the reference's own noise counted: |L - L_ref| <= sqrt(bound^2 + (z sigma)^2),
  // sigma^2 the reference's Variance and z the two-sided normal quantile of the confidence (the
  // half-width its noise needs at that confidence, both errors near normal and independent).
  double coverage_with_reference_noise = 0.0;
  size_t samples = 0;
};

// Over pixel-channels with a finite bound; with `band`, only the pixels whose band is `want`.
inline Accuracy measure(const Renderer& r, const Truth& truth, double confidence,
                        const std::vector<int>* band = nullptr, int want = 1) {
  FilmSettings s = r.film_settings();
  s.confidence = confidence;
  FilmImage img;
  develop(r.layout(), r.states(), r.passes(), s, &img);
  if (size_t(truth.width) * size_t(truth.height) * 3 != img.radiance.size())
    throw std::runtime_error("the reference's size is not the render's");
  const double z = normal_quantile(0.5 + 0.5 * confidence);
  Accuracy a;
  double err_sum = 0.0, rel_sum = 0.0, signed_sum = 0.0, bound_sum = 0.0, covered = 0.0,
         covered_ref = 0.0;
  for (size_t k = 0; k < img.radiance.size(); ++k) {
    if (band && (*band)[k / 3] != want) continue;
    const double bound = img.bound[k];
    if (!std::isfinite(bound)) continue;
    const double err = std::fabs(double(img.radiance[k]) - truth.value[k]);
    const double widened = std::sqrt(bound * bound + z * z * truth.variance[k]);
    err_sum += err;
    rel_sum += err / std::max(truth.value[k], 0.01);
    signed_sum += double(img.radiance[k]) - truth.value[k];
    bound_sum += bound;
    covered += err <= bound;
    covered_ref += err <= widened;
    ++a.samples;
  }
  if (a.samples) {
    const double n = double(a.samples);
    a.mean_abs_error = err_sum / n;
    a.mean_rel_error = rel_sum / n;
    a.mean_signed_error = signed_sum / n;
    a.mean_bound = bound_sum / n;
    a.coverage = covered / n;
    a.coverage_with_reference_noise = covered_ref / n;
  }
  return a;
}

// Sums of the above over renders: for each pass count, band (0 every pixel, 1 the edge band, 2
// the interior; edge_band(r, 2)) and confidence, the accuracy figures times their samples.
struct Sums {
  double err = 0, rel = 0, sgn = 0, bound = 0, covered = 0, covered_ref = 0, n = 0;
  void add(const Accuracy& a) {
    const double m = double(a.samples);
    err += a.mean_abs_error * m;
    rel += a.mean_rel_error * m;
    sgn += a.mean_signed_error * m;
    bound += a.mean_bound * m;
    covered += a.coverage * m;
    covered_ref += a.coverage_with_reference_noise * m;
    n += m;
  }
  double mean(double Sums::*field) const { return this->*field / std::max(n, 1.0); }
};
struct PooledCoverage {
  std::vector<uint64_t> checks;
  std::vector<double> confidences;
  std::vector<Sums> sums;  // [check][band][confidence]
  Sums& at(size_t check, int band, size_t confidence) {
    return sums[(check * 3 + size_t(band)) * confidences.size() + confidence];
  }
};
// Renders `o` with seeds 1..seeds to each of `checks` (ascending) and pools the accuracy there.
inline PooledCoverage pooled_coverage(RenderOptions o, int seeds, const Truth& truth,
                                      const std::vector<uint64_t>& checks,
                                      const std::vector<double>& confidences) {
  PooledCoverage p{checks, confidences, std::vector<Sums>(checks.size() * 3 * confidences.size())};
  const pb::Scene scene = load_gltf(o.scene);
  for (int seed = 1; seed <= seeds; ++seed) {
    o.seed = uint64_t(seed);
    Renderer r(scene, o);
    for (size_t ci = 0; ci < checks.size(); ++ci) {
      while (r.passes() < checks[ci]) r.step();
      const std::vector<int> band = edge_band(r, 2.0);
      for (int bi = 0; bi < 3; ++bi)
        for (size_t k = 0; k < confidences.size(); ++k)
          p.at(ci, bi, k).add(bi == 0 ? measure(r, truth, confidences[k])
                                      : measure(r, truth, confidences[k], &band, bi == 1 ? 1 : 0));
    }
  }
  return p;
}

}  // namespace pb::reference
