// Shared helpers for tests that render the shipped scenes in-process.
#pragma once

#include "app/driver.h"
#include "gltf/gltf_loader.h"
#include "render/renderer.h"

#include <string>

namespace pb::test {

inline std::string scene_path(const std::string& name) {
  return std::string(PHOTONBOUND_SCENES) + "/" + name;
}

// Runs the render to its stop conditions, as photonbound does (Driver, no observers).
inline RenderReport run_to_stop(Renderer& r, const DriverState& state = {}) {
  return Driver(r, state).run();
}

// PPM, whose visible points the tests written for it inspect; SPPM tests set the method.
inline RenderOptions quick_options(const std::string& scene, int size, uint64_t passes) {
  RenderOptions o;
  o.method = Method::PPM;
  o.scene = scene_path(scene);
  o.output = "unused.exr";
  o.width = size;
  o.height = size;
  o.passes = passes;
  o.progress = ProgressMode::Never;
  return o;
}

// Mean over the visible points of |L - L_exact| / L_exact, for points accepted by `use`.
// exact(position) gives the analytic radiance (grey: all channels equal).
template <class Exact, class Use>
double mean_relative_error(const Renderer& r, uint64_t passes, Exact&& exact, Use&& use) {
  double sum = 0.0;
  size_t n = 0;
  const FilmSettings s = r.film_settings();
  const CameraPassResult& eye = r.camera_pass();
  for (size_t pixel = 0; pixel + 1 < eye.pixel_begin.size(); ++pixel) {
    for (uint32_t k = eye.pixel_begin[pixel]; k < eye.pixel_begin[pixel + 1]; ++k) {
      const VisiblePoint& p = eye.points[k];
      if (!use(p.position)) continue;
      const double truth = exact(p.position);
      // The point's estimate carries its camera-path weight (VisiblePoint::f).
      const dvec3 l =
          eye.emission[pixel] + estimate(r.states()[k], passes, s.photons_per_pass).radiance;
      for (int c = 0; c < 3; ++c) sum += std::fabs(l[c] - truth) / truth;
      n += 3;
    }
  }
  return n ? sum / double(n) : INFINITY;
}

}  // namespace pb::test
