// Exact answers of the analytic scenes (scenes/README.md), and the comparison of a render's
// pixels and bounds against them. Shared by the tests and the bounds study tool.
#pragma once

#include "photonbound/driver.h"
#include "photonbound/film.h"
#include "photonbound/gltf_loader.h"
#include "photonbound/renderer.h"
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
  std::function<double(const vec3&)> exact;  // pixel radiance at the pixel's measurement point
};

inline Case by_name(const std::string& name) {
  if (name == "plane") return {"plane_point.gltf", plane_point};
  if (name == "box") return {"closed_box.gltf", closed_box};
  if (name == "glossy") return {"glossy_plane.gltf", glossy_plane};
  throw std::invalid_argument("no analytic scene named " + name);
}

// The exact value of a pixel: PPM's at its measurement point; SPPM's, the average over the
// pixel's area (its box filter), by 8 x 8 camera rays onto the plane y = 0 (the plane scenes).
inline double pixel_exact(const Renderer& r, size_t pixel,
                          const std::function<double(const vec3&)>& exact) {
  if (r.options().method == Method::PPM)
    return exact(r.eye().points[r.eye().pixel_begin[pixel]].position);
  const PinholeCamera cam = choose_camera(r.world().scene(), r.options());
  const float x = float(pixel % size_t(cam.width())), y = float(pixel / size_t(cam.width()));
  double sum = 0.0;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const vec3 d = cam.direction(x + (i + 0.5f) / 8, y + (j + 0.5f) / 8);
      sum += exact(cam.origin() - (cam.origin().y / d.y) * d);
    }
  return sum / 64.0;
}

// Actual error and coverage of a render against the exact answer, over pixel-channels with a
// known, nonzero bound (each of these scenes has one measurement point per pixel).
struct Accuracy {
  double mean_abs_error = 0.0;  // mean over pixels and channels of |L - L_exact|
  double mean_bound = 0.0;      // mean over the same of the bound
  double coverage = 0.0;        // fraction with |L - L_exact| <= bound
  size_t samples = 0;
};

inline Accuracy measure(const Renderer& r, const std::function<double(const vec3&)>& exact,
                        double confidence) {
  FilmSettings s = r.film_settings();
  s.confidence = confidence;
  FilmImage img;
  develop(r.layout(), r.states(), r.passes(), s, &img);
  Accuracy a;
  double err_sum = 0.0, bound_sum = 0.0;
  size_t covered = 0;
  const size_t pixels = size_t(r.eye().width) * size_t(r.eye().height);
  const bool ppm = r.options().method == Method::PPM;
  for (size_t p = 0; p < pixels; ++p) {
    if (ppm && r.eye().pixel_begin[p] == r.eye().pixel_begin[p + 1]) continue;  // exact pixel
    const double truth = pixel_exact(r, p, exact);
    for (int c = 0; c < 3; ++c) {
      const double bound = img.bound[3 * p + size_t(c)];
      if (!std::isfinite(bound)) continue;
      const double err = std::fabs(double(img.radiance[3 * p + size_t(c)]) - truth);
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
  std::vector<CoverageRow> rows;
  for (uint64_t n : checkpoints) {
    while (r.passes() < n) r.step();
    for (double c : confidences) rows.push_back({name, n, c, measure(r, sc.exact, c)});
  }
  return rows;
}

// One render to a target error: what it promised and what it achieved.
struct TerminationRow {
  double target = 0.0;
  double confidence = 0.0;
  uint64_t passes = 0;
  double seconds = 0.0;
  double mean_bound = 0.0;  // the renderer's own image mean bound at the stop
  double actual = 0.0;      // mean over pixels and channels of |L - L_exact|
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
  develop(r.eye(), r.states(), r.passes(), r.film_settings(), &img);
  double sum = 0.0;
  size_t n = 0;
  for (size_t p = 0; p + 1 < r.eye().pixel_begin.size(); ++p) {
    const uint32_t k = r.eye().pixel_begin[p];
    if (k == r.eye().pixel_begin[p + 1]) continue;
    const double truth = sc.exact(r.eye().points[k].position);
    for (int c = 0; c < 3; ++c) sum += std::fabs(double(img.radiance[3 * p + size_t(c)]) - truth);
    n += 3;
  }
  row.actual = n ? sum / double(n) : 0.0;
  return row;
}

}  // namespace pb::analytic
