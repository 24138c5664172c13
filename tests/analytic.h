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

struct Case {
  std::string file;
  std::function<double(const vec3&)> exact;  // pixel radiance at the pixel's measurement point
};

inline Case by_name(const std::string& name) {
  if (name == "plane") return {"plane_point.gltf", plane_point};
  if (name == "box") return {"closed_box.gltf", closed_box};
  throw std::invalid_argument("no analytic scene named " + name);
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
  develop(r.eye(), r.states(), r.passes(), s, &img);
  Accuracy a;
  double err_sum = 0.0, bound_sum = 0.0;
  size_t covered = 0;
  for (size_t p = 0; p + 1 < r.eye().pixel_begin.size(); ++p) {
    const uint32_t k = r.eye().pixel_begin[p];
    if (k == r.eye().pixel_begin[p + 1]) continue;  // no measurement point: exact pixel
    const double truth = exact(r.eye().points[k].position);
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
