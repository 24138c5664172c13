// Next-event estimation at a visible point (ESTIMATOR.md section 4): one light sample and one
// shadow ray per point and pass, used by the camera paths (camera_paths.h) and the pass stages
// (pass_stages.h) alike.
#pragma once

#include "render/camera_pass.h"
#include "util/rng.h"
#include "world/world.h"

namespace pb {

// One light sample with a shadow ray: D_j = f Li cos / pdf (ESTIMATOR.md section 4); with
// `glossy`, f = point.f x f(wo, wi_light).
// The other strategy of multiple importance sampling for the environment's part of the direct
// light (next_event.cpp): directions drawn from `bsdf` (seen from wo) with `share` x its pdf().
// With `draw`, direct_light draws one itself (a gather point); without, the caller's path is that
// draw (a followed lobe: camera_paths.cpp weighs what it finds of the environment).
struct EnvironmentMis {
  const Bsdf* bsdf = nullptr;
  vec3 wo{0.0f};
  float share = 1.0f;
  bool draw = true;
  float density(const vec3& wi) const { return share * bsdf->pdf(wo, wi); }
};
// Lobes below this roughness take the environment's light by multiple importance sampling.
inline constexpr float kMisRoughness = 0.7f;
// Whether the draws of `draws` (a whole Bsdf, or SPPM's followed part of `whole`) may be the
// environment's other strategy: its pdf() describes them (no delta branch, nothing through the
// surface), `whole` has a lobe below kMisRoughness, and there is an environment.
bool environment_mis_applies(const World& world, const Bsdf& draws, const Bsdf& whole);
// One light sample with a shadow ray; with `mis`, an environment sample keeps the balance
// heuristic's share p_l / (p_l + p_b) of the part of f that mis->bsdf is (all of f for a gather
// point, the followed lobe's part at a followed lobe).
dvec3 direct_light(const World& world, const VisiblePoint& point, const PointBsdf* glossy, Rng& rng,
                   const EnvironmentMis* mis);
inline dvec3 direct_light(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                          Rng& rng) {
  return direct_light(world, point, glossy, rng, nullptr);
}
inline dvec3 direct_light(const World& world, const VisiblePoint& point, Rng& rng) {
  return direct_light(world, point, nullptr, rng, nullptr);
}
// A sample's shadow ray and the light it brings where nothing blocks the ray (traced false: the
// segment is empty, and the value counts).
struct ShadowTest {
  Accel::Ray ray;
  dvec3 value{0.0};
  bool traced = true;
};
inline constexpr int kMaxShadowTests = 2;  // the light sample and the environment's MIS draw
// direct_light up to its shadow rays: its samples' tests, in order (returns how many, at most
// kMaxShadowTests). The direct light is the sum, in order, of the values of those not blocked
// (shadow_sum), so the tests of many points may be traced together (next_event_pass).
int direct_light_tests(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                       Rng& rng, const EnvironmentMis* mis, ShadowTest* tests);
// The sum of tests[i].value over the tests not blocked (blocked null: each traced alone).
dvec3 shadow_sum(const World& world, const ShadowTest* tests, int n, const bool* blocked = nullptr);
// One light sample through the surface at s (Bsdf::eval_transmission: diffuse transmission, and
// rough glass with `glass`), seen from wo, from the other side, times the path weight.
dvec3 direct_light_through(const World& world, const Surface& s, const vec3& wo, const vec3& weight,
                           bool glass, Rng& rng);

}  // namespace pb
