// Ray origins that leave a surface without hitting it again, at any scene scale: the offset is
// the floating-point error bound of the hit position, not a fraction of the scene's size (pbrt-v4
// Interaction::OffsetRayOrigin and the error bounds of its triangle intersection, Pharr, Jakob,
// Humphreys, "Physically Based Rendering" 4th ed., section 6.8). A 1-unit object over a
// 1e6-unit ground keeps offsets of its own size (~1e-7), the ground gets offsets of its own.
#pragma once

#include "util/math.h"

#include <cstring>
#include <limits>

namespace pb {

// gamma(n) = n u / (1 - n u), u = 2^-24 the unit roundoff of float: the relative error bound of
// n floating-point operations (PBR 4th ed. section 6.8.1, after Higham).
constexpr float gamma_bound(int n) {
  constexpr float u = std::numeric_limits<float>::epsilon() * 0.5f;
  return (float(n) * u) / (1.0f - float(n) * u);
}

// How far along the unit geometric normal n a point computed by barycentric interpolation of the
// triangle (p0, p1, p2) may lie off the triangle's plane, with the margin Embree's intersection
// needs. PBR's bound is gamma(7) (|b0 p0| + |b1 p1| + |b2 p2|), projected on |n|. Embree computes
// a ray's distance to the plane from v0 - origin, whose rounding grows with |p0| whatever the
// barycentrics, so the sum here is over the vertices' magnitudes unweighted: it bounds PBR's sum
// and Embree's (tests/world/test_offsets.cpp fires rays from points near every corner of huge,
// tilted and far-off triangles and finds no self-hit; with the weighted sum it finds some).
inline float surface_error(const vec3& p0, const vec3& p1, const vec3& p2, const vec3& n) {
  const vec3 sum = glm::abs(p0) + glm::abs(p1) + glm::abs(p2);
  return gamma_bound(7) * glm::dot(glm::abs(n), sum);
}

// The next float above or below v (PBR NextFloatUp / NextFloatDown, by the bit pattern): one
// ulp, without the libm call of std::nextafter in the hot loops.
inline float next_float_up(float v) {
  if (std::isinf(v) && v > 0.0f) return v;
  if (v == -0.0f) v = 0.0f;
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  bits = v >= 0.0f ? bits + 1 : bits - 1;
  std::memcpy(&v, &bits, 4);
  return v;
}
inline float next_float_down(float v) {
  if (std::isinf(v) && v < 0.0f) return v;
  if (v == 0.0f) v = -0.0f;
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  bits = v > 0.0f ? bits - 1 : bits + 1;
  std::memcpy(&v, &bits, 4);
  return v;
}

// The origin of a ray leaving p (geometric normal n, error bound `error` along n) toward dir's
// side of the surface: p moved by `error` along n, each coordinate then rounded one more ulp
// away from the surface, so the rounding of the addition cannot bring it back (PBR
// OffsetRayOrigin). With error 0 only the rounding step remains.
inline vec3 offset_ray_origin(const vec3& p, const vec3& n, float error, const vec3& dir) {
  vec3 offset = error * n;
  if (glm::dot(dir, n) < 0.0f) offset = -offset;
  vec3 o = p + offset;
  for (int c = 0; c < 3; ++c) {
    if (n[c] == 0.0f) continue;
    const bool up = (n[c] > 0.0f) == (glm::dot(dir, n) >= 0.0f);
    o[c] = up ? next_float_up(o[c]) : next_float_down(o[c]);
  }
  return o;
}

// Shadow rays end short of the point they test by the relative rounding of their length and of
// Embree's ray parameter (a few operations; 16 to spare).
inline constexpr float kShadowLengthFactor = 1.0f - gamma_bound(16);

}  // namespace pb
