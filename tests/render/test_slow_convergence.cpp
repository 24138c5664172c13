// Convergence to exact answers on the analytic scenes (issue 2 "Done when"). Labelled slow.
#include "render_fixture.h"

#include <gtest/gtest.h>

namespace pb {
namespace {

// Diffuse plane (rho = 0.5) under a point light of intensity 10 at height 1:
// L = rho/pi I cos(theta) / d^2 = 5 / (pi d^3) (scenes/README.md).
double plane_exact(const vec3& p) {
  const double d = std::sqrt(double(p.x) * p.x + 1.0 + double(p.z) * p.z);
  return 5.0 / (kPiD * d * d * d);
}

TEST(SlowConvergence, AnalyticPlaneWithPhotonsOnly) {
  RenderOptions o = test::quick_options("plane_point.gltf", 64, 1);
  o.direct = DirectMode::Photons;
  const Scene scene = load_gltf(o.scene);
  Renderer r(scene, o);
  auto all = [](const vec3&) { return true; };
  // Run 16, 64, 256 passes in one render by asking for the error along the way.
  std::vector<double> errors;
  for (uint64_t target : {16u, 64u, 256u}) {
    while (r.passes() < target) r.step();
    errors.push_back(test::mean_relative_error(r, r.passes(), plane_exact, all));
  }
  std::printf("plane: mean relative error at 16/64/256 passes: %.4f %.4f %.4f\n", errors[0],
              errors[1], errors[2]);
  EXPECT_LT(errors[2], 0.02);
  // The error must fall as passes grow (noise ~ i^(-1/3) or faster at alpha = 0.7).
  EXPECT_LT(errors[1], errors[0]);
  EXPECT_LT(errors[2], errors[1]);
}

// Closed box whose walls emit Le = 1 and reflect rho = 0.5: L = Le / (1 - rho) = 2 inside.
// Interior: points at least 0.1 from every edge of the wall they lie on.
double closed_box_error(DirectMode mode, uint64_t passes, uint64_t photons_per_pass) {
  RenderOptions o = test::quick_options("closed_box.gltf", 64, passes);
  o.direct = mode;
  o.photons_per_pass = photons_per_pass;
  const Scene scene = load_gltf(o.scene);
  Renderer r(scene, o);
  auto interior = [](const vec3& p) {
    int near_face = 0;
    for (int c = 0; c < 3; ++c) near_face += std::fabs(p[c]) > 0.9f;
    return near_face == 1;
  };
  while (r.passes() < passes) r.step();
  return test::mean_relative_error(
      r, r.passes(), [](const vec3&) { return 2.0; }, interior);
}

TEST(SlowConvergence, ClosedEmittingBoxWithPhotonsOnly) {
  const double err = closed_box_error(DirectMode::Photons, 256, 100000);
  std::printf("closed box, photons only, 256 passes: mean relative error %.4f\n", err);
  EXPECT_LT(err, 0.02);
}

TEST(SlowConvergence, ClosedEmittingBoxWithNextEvent) {
  const double err = closed_box_error(DirectMode::NextEvent, 256, 100000);
  std::printf("closed box, next-event, 256 passes: mean relative error %.4f\n", err);
  EXPECT_LT(err, 0.02);
}

}  // namespace
}  // namespace pb
