// SPPM's camera stage (ESTIMATOR.md section 10): every pass, one camera path per pixel through
// a uniformly jittered point of the pixel (box filter: the pixel estimates the average radiance
// over its area), keyed by (seed, pass, pixel). At a mirror or dielectric the path continues
// along one branch, chosen in proportion to its throughput and divided by that probability;
// the visible point is the first non-delta hit. Where a surface has both (a smooth coat over a
// diffuse base) the path stops there with Bsdf::delta_probability's complement, and both
// choices are divided by their probability.
#pragma once

#include "photonbound/camera.h"
#include "photonbound/estimator.h"
#include "photonbound/eye_pass.h"
#include "photonbound/world.h"

#include <cstdint>
#include <span>

namespace pb {

struct CameraPathInputs {
  const World& world;
  const PinholeCamera& camera;
  int max_depth = 8;  // delta bounces a path may take
  uint64_t seed = 0, pass = 0;
};

// For pixels [first, first + points.size()) in row-major order: points[k] = pixel first + k's
// visible point this pass, its f the path throughput times the BRDF (f = 0 when the path ends
// without one: background, an emitter or a black surface, or the depth limit), and out[k] = a
// fresh pass sum whose direct part holds the emission the path saw on its way. A visible point
// on a non-Lambertian surface keeps the throughput alone in f, and its GlossyPoint (point = k)
// goes to the front of `glossy` (room for points.size()), in pixel order. Returns their count.
size_t trace_visible_points(const CameraPathInputs& in, size_t first,
                            std::span<MeasurementPoint> points, std::span<GlossyPoint> glossy,
                            std::span<PassGather> out);

}  // namespace pb
