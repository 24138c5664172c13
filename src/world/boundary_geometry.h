// Geometry the boundary index's construction (boundary.cpp) and its queries (boundary_query.cpp)
// share.
#pragma once

#include "util/math.h"

#include <algorithm>
#include <cmath>

namespace pb::boundary_geometry {

// Squared distance from p to the segment [a, b], in double.
inline double segment_distance2(const vec3& p, const vec3& a, const vec3& b) {
  const dvec3 ab = dvec3(b) - dvec3(a), ap = dvec3(p) - dvec3(a);
  const double len2 = glm::dot(ab, ab);
  const double s = len2 > 0.0 ? std::clamp(glm::dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
  const dvec3 d = ap - s * ab;
  return glm::dot(d, d);
}

inline vec3 triangle_centre(const vec3 v[3]) { return (v[0] + v[1] + v[2]) / 3.0f; }

inline float triangle_reach(const vec3 v[3]) {
  const vec3 c = triangle_centre(v);
  return std::sqrt(std::max(
      {glm::dot(v[0] - c, v[0] - c), glm::dot(v[1] - c, v[1] - c), glm::dot(v[2] - c, v[2] - c)}));
}

// Clips segment [a, b] to the ball (c, r); false when they do not meet.
inline bool clip_to_sphere(vec3& a, vec3& b, const vec3& c, float r) {
  const dvec3 d = dvec3(b) - dvec3(a), f = dvec3(a) - dvec3(c);
  const double qa = glm::dot(d, d), qb = 2.0 * glm::dot(f, d), qc = glm::dot(f, f) - double(r) * r;
  if (!(qa > 0.0)) return qc <= 0.0;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  const double s0 = std::max(0.0, (-qb - sq) / (2.0 * qa)),
               s1 = std::min(1.0, (-qb + sq) / (2.0 * qa));
  if (s0 > s1) return false;
  const dvec3 a0(a);
  a = vec3(a0 + s0 * d);
  b = vec3(a0 + s1 * d);
  return true;
}

}  // namespace pb::boundary_geometry
