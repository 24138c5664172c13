// Exact answers of the analytic scenes (scenes/README.md), and the comparison of a render's
// pixels and bounds against them. Shared by the tests and the bounds study tool.
#pragma once

#include "app/driver.h"
#include "estimator/film.h"
#include "gltf/gltf_loader.h"
#include "render/renderer.h"
#include "render_fixture.h"

#include <cmath>
#include <functional>
#include <string>

namespace pb::analytic {

// Diffuse plane (rho = 0.5) under a point light of intensity 10 at height 1:
// L = rho/pi I cos(theta) / d^2 = 5 / (pi d^3).
inline double plane_point(const vec3& p) {
  const double d = std::sqrt(double(p.x) * p.x + 1.0 + double(p.z) * p.z);
  return 5.0 / (kPiD * d * d * d);
}

// Closed box whose walls emit Le = 1 and reflect rho = 0.5: L = Le / (1 - rho) = 2 inside.
inline double closed_box(const vec3&) { return 2.0; }

// glossy_plane.gltf: the plane under the same light with glTF's metallic-roughness BRDF (base
// colour 0.6, metallic 0.5, roughness 0.4, ior 1.5), seen from the camera at (0, 3, 0):
// L = f(wo, wi) I cos(theta) / d^2, f glTF appendix B written out here in double.
inline double glossy_plane(const vec3& p) {
  const dvec3 x(p), n(0, 1, 0);
  const dvec3 v = glm::normalize(dvec3(0, 3, 0) - x), to = dvec3(0, 1, 0) - x;
  const double d2 = glm::dot(to, to);
  const dvec3 l = to / std::sqrt(d2), h = glm::normalize(v + l);
  const double base = 0.6, metallic = 0.5, a = 0.4 * 0.4, a2 = a * a;
  const double nh = glm::dot(n, h), nl = glm::dot(n, l), nv = glm::dot(n, v);
  const double d = a2 / (kPiD * std::pow(nh * nh * (a2 - 1) + 1, 2));
  const double vis =
      1 / (2 * (nv * std::sqrt(a2 + (1 - a2) * nl * nl) + nl * std::sqrt(a2 + (1 - a2) * nv * nv)));
  const double w = std::pow(1 - std::fabs(glm::dot(v, h)), 5), fd = 0.04 + 0.96 * w;
  const double dielectric = (1 - fd) * base / kPiD + fd * d * vis;
  const double metal = (base + (1 - base) * w) * d * vis;
  return ((1 - metallic) * dielectric + metallic * metal) * 10.0 * nl / d2;
}

struct Case {
  std::string file;
  std::function<double(const vec3&)> exact;  // pixel radiance at the pixel's visible point
};

inline Case by_name(const std::string& name) {
  if (name == "plane") return {"plane_point.gltf", plane_point};
  if (name == "box") return {"closed_box.gltf", closed_box};
  if (name == "block") return {"closed_block.gltf", closed_box};  // a furnace too: L = 2
  if (name == "glossy") return {"glossy_plane.gltf", glossy_plane};
  throw std::invalid_argument("no analytic scene named " + name);
}

// Actual error and coverage of a render against the exact answer, over pixel-channels with a
// known, nonzero bound (each of these scenes has one visible point per pixel).
struct Accuracy {
  double mean_abs_error = 0.0;  // mean over pixels and channels of |L - L_exact|
  double mean_bound = 0.0;      // mean over the same of the bound
  double coverage = 0.0;        // fraction with |L - L_exact| <= bound
  size_t samples = 0;
};

// The exact value of every pixel, what the render estimates: PPM, the exact answer at the
// pixel's (first) visible point (NaN without one: an exact pixel); SPPM, the average of the
// exact answer over the pixel's area (ESTIMATOR.md section 10), from sub x sub stratified
// camera rays (0 where a ray misses: black background).
inline std::vector<double> pixel_truth(const Renderer& r,
                                       const std::function<double(const vec3&)>& exact,
                                       int sub = 16) {
  const CameraPassResult& eye = r.camera_pass();
  const size_t pixels = size_t(eye.width) * size_t(eye.height);
  std::vector<double> truth(pixels, std::nan(""));
  if (r.options().method == Method::PPM) {
    for (size_t p = 0; p < pixels; ++p)
      if (eye.pixel_begin[p] != eye.pixel_begin[p + 1])
        truth[p] = exact(eye.points[eye.pixel_begin[p]].position);
    return truth;
  }
  for (size_t p = 0; p < pixels; ++p) {
    const int x = int(p % size_t(eye.width)), y = int(p / size_t(eye.width));
    double sum = 0.0;
    for (int j = 0; j < sub; ++j)
      for (int i = 0; i < sub; ++i) {
        const vec3 d = r.camera().direction(float(x) + (float(i) + 0.5f) / float(sub),
                                            float(y) + (float(j) + 0.5f) / float(sub));
        Hit hit;
        if (r.world().accel().intersect(r.camera().origin(), d, 0.0f, INFINITY, hit))
          sum += exact(r.world().surface(hit).position);
      }
    truth[p] = sum / double(sub * sub);
  }
  return truth;
}

// For scenes made of axis-aligned boxes (the closed box, and the block inside it): per pixel,
// whether the surface at the pixel centre lies within `radii` current search radii of an edge of
// a box, every mesh being one box (1), farther (0), or the centre ray misses (-1). The radius is
// the pixel's (SPPM) or its first point's (PPM) at the time of the call.
inline std::vector<int> box_edge_band(const Renderer& r, double radii) {
  const CameraPassResult& eye = r.camera_pass();
  const size_t pixels = size_t(eye.width) * size_t(eye.height);
  std::vector<std::pair<dvec3, dvec3>> edges;  // the 12 edges of each mesh's bounds
  for (const Mesh& m : r.world().scene().meshes) {
    Bounds b;
    for (const vec3& v : m.positions) b.extend(v);
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < 4; ++k) {
        dvec3 p0(b.lo), p1(b.lo);
        const int u = (a + 1) % 3, v = (a + 2) % 3;
        p0[u] = p1[u] = (k & 1) ? b.hi[u] : b.lo[u];
        p0[v] = p1[v] = (k & 2) ? b.hi[v] : b.lo[v];
        p1[a] = b.hi[a];
        edges.emplace_back(p0, p1);
      }
  }
  std::vector<int> band(pixels, -1);
  for (size_t p = 0; p < pixels; ++p) {
    const size_t state = r.options().method == Method::PPM ? size_t(eye.pixel_begin[p]) : p;
    if (state >= r.states().size() || eye.pixel_begin[p] == eye.pixel_begin[p + 1]) continue;
    const int x = int(p % size_t(eye.width)), y = int(p / size_t(eye.width));
    Hit hit;
    if (!r.world().accel().intersect(r.camera().origin(),
                                     r.camera().direction(float(x) + 0.5f, float(y) + 0.5f), 0.0f,
                                     INFINITY, hit))
      continue;
    const dvec3 q(r.world().surface(hit).position);
    double d2 = INFINITY;
    for (const auto& [a, b] : edges) {
      const dvec3 e = b - a;
      const double t = std::clamp(glm::dot(q - a, e) / glm::dot(e, e), 0.0, 1.0);
      const dvec3 c = a + t * e - q;
      d2 = std::min(d2, glm::dot(c, c));
    }
    const double reach = radii * std::sqrt(r.states()[state].r2);
    band[p] = d2 < reach * reach ? 1 : 0;
  }
  return band;
}

// Actual error and coverage against per-pixel exact values (pixel_truth), over pixel-channels
// with a known bound; with `band`, only the pixels whose band value is `want`.
inline Accuracy measure(const Renderer& r, const std::vector<double>& truth, double confidence,
                        const std::vector<int>* band = nullptr, int want = 1) {
  FilmSettings s = r.film_settings();
  s.confidence = confidence;
  FilmImage img;
  develop(r.layout(), r.states(), r.passes(), s, &img);
  Accuracy a;
  double err_sum = 0.0, bound_sum = 0.0;
  size_t covered = 0;
  for (size_t p = 0; p < truth.size(); ++p) {
    if (std::isnan(truth[p])) continue;  // no visible point: exact pixel
    if (band && (*band)[p] != want) continue;
    for (int c = 0; c < 3; ++c) {
      const double bound = img.bound[3 * p + size_t(c)];
      if (!std::isfinite(bound)) continue;
      const double err = std::fabs(double(img.radiance[3 * p + size_t(c)]) - truth[p]);
      err_sum += err;
      bound_sum += bound;
      covered += err <= bound;
      ++a.samples;
    }
  }
  if (a.samples) {
    a.mean_abs_error = err_sum / double(a.samples);
    a.mean_bound = bound_sum / double(a.samples);
    a.coverage = double(covered) / double(a.samples);
  }
  return a;
}

inline Accuracy measure(const Renderer& r, const std::function<double(const vec3&)>& exact,
                        double confidence) {
  return measure(r, pixel_truth(r, exact), confidence);
}

}  // namespace pb::analytic

namespace pb::analytic {

// Renders `scene` with the given options and reports the accuracy at each pass count of
// `checkpoints` (ascending), at each confidence.
struct CoverageRow {
  std::string scene;
  uint64_t passes = 0;
  double confidence = 0.0;
  Accuracy accuracy;
};

inline std::vector<CoverageRow> coverage_run(const std::string& name, RenderOptions o,
                                             const std::vector<uint64_t>& checkpoints,
                                             const std::vector<double>& confidences) {
  const Case sc = by_name(name);
  const pb::Scene scene = load_gltf(o.scene);
  Renderer r(scene, o);
  const std::vector<double> truth = pixel_truth(r, sc.exact);
  std::vector<CoverageRow> rows;
  for (uint64_t n : checkpoints) {
    while (r.passes() < n) r.step();
    for (double c : confidences) rows.push_back({name, n, c, measure(r, truth, c)});
  }
  return rows;
}

// One render to a target error: what it promised and what it achieved.
struct TerminationRow {
  double target = 0.0;
  double confidence = 0.0;
  uint64_t passes = 0;
  double seconds = 0.0;
  double mean_bound = 0.0;     // the renderer's own image mean bound at the stop
  double actual = 0.0;         // mean over pixels and channels of |L - L_exact|
  double pixels_within = 0.0;  // share of pixels whose every channel is within the target
  std::string stop_reason;
};

inline TerminationRow termination_run(const std::string& name, RenderOptions o) {
  const Case sc = by_name(name);
  const pb::Scene scene = load_gltf(o.scene);
  Renderer r(scene, o);
  const RenderReport report = test::run_to_stop(r);
  TerminationRow row;
  row.target = o.target_error.value_or(0.0);
  row.confidence = o.confidence;
  row.passes = report.work.passes;
  row.seconds = report.seconds;
  row.mean_bound = report.summary.mean_bound;
  row.stop_reason = stop_text(report.stop);
  FilmImage img;
  r.develop(&img);
  const std::vector<double> truth = pixel_truth(r, sc.exact);
  double sum = 0.0;
  size_t n = 0, within = 0;
  for (size_t p = 0; p < truth.size(); ++p) {
    if (std::isnan(truth[p])) continue;
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double e = std::fabs(double(img.radiance[3 * p + size_t(c)]) - truth[p]);
      sum += e;
      worst = std::max(worst, e);
    }
    within += worst <= row.target;
    n += 3;
  }
  row.actual = n ? sum / double(n) : 0.0;
  row.pixels_within = n ? double(within) / double(n / 3) : 0.0;
  return row;
}

}  // namespace pb::analytic
