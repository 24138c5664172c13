#include "bsdf/scattering.h"

#include <algorithm>

namespace pb {

float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  // Snell: sin_t = sin_i / eta.
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_parl * r_parl + r_perp * r_perp);
}

bool refract(const vec3& w, const vec3& n, float eta, vec3& wt) {
  const float cos_i = glm::dot(w, n);
  const float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return false;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  wt = glm::normalize(-w / eta + (cos_i / eta - cos_t) * n);
  return true;
}

vec3 sample_cosine_hemisphere(const vec3& n, float u1, float u2) {
  // Malley's method: uniform disk point lifted to the hemisphere.
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  const float z = std::sqrt(std::max(0.0f, 1.0f - u1));
  vec3 t, b;
  orthonormal_basis(n, t, b);
  return glm::normalize(x * t + y * b + z * n);
}

vec3 sample_uniform_sphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u2;
  return vec3(r * std::cos(phi), r * std::sin(phi), z);
}

vec3 sample_uniform_cone(const vec3& axis, float cos_max, float u1, float u2) {
  const float z = 1.0f - u1 * (1.0f - cos_max);
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u2;
  vec3 t, b;
  orthonormal_basis(axis, t, b);
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + z * axis);
}

float adjoint_shading_factor(const vec3& wo, const vec3& wi, const vec3& ng, const vec3& ns) {
  const float den = std::fabs(glm::dot(wo, ng)) * std::fabs(glm::dot(wi, ns));
  if (den <= 0.0f) return 0.0f;
  return std::fabs(glm::dot(wo, ns)) * std::fabs(glm::dot(wi, ng)) / den;
}

}  // namespace pb
