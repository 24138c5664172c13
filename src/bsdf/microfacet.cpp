#include "bsdf/microfacet.h"

#include "bsdf/thin_film.h"

#include <algorithm>

namespace pb {

namespace {

float clamp_alpha(float alpha) { return std::max(alpha, kMinGgxAlpha); }

// sqrt(alpha^2 + (1 - alpha^2) z^2) = z sqrt(1 + alpha^2 tan^2 theta), the root shared by
// Lambda, G1, G2 and V; written as z^2 + alpha^2 sin^2 so that nothing cancels near z = 1.
float smith_root(float z, float sin2, float alpha) {
  return std::sqrt(z * z + alpha * alpha * sin2);
}
float smith_root(float z, float alpha) {
  return smith_root(z, std::max(0.0f, 1.0f - z * z), alpha);
}
// For a direction, sin^2 from x and y keeps its digits near the pole, where 1 - z^2 would not,
// and makes Lambda, G1 and G2 functions of the direction of w alone (not of its length).
float smith_root(const vec3& w, float alpha) {
  return smith_root(w.z, w.x * w.x + w.y * w.y, alpha);
}

}  // namespace

float ggx_alpha(float roughness) {
  const float r = std::clamp(roughness, 0.0f, 1.0f);
  return clamp_alpha(r * r);
}

float ggx_d(const vec3& h, float alpha) {
  if (h.z <= 0.0f) return 0.0f;
  const float a2 = clamp_alpha(alpha) * clamp_alpha(alpha);
  // Walter et al. 2007, eq. 33: alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2). For a unit h,
  // cos^4 (alpha^2 + tan^2)^2 = (h.x^2 + h.y^2 + alpha^2 h.z^2)^2; the usual form
  // (n.h)^2 (alpha^2 - 1) + 1 loses every digit near h = n once alpha^2 is below float epsilon.
  const float d = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
  return a2 / (kPi * d * d);
}

float smith_lambda(const vec3& w, float alpha) {
  if (w.z <= 0.0f) return INFINITY;
  const float a = clamp_alpha(alpha);
  // (-1 + sqrt(1 + a^2 tan^2)) / 2 = (s - z) / (2 z) with s = smith_root; the difference is
  // a^2 sin^2 / (s + z), so Lambda = a^2 sin^2 / (2 z (s + z)) without cancellation.
  const float sin2 = w.x * w.x + w.y * w.y;
  return a * a * sin2 / (2.0f * w.z * (smith_root(w.z, sin2, a) + w.z));
}

float smith_g1(const vec3& w, float alpha) {
  if (w.z <= 0.0f) return 0.0f;
  // 1 / (1 + Lambda) = 2 z / (z + s): finite and exact at grazing.
  return 2.0f * w.z / (w.z + smith_root(w, clamp_alpha(alpha)));
}

float smith_g2(const vec3& wo, const vec3& wi, float alpha) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  // 1 / (1 + Lambda_o + Lambda_i) = 2 zo zi / (zi so + zo si): glTF appendix B's G.
  const float a = clamp_alpha(alpha);
  return 2.0f * wo.z * wi.z / (wi.z * smith_root(wo, a) + wo.z * smith_root(wi, a));
}

float ggx_visibility(float cos_o, float cos_i, float alpha) {
  const float a = clamp_alpha(alpha);
  const float zo = std::max(std::fabs(cos_o), kMinCosine);
  const float zi = std::max(std::fabs(cos_i), kMinCosine);
  // glTF appendix B "Specular BRDF", the visibility function; the sum is written so that
  // swapping the cosines swaps its terms, which keeps the BRDF reciprocal bit for bit.
  return 0.5f / (zi * smith_root(zo, a) + zo * smith_root(zi, a));
}

float ggx_vndf(const vec3& wo, const vec3& h, float alpha) {
  if (wo.z <= 0.0f) return 0.0f;
  const float wo_h = glm::dot(wo, h);
  if (wo_h <= 0.0f) return 0.0f;
  // G1(wo) / wo.z = 2 / (wo.z + s_o): no division by a grazing cosine.
  const float a = clamp_alpha(alpha);
  return 2.0f * wo_h * ggx_d(h, a) / (wo.z + smith_root(wo, a));
}

vec3 sample_ggx_vndf(const vec3& wo, float alpha, float u1, float u2) {
  const float a = clamp_alpha(alpha);
  // Heitz 2018, listing 1. Section 3.2: stretch wo into the configuration where the
  // microsurface is the upper unit hemisphere (alpha = 1).
  const vec3 vh = glm::normalize(vec3(a * wo.x, a * wo.y, wo.z));
  // Section 4.1: an orthonormal basis around vh (x when vh is the pole).
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const vec3 t1 = len2 > 0.0f ? vec3(-vh.y, vh.x, 0.0f) / std::sqrt(len2) : vec3(1, 0, 0);
  const vec3 t2 = glm::cross(vh, t1);
  // Section 4.2: a uniform point on the projected area, a disk whose lower half is squashed
  // by s = (1 + vh.z) / 2.
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float p1 = r * std::cos(phi);
  const float s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
  // Section 4.3: lift the point onto the hemisphere around vh.
  const vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  // Section 3.4: unstretch the normal back to the configuration of alpha.
  return glm::normalize(vec3(a * nh.x, a * nh.y, std::max(0.0f, nh.z)));
}

float ggx_reflection_pdf(const vec3& wo, const vec3& wi, float alpha) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  const vec3 h = glm::normalize(wo + wi);
  // Heitz 2018, eq. 17: D_wo(h) / (4 wo.h), with D_wo(h) = 2 (wo.h) D(h) / (wo.z + s_o); the
  // factor wo.h cancels (and is positive: wo and wi are both above the surface).
  const float a = clamp_alpha(alpha);
  return ggx_d(h, a) / (2.0f * (wo.z + smith_root(wo, a)));
}

namespace {

// |(ax w.x, ay w.y, w.z)|: the anisotropic smith_root, z sqrt(1 + alpha(phi)^2 tan^2) with
// alpha(phi)^2 = (ax^2 cos^2 phi + ay^2 sin^2 phi) (Heitz 2014, eq. 80).
float smith_root(const vec3& w, float ax, float ay) {
  return std::sqrt(w.z * w.z + ax * ax * w.x * w.x + ay * ay * w.y * w.y);
}

}  // namespace

float ggx_d(const vec3& h, float alpha_x, float alpha_y) {
  if (h.z <= 0.0f) return 0.0f;
  const float ax = clamp_alpha(alpha_x), ay = clamp_alpha(alpha_y);
  const float x = h.x / ax, y = h.y / ay;
  const float s = x * x + y * y + h.z * h.z;
  return 1.0f / (kPi * ax * ay * s * s);
}

float smith_g1(const vec3& w, float alpha_x, float alpha_y) {
  if (w.z <= 0.0f) return 0.0f;
  return 2.0f * w.z / (w.z + smith_root(w, clamp_alpha(alpha_x), clamp_alpha(alpha_y)));
}

float ggx_visibility(const vec3& wo, const vec3& wi, float alpha_x, float alpha_y) {
  const float ax = clamp_alpha(alpha_x), ay = clamp_alpha(alpha_y);
  const vec3 o(wo.x, wo.y, std::max(std::fabs(wo.z), kMinCosine));
  const vec3 i(wi.x, wi.y, std::max(std::fabs(wi.z), kMinCosine));
  // Written so that swapping wo and wi swaps the two terms (reciprocal bit for bit).
  return 0.5f / (i.z * smith_root(o, ax, ay) + o.z * smith_root(i, ax, ay));
}

float ggx_vndf(const vec3& wo, const vec3& h, float alpha_x, float alpha_y) {
  if (wo.z <= 0.0f) return 0.0f;
  const float wo_h = glm::dot(wo, h);
  if (wo_h <= 0.0f) return 0.0f;
  const float ax = clamp_alpha(alpha_x), ay = clamp_alpha(alpha_y);
  return 2.0f * wo_h * ggx_d(h, ax, ay) / (wo.z + smith_root(wo, ax, ay));
}

vec3 sample_ggx_vndf(const vec3& wo, float alpha_x, float alpha_y, float u1, float u2) {
  const float ax = clamp_alpha(alpha_x), ay = clamp_alpha(alpha_y);
  // Heitz 2018, listing 1, as the isotropic one with the stretch (ax, ay).
  const vec3 vh = glm::normalize(vec3(ax * wo.x, ay * wo.y, wo.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const vec3 t1 = len2 > 0.0f ? vec3(-vh.y, vh.x, 0.0f) / std::sqrt(len2) : vec3(1, 0, 0);
  const vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float p1 = r * std::cos(phi);
  const float s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
  const vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(vec3(ax * nh.x, ay * nh.y, std::max(0.0f, nh.z)));
}

float ggx_reflection_pdf(const vec3& wo, const vec3& wi, float alpha_x, float alpha_y) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  const vec3 h = glm::normalize(wo + wi);
  const float ax = clamp_alpha(alpha_x), ay = clamp_alpha(alpha_y);
  return ggx_d(h, ax, ay) / (2.0f * (wo.z + smith_root(wo, ax, ay)));
}

float schlick_weight(float cos_theta) {
  const float x = std::clamp(1.0f - std::fabs(cos_theta), 0.0f, 1.0f);
  const float x2 = x * x;
  return x2 * x2 * x;
}

float dielectric_f0(float ior) {
  const float r = (ior - 1.0f) / (ior + 1.0f);
  return r * r;
}

namespace {

// f(wo, wi) and, when pdf is given, the sampling density, sharing the half vector. With
// `parts`, also the two terms f is the sum of: parts[0] the diffuse base, parts[1] the GGX
// lobe (both layers' specular terms), each already weighted by (1 - metallic) and metallic.
vec3 eval_and_pdf(const MetalRoughBrdf& m, const vec3& wo, const vec3& wi, float* pdf,
                  vec3* parts = nullptr) {
  if (pdf) *pdf = 0.0f;
  if (parts) parts[0] = parts[1] = vec3(0.0f);
  if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
  const float a = ggx_alpha(m.roughness);
  // Float addition commutes, so h, v.h (averaged over both directions) and V are the same for
  // (wo, wi) and (wi, wo): reciprocity holds exactly (barring FMA contraction, see the header).
  const vec3 h = glm::normalize(wo + wi);
  const float v_h = 0.5f * (glm::dot(wo, h) + glm::dot(wi, h));
  const bool aniso = m.anisotropy > 0.0f;
  const float ax = aniso ? m.alpha_x() : a;
  const float d = aniso ? ggx_d(h, ax, a) : ggx_d(h, a);
  // glTF specular_brdf (KHR_materials_anisotropy's BRDF_specularAnisotropicGGX)
  const float specular =
      (aniso ? ggx_visibility(wo, wi, ax, a) : ggx_visibility(wo.z, wi.z, a)) * d;
  const float fw = schlick_weight(v_h);
  const vec3 f0 = m.dielectric_f0();
  vec3 fr = f0 + (vec3(m.dielectric_f90()) - f0) * fw;
  vec3 fm = m.base_color + (vec3(1.0f) - m.base_color) * fw;
  if (m.iridescence > 0.0f) {  // KHR_materials_iridescence: the film's Fresnel mixed in
    if (m.metallic < 1.0f) fr = m.layer_fresnel(v_h);
    if (m.metallic > 0.0f) fm = m.metal_fresnel(v_h);
  }
  // glTF appendix B "Metal BRDF and Dielectric BRDF", the full code, with KHR_materials_specular's
  // RGB Fresnel term (the diffuse base keeps 1 - its largest channel).
  const vec3 diffuse = m.base_color * m.diffuse_weight;
  const vec3 dielectric = (1.0f - max_component(fr)) * diffuse / kPi + fr * specular;
  const vec3 metal = fm * specular;
  if (pdf) {
    const float ps = m.specular_probability(wo);
    // ggx_reflection_pdf with the half vector already at hand.
    const float spec_pdf =
        d / (2.0f * (wo.z + (aniso ? smith_root(wo, ax, a) : smith_root(wo, a))));
    *pdf = ps * spec_pdf + (1.0f - ps) * wi.z / kPi;
  }
  if (parts) {
    parts[0] = (1.0f - m.metallic) * ((1.0f - max_component(fr)) * diffuse / kPi);
    parts[1] = (1.0f - m.metallic) * (fr * specular) + m.metallic * metal;
  }
  return (1.0f - m.metallic) * dielectric + m.metallic * metal;
}

}  // namespace

vec3 MetalRoughBrdf::eval(const vec3& wo, const vec3& wi) const {
  return eval_and_pdf(*this, wo, wi, nullptr);
}

vec3 MetalRoughBrdf::eval_diffuse(const vec3& wo, const vec3& wi) const {
  vec3 parts[2];
  eval_and_pdf(*this, wo, wi, nullptr, parts);
  return parts[0];
}

vec3 MetalRoughBrdf::eval_specular(const vec3& wo, const vec3& wi) const {
  vec3 parts[2];
  eval_and_pdf(*this, wo, wi, nullptr, parts);
  return parts[1];
}

bool MetalRoughBrdf::sample_specular(const vec3& wo, float u1, float u2, vec3& wi, vec3& weight,
                                     float& pdf_out) const {
  if (wo.z <= 0.0f) return false;
  const vec3 h = sample_specular_normal(wo, u1, u2);
  wi = glm::normalize(2.0f * glm::dot(wo, h) * h - wo);
  if (wi.z <= 0.0f) return false;
  pdf_out = specular_pdf(wo, wi);
  if (!(pdf_out > 0.0f)) return false;
  weight = eval_specular(wo, wi) * (wi.z / pdf_out);
  return true;
}

float MetalRoughBrdf::pdf(const vec3& wo, const vec3& wi) const {
  float p;
  eval_and_pdf(*this, wo, wi, &p);
  return p;
}

float MetalRoughBrdf::alpha_x() const {
  // KHR_materials_anisotropy: directionAlphaRoughness = mix(alpha, 1, strength^2).
  const float a = ggx_alpha(roughness), s = std::clamp(anisotropy, 0.0f, 1.0f);
  return s > 0.0f ? a + (1.0f - a) * (s * s) : a;
}

float MetalRoughBrdf::specular_pdf(const vec3& wo, const vec3& wi) const {
  return anisotropy > 0.0f ? ggx_reflection_pdf(wo, wi, alpha_x(), alpha_y())
                           : ggx_reflection_pdf(wo, wi, ggx_alpha(roughness));
}

vec3 MetalRoughBrdf::sample_specular_normal(const vec3& wo, float u1, float u2) const {
  return anisotropy > 0.0f ? sample_ggx_vndf(wo, alpha_x(), alpha_y(), u1, u2)
                           : sample_ggx_vndf(wo, ggx_alpha(roughness), u1, u2);
}

vec3 MetalRoughBrdf::layer_fresnel(float cos_theta) const {
  const vec3 f0 = dielectric_f0();
  const vec3 fr = f0 + (vec3(dielectric_f90()) - f0) * schlick_weight(cos_theta);
  if (!(iridescence > 0.0f)) return fr;
  return glm::mix(fr,
                  iridescent_fresnel(1.0f, iridescence_ior, f0, iridescence_thickness, cos_theta),
                  iridescence);
}

vec3 MetalRoughBrdf::metal_fresnel(float cos_theta) const {
  const vec3 fm = schlick_fresnel(base_color, cos_theta);
  if (!(iridescence > 0.0f)) return fm;
  return glm::mix(
      fm, iridescent_fresnel(1.0f, iridescence_ior, base_color, iridescence_thickness, cos_theta),
      iridescence);
}

vec3 MetalRoughBrdf::dielectric_f0() const {
  return glm::min(pb::dielectric_f0(ior) * specular_color, vec3(1.0f)) * specular;
}

float MetalRoughBrdf::specular_probability(const vec3& wo) const {
  const float f0 = max_component(dielectric_f0());
  const float f90 = dielectric_f90();
  const float s = (1.0f - metallic) * (f0 + (f90 - f0) * schlick_weight(wo.z)) +
                  metallic * max_component(schlick_fresnel(base_color, wo.z));
  const float d = (1.0f - metallic) * (1.0f - f0) * diffuse_weight * max_component(base_color);
  return s + d > 0.0f ? s / (s + d) : 1.0f;
}

bool MetalRoughBrdf::sample(const vec3& wo, float u_lobe, float u1, float u2, vec3& wi,
                            vec3& weight, float& pdf_out) const {
  if (wo.z <= 0.0f) return false;
  if (u_lobe < specular_probability(wo)) {
    const vec3 h = sample_specular_normal(wo, u1, u2);
    wi = glm::normalize(2.0f * glm::dot(wo, h) * h - wo);
  } else {
    // Cosine-weighted hemisphere (Malley's method): a uniform disk point lifted to the
    // hemisphere; density z / pi. z >= 2^-12 since u1 < 1.
    const float r = std::sqrt(u1);
    const float phi = 2.0f * kPi * u2;
    wi = vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1)));
  }
  if (wi.z <= 0.0f) return false;
  // Value and density of the mixture at the direction drawn (either lobe could have drawn it).
  const vec3 f = eval_and_pdf(*this, wo, wi, &pdf_out);
  if (!(pdf_out > 0.0f)) return false;
  weight = f * (wi.z / pdf_out);
  return true;
}

}  // namespace pb
