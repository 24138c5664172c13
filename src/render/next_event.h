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
dvec3 direct_light(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                   Rng& rng);
inline dvec3 direct_light(const World& world, const VisiblePoint& point, Rng& rng) {
  return direct_light(world, point, nullptr, rng);
}
// One light sample through the surface at s (Bsdf::eval_transmission: diffuse transmission, and
// rough glass with `glass`), seen from wo, from the other side, times the path weight.
dvec3 direct_light_through(const World& world, const Surface& s, const vec3& wo, const vec3& weight,
                           bool glass, Rng& rng);

}  // namespace pb
