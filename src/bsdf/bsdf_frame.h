// The Bsdf's shading frame, shared by its eval (bsdf_eval.cpp) and sampling (bsdf_sample.cpp);
// internal to src/bsdf.
#pragma once

#include "util/math.h"

namespace pb::bsdf_detail {

// Directions in the shading frame (t, b, n) and back. With a tangent (unit, orthogonal to n:
// KHR_materials_anisotropy's direction) t is it; without, any basis (isotropic lobes).
struct Frame {
  vec3 t, b, n;
  explicit Frame(const vec3& normal) : n(normal) { orthonormal_basis(n, t, b); }
  Frame(const vec3& normal, const vec3& tangent) : n(normal) {
    if (tangent == vec3(0.0f)) {
      orthonormal_basis(n, t, b);
    } else {
      t = tangent;
      b = glm::cross(n, t);
    }
  }
  vec3 local(const vec3& w) const { return vec3(glm::dot(w, t), glm::dot(w, b), glm::dot(w, n)); }
  vec3 world(const vec3& w) const { return glm::normalize(w.x * t + w.y * b + w.z * n); }
};

}  // namespace pb::bsdf_detail
