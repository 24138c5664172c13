// Small vector helpers shared by every stage. Geometry is float (what Embree traces);
// estimator state is double (ESTIMATOR.md section 8).
#pragma once

#include <glm/glm.hpp>

#include <cmath>
#include <cstdint>
#include <numbers>

namespace pb {

using glm::dvec3;
using glm::mat4;
using glm::vec2;
using glm::vec3;

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr double kPiD = std::numbers::pi;

// std::fmax's value, inline: a NaN argument yields the other (x86-64 glibc's fmax, whose call
// was 0.8% of a pass, returns y when the two are equal, +-0 included; so does this).
template <class T>
inline T fmax_inline(T x, T y) {
  return (x > y || y != y) ? x : y;
}
inline float max_component(const vec3& v) { return fmax_inline(v.x, fmax_inline(v.y, v.z)); }
inline double max_component(const dvec3& v) { return fmax_inline(v.x, fmax_inline(v.y, v.z)); }
inline float average(const vec3& v) { return (v.x + v.y + v.z) / 3.0f; }

inline bool is_finite(const vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Orthonormal basis around a unit vector n (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited"), branch-free and stable for every n.
inline void orthonormal_basis(const vec3& n, vec3& t, vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = vec3(c, sign + n.y * n.y * a, -n.y);
}

// Axis-aligned bounding box.
struct Bounds {
  vec3 lo{INFINITY};
  vec3 hi{-INFINITY};
  void extend(const vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
  float diagonal() const { return empty() ? 0.0f : glm::length(hi - lo); }
};

}  // namespace pb
