#include "photonbound/bsdf.h"

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

namespace {

// Shading normals make tessellated spheres look smooth, but a direction computed from ns can
// end up on the wrong side of the true surface; then the geometric normal is used instead.
vec3 reflect_checked(const vec3& wo, const vec3& ns, const vec3& ng) {
  const vec3 r = reflect(wo, ns);
  return glm::dot(r, ng) > 0.0f ? r : reflect(wo, ng);
}

}  // namespace

Bsdf::Bsdf(const Material& m, const vec3& ng, const vec3& ns)
    : model_(m.model), color_(m.base_color), ior_(m.ior), ng_(ng), ns_(ns) {}

vec3 Bsdf::eval(const vec3& wo, const vec3& wi) const {
  if (is_delta()) return vec3(0.0f);
  // Both directions on one side of the true surface: reflection only.
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return vec3(0.0f);
  return diffuse_f();
}

float Bsdf::pdf(const vec3& wo, const vec3& wi) const {
  if (is_delta()) return 0.0f;
  const vec3 ns = glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_;
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return 0.0f;
  return std::max(0.0f, glm::dot(wi, ns)) / kPi;  // cosine-weighted about the shading normal
}

bool Bsdf::sample(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;
  const vec3 ns = front ? ns_ : -ns_;
  if (!is_delta()) {
    // Drawn in this order: the arguments of an earlier call, which GCC evaluated right to left
    // (images stay bit-identical; the order is now explicit for every compiler).
    const float u2 = rng.next_float(), u1 = rng.next_float();
    out.wi = sample_cosine_hemisphere(ns, u1, u2);
    if (glm::dot(out.wi, ng) <= 0.0f) return false;  // below the true surface: absorbed
    // Cosine sampling cancels f cos / pdf to rho.
    out.weight = color_;
    out.pdf = glm::dot(out.wi, ns) / kPi;
    out.delta = false;
    return true;
  }
  SpecularBranch b[2];
  const int n = delta_branches(wo, mode, b);
  int pick = 0;
  float p = 1.0f;
  if (n == 2) {
    // Reflection or refraction in proportion to their throughput.
    const float a0 = average(b[0].weight), a1 = average(b[1].weight);
    p = a0 / (a0 + a1);
    if (rng.next_float() >= p) {
      pick = 1;
      p = 1.0f - p;
    }
  }
  if (!(p > 0.0f)) return false;
  out.wi = b[pick].dir;
  out.weight = b[pick].weight / p;
  out.pdf = 0.0f;
  out.delta = true;
  return true;
}

int Bsdf::delta_branches(const vec3& wo, Transport mode, SpecularBranch out[2]) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;  // normals on wo's side
  const vec3 ns = front ? ns_ : -ns_;
  if (model_ == Reflection::Mirror) {
    out[0] = {reflect_checked(wo, ns, ng), color_};
    return 1;
  }
  if (model_ != Reflection::Dielectric) return 0;
  const float eta = front ? ior_ : 1.0f / ior_;  // eta_t / eta_i
  const float cos_i = std::fabs(glm::dot(wo, ns));
  const float f = fresnel_dielectric(cos_i, eta);
  out[0] = {reflect_checked(wo, ns, ng), vec3(f)};
  if (f >= 1.0f) return 1;
  vec3 wt;
  if (!refract(wo, ns, eta, wt) || glm::dot(wt, ng) >= 0.0f) {
    if (!refract(wo, ng, eta, wt)) {
      // No transmission about either normal: all of the energy is reflected.
      out[0].weight = vec3(1.0f);
      return 1;
    }
  }
  const float scale = mode == Transport::Radiance ? 1.0f / (eta * eta) : 1.0f;
  out[1] = {wt, color_ * ((1.0f - f) * scale)};
  return 2;
}

}  // namespace pb
