// The Bsdf's eval and pdf, with the layering of the clear coat and the sheen over the material
// (bsdf.h).
#include "bsdf/bsdf.h"

#include "bsdf/bsdf_frame.h"
#include "bsdf/sheen.h"

#include <algorithm>

namespace pb {

using bsdf_detail::Frame;

vec3 Bsdf::eval_local(const vec3& wo, const vec3& wi, float* pdf) const {
  if (pdf) *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
  // The kept terms: both (MetalRoughBrdf whole), the lobe alone or the diffuse base alone.
  if (!smooth_ && keeps(Term::Diffuse) && keeps(Term::Lobe)) {
    if (pdf) *pdf = brdf_.pdf(wo, wi);
    return reflect_ * brdf_.eval(wo, wi);
  }
  if (!keeps(Term::Diffuse)) {
    if (!keeps(Term::Lobe) || smooth_) return vec3(0.0f);
    if (pdf) *pdf = brdf_.specular_pdf(wo, wi);
    return reflect_ * brdf_.eval_specular(wo, wi);
  }
  if (pdf) *pdf = wi.z / kPi;
  return diffuse_term(wo, wi);
}

vec3 Bsdf::diffuse_term(const vec3& wo, const vec3& wi) const {
  // The mirror limit of appendix B's dielectric: the GGX layer is a delta branch, the diffuse
  // base keeps its weight 1 - max F(v.h) at this pair's half vector (v.h averaged over both
  // directions, so that f stays reciprocal bit for bit). A Bsdf restricted to it keeps the
  // same term of a rough lobe (MetalRoughBrdf::eval_diffuse computes it the same way).
  const vec3 h = glm::normalize(wo + wi);
  const float v_h = 0.5f * (glm::dot(wo, h) + glm::dot(wi, h));
  const vec3 fr = brdf_.layer_fresnel(v_h);
  const float opaque = reflect_ * (1.0f - brdf_.metallic);
  return (opaque * (1.0f - max_component(fr)) / kPi) * (brdf_.base_color * brdf_.diffuse_weight);
}

vec3 Bsdf::eval(const vec3& wo, const vec3& wi) const {
  if (kind_ == Kind::Delta) return vec3(0.0f);
  // Both directions on one side of the true surface: reflection only.
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return vec3(0.0f);
  if (kind_ == Kind::Lambertian) return diffuse_f();
  if (layered()) return eval_with_view(wo, wi, wo, nullptr);
  const Frame f(glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_, tangent_);
  const vec3 value = eval_local(f.local(wo), f.local(wi), nullptr);
  // Rough glass's reflection (its transmission reaches only the other side).
  return glass_in_part() ? value + eval_glass(wo, wi, wo, Transport::Radiance, nullptr) : value;
}

float Bsdf::coat_weight(const vec3& v) const {
  return clearcoat_fresnel(coat_, glm::dot(v, nc_));  // fresnel_coat at |v.n_c|
}

float Bsdf::coat_dv(const vec3& wo, const vec3& wi, float* pdf) const {
  if (pdf) *pdf = 0.0f;
  const Frame f(glm::dot(wo, ng_) > 0.0f ? nc_ : -nc_);
  const vec3 lo = f.local(wo), li = f.local(wi);
  if (lo.z <= 0.0f || li.z <= 0.0f) return 0.0f;
  const float alpha = ggx_alpha(coat_roughness_);
  if (pdf) *pdf = ggx_reflection_pdf(lo, li, alpha);
  // glTF's specular_brdf without its Fresnel (the coat's is in k): V D.
  return ggx_d(glm::normalize(lo + li), alpha) * ggx_visibility(lo.z, li.z, alpha);
}

Bsdf::Terms Bsdf::term_flags() const {
  const bool lobe = base_non_delta_ && !smooth_, coat = coat_lobe(), sheen = sheen_max() > 0.0f;
  return {base_non_delta_ && keeps(Term::Diffuse), lobe && keeps(Term::Lobe),
          coat && keeps(Term::Coat), sheen && keeps(Term::Sheen)};
}

TermSet Bsdf::terms() const {
  if (kind_ == Kind::Lambertian) return TermSet{}.with(Term::Diffuse, keeps(Term::Diffuse));
  if (kind_ == Kind::Delta) return TermSet{};
  const Terms t = term_flags();
  return TermSet{}
      .with(Term::Diffuse, t.diffuse)
      .with(Term::Lobe, t.lobe)
      .with(Term::Coat, t.coat)
      .with(Term::Sheen, t.sheen)
      .with(Term::Glass, glass_in_part())
      .with(Term::Transmission, dt_in_part());
}

Bsdf Bsdf::restricted(TermSet keep) const {
  Bsdf b = *this;
  b.keep_ = keep_ & keep;
  return b;
}

float Bsdf::sheen_scaling(float cos_o, float cos_i) const {
  const float sm = sheen_max();
  if (!(sm > 0.0f)) return 1.0f;
  // KHR_materials_sheen's albedo scaling, in its reciprocal form: min over both directions of
  // 1 - max(sheen colour) E(cos), and not below 0 where E exceeds 1 (sheen.h).
  return std::max(0.0f, std::min(1.0f - sm * sheen_albedo(std::fabs(cos_o), sheen_roughness_),
                                 1.0f - sm * sheen_albedo(std::fabs(cos_i), sheen_roughness_)));
}

void Bsdf::term_albedos(const vec3& wo, float a[kTerms]) const {
  // Estimates only (they choose among the terms; the weights stay exact), as
  // non_delta_albedo's: the diffuse base's (1 - f0) max(base), Schlick's Fresnel at the macro
  // normal for the base's lobe, each x (1 - k) and under a sheen x (1 - max(sheen) E); k for
  // the coat's lobe (D V has albedo about 1) and (1 - k) max(sheen) E for the sheen. The floor
  // keeps each term's probability above 0.
  const Terms t = term_flags();
  const float k = coat_weight(wo), cos_o = std::fabs(glm::dot(wo, ns_));
  const float mu = brdf_.metallic, f0 = max_component(brdf_.dielectric_f0());
  const float sm = sheen_max();
  const float e = sm > 0.0f ? sm * sheen_albedo(cos_o, sheen_roughness_) : 0.0f;
  const float under = (1.0f - k) * std::max(0.0f, 1.0f - e) * reflect_;
  a[0] = t.diffuse ? std::max(under * (1.0f - mu) * (1.0f - f0) * brdf_.diffuse_weight *
                                  max_component(brdf_.base_color),
                              1e-3f)
                   : 0.0f;
  a[1] = t.lobe ? std::max(under * ((1.0f - mu) * (f0 + (brdf_.dielectric_f90() - f0) *
                                                            schlick_weight(cos_o)) +
                                    mu * max_component(schlick_fresnel(brdf_.base_color, cos_o))),
                           1e-3f)
                : 0.0f;
  a[2] = t.coat ? std::max(k, 1e-3f) : 0.0f;
  a[3] = t.sheen ? std::max((1.0f - k) * e, 1e-3f) : 0.0f;
}

vec3 Bsdf::eval_with_view(const vec3& wo, const vec3& wi, const vec3& v, float* pdf) const {
  const Frame f(glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_, tangent_);
  const vec3 lo = f.local(wo), li = f.local(wi);
  const Terms t = term_flags();
  vec3 under(0.0f);  // everything below the coat
  float p[kTerms] = {0.0f, 0.0f, 0.0f, 0.0f};
  if (lo.z > 0.0f && li.z > 0.0f) {
    vec3 base(0.0f);
    if (t.diffuse) {
      base += diffuse_term(lo, li);
      p[0] = li.z / kPi;
    }
    if (t.lobe) {
      base += reflect_ * brdf_.eval_specular(lo, li);
      p[1] = brdf_.specular_pdf(lo, li);
    }
    // Rough glass's reflection (drawn apart from these terms: sample()).
    if (glass_in_part())
      base += glass_f(lo, li, glm::dot(wo, ng_) > 0.0f, Transport::Radiance, nullptr);
    under = sheen_scaling(lo.z, li.z) * base;
    if (t.sheen) {  // f_sheen + scaling x f_material (KHR_materials_sheen, "albedo scaling")
      under += sheen_ * sheen_dv(lo, li, sheen_alpha(sheen_roughness_));
      p[3] = 1.0f / (2.0f * kPi);  // drawn uniformly over the hemisphere
    }
  }
  const float k = coat_weight(v);
  vec3 out = (1.0f - k) * under;
  if (t.coat) out += vec3(k * coat_dv(wo, wi, &p[2]));
  if (pdf) {  // the mixture sample_non_delta draws from (its choice reads wo alone)
    float a[kTerms];
    term_albedos(wo, a);
    float sum = 0.0f, mix = 0.0f;
    for (int j = 0; j < kTerms; ++j) {
      sum += a[j];
      mix += a[j] * p[j];
    }
    *pdf = sum > 0.0f ? mix / sum : 0.0f;
  }
  return out;
}

float Bsdf::pdf(const vec3& wo, const vec3& wi) const {
  if (kind_ == Kind::Delta) return 0.0f;
  const vec3 ns = glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_;
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return 0.0f;
  if (kind_ == Kind::Lambertian)
    return std::max(0.0f, glm::dot(wi, ns)) / kPi;  // cosine-weighted about the shading normal
  const Frame f(ns, tangent_);
  float p = 0.0f;
  if (layered())
    eval_with_view(wo, wi, wo, &p);
  else
    eval_local(f.local(wo), f.local(wi), &p);
  return has_delta_ && !is_restricted() ? (1.0f - delta_probability(wo)) * p : p;
}

}  // namespace pb
