// What passes through a surface as a non-delta component: rough glass and diffuse transmission
// (KHR_materials_diffuse_transmission, below).
//
// Rough glass: KHR_materials_transmission's transmitting part, (1 - metallic) transmission, at a
// roughness at or above --mirror-roughness (at a smaller one it is the smooth glass of
// base_branches). glTF writes it fresnel_mix(layer = specular_brdf(alpha), base =
// specular_btdf(alpha) x baseColor), alpha = roughness^2, so the component is
//   reflection    F D V at h = normalize(wo + wi)                          (wi on wo's side)
//   transmission  thin-walled: baseColor (1 - max F) D V at the half vector of wo and wi
//                 mirrored through the surface (the extension's "Refraction": the specular
//                 lobe "sampled along the line of sight through the surface"; V the BRDF's own,
//                 so that reflection plus transmission is the white GGX lobe);
//                 a volume boundary (KHR_materials_volume): baseColor times Walter et al. 2007's
//                 BTDF, eq. 21, with the exact Fresnel equations, as the smooth boundary uses:
//                 (1 - F) D G2 |wi.h| |wo.h| / (|wi.n| |wo.n| (wi.h + wo.h / eta)^2), divided
//                 by eta^2 for radiance (eta = eta_t / eta_i; photons carry flux and do not).
// F is the layer's Schlick term (KHR_materials_specular and the film included) on a thin wall,
// the exact dielectric term (the film mixed in on the outside) on a volume. Drawn by Heitz's
// visible normals, then reflection or transmission at that normal in proportion to what each
// carries; layered under a sheen and a coat as the delta branches are. Isotropic: the roughness
// of an anisotropic material's transmission is its base roughness.
#include "bsdf/bsdf.h"
#include "bsdf/microfacet.h"
#include "bsdf/sheen.h"
#include "bsdf/thin_film.h"

#include <algorithm>

namespace pb {

namespace {

// The shading frame of wo's side: directions to (t, b, n) coordinates and back.
struct LocalFrame {
  vec3 t, b, n;
  explicit LocalFrame(const vec3& normal) : n(normal) { orthonormal_basis(n, t, b); }
  vec3 local(const vec3& w) const { return vec3(glm::dot(w, t), glm::dot(w, b), glm::dot(w, n)); }
  vec3 world(const vec3& w) const { return glm::normalize(w.x * t + w.y * b + w.z * n); }
};

// The probability of reflecting at a microfacet whose Fresnel term is f, for glass of base
// colour `base`: in proportion to what each way carries (1 where nothing passes).
float reflect_probability(const vec3& f, const vec3& base) {
  const float r = average(f), t = average(base) * (1.0f - max_component(f));
  return r + t > 0.0f ? r / (r + t) : 1.0f;
}

}  // namespace

vec3 Bsdf::glass_fresnel(float cos_h, bool front) const {
  if (thin_) return brdf_.layer_fresnel(cos_h);
  const float eta = front ? brdf_.ior : 1.0f / brdf_.ior;
  const vec3 f(fresnel_dielectric(cos_h, eta));
  if (!(brdf_.iridescence > 0.0f) || !front) return f;
  return glm::mix(f,
                  iridescent_fresnel(1.0f, brdf_.iridescence_ior, vec3(dielectric_f0(brdf_.ior)),
                                     brdf_.iridescence_thickness, cos_h),
                  brdf_.iridescence);
}

vec3 Bsdf::glass_f(const vec3& lo, const vec3& li, bool front, Transport mode, float* pdf) const {
  if (pdf) *pdf = 0.0f;
  if (!(lo.z > 0.0f) || li.z == 0.0f) return vec3(0.0f);
  const float alpha = ggx_alpha(brdf_.roughness);
  const vec3 base = brdf_.base_color;
  if (li.z > 0.0f) {  // reflection
    const vec3 h = glm::normalize(lo + li);
    const vec3 f = glass_fresnel(glm::dot(lo, h), front);
    if (pdf) *pdf = reflect_probability(f, base) * ggx_reflection_pdf(lo, li, alpha);
    return glass_ * ggx_d(h, alpha) * ggx_visibility(lo.z, li.z, alpha) * f;
  }
  if (thin_) {  // the reflection lobe, mirrored through the surface
    const vec3 lr(li.x, li.y, -li.z);
    const vec3 h = glm::normalize(lo + lr);
    const vec3 f = glass_fresnel(glm::dot(lo, h), front);
    if (pdf) *pdf = (1.0f - reflect_probability(f, base)) * ggx_reflection_pdf(lo, lr, alpha);
    return (glass_ * (1.0f - max_component(f)) * ggx_d(h, alpha) *
            ggx_visibility(lo.z, lr.z, alpha)) *
           base;
  }
  // Refraction: the microfacet normal h = +-normalize(eta wi + wo) (Walter et al. 2007, eq.
  // 16), facing the side of wo; wo in front of it and wi behind.
  const float eta = front ? brdf_.ior : 1.0f / brdf_.ior;
  vec3 h = eta * li + lo;
  const float len = glm::length(h);
  if (!(len > 0.0f)) return vec3(0.0f);
  h /= len;
  if (h.z < 0.0f) h = -h;
  const float o_h = glm::dot(lo, h), i_h = glm::dot(li, h);
  if (!(o_h > 0.0f) || !(i_h < 0.0f)) return vec3(0.0f);
  const vec3 f = glass_fresnel(o_h, front);
  const float root = i_h + o_h / eta, denom = root * root;
  if (!(denom > 0.0f)) return vec3(0.0f);
  // dwh / dwi = |wi.h| / (wi.h + wo.h / eta)^2 (eq. 17 with eta_i = 1 in wo's medium's units).
  if (pdf) *pdf = (1.0f - reflect_probability(f, base)) * ggx_vndf(lo, h, alpha) * -i_h / denom;
  const float g2 = smith_g2(lo, vec3(li.x, li.y, -li.z), alpha);
  const float ft = ggx_d(h, alpha) * g2 * (-i_h * o_h) / (-li.z * lo.z * denom);
  const float scale = mode == Transport::Radiance ? 1.0f / (eta * eta) : 1.0f;
  return (glass_ * (1.0f - max_component(f)) * ft * scale) * base;
}

vec3 Bsdf::eval_glass(const vec3& wo, const vec3& wi, const vec3& v, Transport mode,
                      float* pdf) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const LocalFrame fr(front ? ns_ : -ns_);
  const vec3 lo = fr.local(wo), li = fr.local(wi);
  const vec3 f = glass_f(lo, li, front, mode, pdf);
  return f * under_layers(lo.z, li.z, v);
}

bool Bsdf::glass_lit_directly() const {
  return glass_in_part() && !(brdf_.roughness < kGlassDirectRoughness);
}

Bsdf Bsdf::without_glass() const {
  Bsdf b = *this;
  b.rough_glass_ = false;  // eval() without its reflection; not drawn from (not for sample())
  return b;
}

vec3 Bsdf::eval_transmission(const vec3& wo, const vec3& wi, bool glass) const {
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) >= 0.0f) return vec3(0.0f);
  vec3 f =
      glass && glass_in_part() ? eval_glass(wo, wi, wo, Transport::Radiance, nullptr) : vec3(0.0f);
  if (dt_in_part()) {
    const LocalFrame fr(glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_);
    const vec3 lo = fr.local(wo), li = fr.local(wi);
    f += dt_f(lo, li) * under_layers(lo.z, li.z, wo);
  }
  return f;
}

// KHR_materials_diffuse_transmission's diffuse_btdf(colour) x dt inside fresnel_mix: the
// dielectric layer's weight 1 - max F at the half vector of wo and wi mirrored through the
// surface (v.h averaged over both, as the diffuse base's, diffuse_term), over the opaque
// dielectric's share; a Lambertian BTDF, the same both ways (photons need no adjoint).
vec3 Bsdf::dt_f(const vec3& lo, const vec3& li) const {
  if (!(lo.z > 0.0f) || !(li.z < 0.0f)) return vec3(0.0f);
  const vec3 lr(li.x, li.y, -li.z);
  const vec3 h = glm::normalize(lo + lr);
  const vec3 fr = brdf_.layer_fresnel(0.5f * (glm::dot(lo, h) + glm::dot(lr, h)));
  const float opaque = reflect_ * (1.0f - brdf_.metallic);
  return (opaque * dt_ * (1.0f - max_component(fr)) / kPi) * dt_color_;
}

bool Bsdf::sample_dt(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;
  const LocalFrame fr(front ? ns_ : -ns_);
  const vec3 lo = fr.local(wo);
  if (!(lo.z > 0.0f)) return false;
  const float u2 = rng.next_float(), u1 = rng.next_float();
  const vec3 wi = sample_cosine_hemisphere(-fr.n, u1, u2);  // the other side
  if (!(glm::dot(wi, ng) < 0.0f)) return false;             // not through the true surface
  const vec3 li = fr.local(wi);
  const float layer = under_layers(lo.z, li.z, mode == Transport::Radiance ? wo : wi);
  const float p = -li.z / kPi;
  if (!(p > 0.0f)) return false;
  out.wi = wi;
  out.weight = dt_f(lo, li) * (layer * kPi);  // f |cos| / (|cos| / pi)
  out.pdf = p;
  out.delta = false;
  out.glass = false;
  return max_component(out.weight) > 0.0f;
}

float Bsdf::dt_albedo(const vec3& wo) const {
  const float c = std::fabs(glm::dot(wo, ns_));
  const float f0 = max_component(brdf_.dielectric_f0());
  const float a = reflect_ * (1.0f - brdf_.metallic) * dt_ * (1.0f - f0) * max_component(dt_color_);
  return std::max(a * layers_albedo(wo, c), 1e-3f * dt_);
}

bool Bsdf::sample_glass(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;
  const LocalFrame fr(front ? ns_ : -ns_);
  const vec3 lo = fr.local(wo);
  if (!(lo.z > 0.0f)) return false;  // seen from below the shading hemisphere
  const float u1 = rng.next_float(), u2 = rng.next_float(), u3 = rng.next_float();
  const vec3 h = sample_ggx_vndf(lo, ggx_alpha(brdf_.roughness), u1, u2);
  const float o_h = glm::dot(lo, h);
  if (!(o_h > 0.0f)) return false;
  const vec3 r = 2.0f * o_h * h - lo;  // the reflection at h
  vec3 li;
  if (u3 < reflect_probability(glass_fresnel(o_h, front), brdf_.base_color)) {
    li = r;
    if (!(li.z > 0.0f)) return false;  // the draw fell below the surface
  } else if (thin_) {
    if (!(r.z > 0.0f)) return false;
    li = vec3(r.x, r.y, -r.z);  // straight through, blurred by the microfacets
  } else if (!refract(lo, h, front ? brdf_.ior : 1.0f / brdf_.ior, li) || !(li.z < 0.0f)) {
    return false;  // total internal reflection at h (its probability to pass was 0)
  }
  float p = 0.0f;
  const vec3 f = glass_f(lo, li, front, mode, &p);
  if (!(p > 0.0f)) return false;
  const vec3 wi = fr.world(li);
  // Reflected above the true surface, transmitted below it; else absorbed.
  if ((li.z > 0.0f) != (glm::dot(wi, ng) > 0.0f)) return false;
  const float layer = under_layers(lo.z, li.z, mode == Transport::Radiance ? wo : wi);
  out.wi = wi;
  out.weight = f * (layer * std::fabs(li.z) / p);
  out.pdf = p;
  out.delta = false;
  out.glass = true;
  return max_component(out.weight) > 0.0f;
}

float Bsdf::glass_albedo(const vec3& wo) const {
  // An estimate (it chooses the component; the weights stay exact): what the Fresnel term at
  // the macro normal reflects plus what the rest transmits, under the layers above.
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const float c = std::fabs(glm::dot(wo, ns_));
  const float f = max_component(glass_fresnel(c, front));
  const float a = glass_ * (f + (1.0f - f) * max_component(brdf_.base_color));
  return std::max(a * layers_albedo(wo, c), 1e-3f * glass_);
}

float Bsdf::under_layers(float cos_o, float cos_i, const vec3& v) const {
  // As the delta branches: the sheen's albedo scaling, and 1 - k of the coat at the view v.
  return sheen_scaling(cos_o, cos_i) * (1.0f - coat_weight(v));
}

float Bsdf::layers_albedo(const vec3& wo, float cos_o) const {
  const float sm = sheen_max();
  const float sheen =
      sm > 0.0f ? std::max(0.0f, 1.0f - sm * sheen_albedo(cos_o, sheen_roughness_)) : 1.0f;
  return sheen * (1.0f - coat_weight(wo));
}

}  // namespace pb
