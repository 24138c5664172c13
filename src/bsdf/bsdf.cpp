// The Bsdf's construction: glTF's material parameters to its parts (bsdf.h).
#include "bsdf/bsdf.h"

#include <algorithm>

namespace pb {

BsdfParams BsdfParams::of(const Material& m) {
  BsdfParams p;
  p.base_color = m.base_color;
  p.metallic = m.metallic;
  p.roughness = m.roughness;
  p.ior = m.ior;
  p.specular = m.specular;
  p.specular_color = m.specular_color;
  p.transmission = m.transmission;
  p.thin = m.thin;
  p.clearcoat = m.clearcoat;
  p.clearcoat_roughness = m.clearcoat_roughness;
  p.sheen_color = m.sheen_color;
  p.sheen_roughness = m.sheen_roughness;
  p.anisotropy = m.anisotropy;
  p.iridescence = m.iridescence;
  p.iridescence_ior = m.iridescence_ior;
  p.iridescence_thickness = m.iridescence_thickness_maximum;  // the texture's 1 (none: 1)
  p.dispersion = m.dispersion;
  p.diffuse_transmission = m.diffuse_transmission;
  p.diffuse_transmission_color = m.diffuse_transmission_color;
  return p;
}

Bsdf::Bsdf(const BsdfParams& p, const vec3& ng, const vec3& ns, float mirror_roughness)
    : thin_(p.thin), ng_(ng), ns_(ns) {
  brdf_.base_color = p.base_color;
  brdf_.roughness = p.roughness;
  brdf_.ior = p.ior;
  brdf_.specular = p.specular;
  brdf_.specular_color = p.specular_color;
  if (p.iridescence > 0.0f) {
    brdf_.iridescence = std::min(p.iridescence, 1.0f);
    brdf_.iridescence_ior = p.iridescence_ior;
    brdf_.iridescence_thickness = p.iridescence_thickness;
  }
  const float m = std::clamp(p.metallic, 0.0f, 1.0f), t = std::clamp(p.transmission, 0.0f, 1.0f);
  const float coat = std::clamp(p.clearcoat, 0.0f, 1.0f);
  const float sheen = max_component(p.sheen_color);
  const float dt = p.follows_transmission ? std::clamp(p.diffuse_transmission, 0.0f, 1.0f) : 0.0f;
  if (m == 0.0f && t == 0.0f && p.specular == 0.0f && coat == 0.0f && !(sheen > 0.0f) &&
      brdf_.iridescence == 0.0f && dt == 0.0f) {
    brdf_.metallic = 0.0f;
    reflect_ = 1.0f;
    return;  // kind_ Lambertian
  }
  // KHR_materials_transmission: dielectric = fresnel_mix(mix(diffuse, btdf, t), specular) is
  // (1 - t) fresnel_mix(diffuse, specular) + t fresnel_mix(btdf, specular): the parts split.
  glass_ = (1.0f - m) * t;
  // Rough glass (bsdf_glass.cpp) where the transmitting part's roughness is at or above the
  // mirror's, unless it is asked to be smooth (PPM). A volume of index 1 does not refract at any
  // microfacet: its transmission is straight through, a delta branch (Walter's half vector
  // eta wi + wo vanishes there).
  rough_glass_ = glass_ > 0.0f && p.follows_transmission && !(p.roughness < mirror_roughness) &&
                 (p.thin || std::fabs(p.ior - 1.0f) > 1e-4f);
  // KHR_materials_dispersion changes only a smooth volume's refraction.
  if (!p.thin && glass_ > 0.0f && p.dispersion > 0.0f && !rough_glass_) dispersion_ = p.dispersion;
  reflect_ = m + (1.0f - m) * (1.0f - t);
  brdf_.metallic = reflect_ > 0.0f ? m / reflect_ : 0.0f;
  // KHR_materials_diffuse_transmission: the opaque dielectric's diffuse base becomes
  // mix(diffuse_brdf(baseColor), diffuse_btdf(colour), dt); the BTDF is a component of its own
  // (bsdf_glass.cpp), the BRDF keeps 1 - dt.
  if (dt > 0.0f && reflect_ * (1.0f - brdf_.metallic) > 0.0f) {
    dt_ = dt;
    dt_color_ = glm::clamp(p.diffuse_transmission_color, vec3(0.0f), vec3(1.0f));
    brdf_.diffuse_weight = 1.0f - dt;
  }
  if (p.anisotropy > 0.0f) {  // KHR_materials_anisotropy: the direction in ns's tangent plane
    const vec3 d = p.anisotropy_direction - glm::dot(p.anisotropy_direction, ns) * ns;
    const float len = glm::length(d);
    if (len > 1e-6f && std::isfinite(len)) {
      tangent_ = d / len;
      brdf_.anisotropy = std::min(p.anisotropy, 1.0f);
    }
  }
  // A mirror only when the lobe is narrow in every direction (the anisotropic alpha_x).
  smooth_ = brdf_.anisotropy > 0.0f ? std::sqrt(brdf_.alpha_x()) < mirror_roughness
                                    : p.roughness < mirror_roughness;
  // A Lambertian under a coat or a sheen: its layer reflects nothing, so it has no mirror either.
  if ((coat > 0.0f || sheen > 0.0f) && m == 0.0f && p.specular == 0.0f) smooth_ = false;
  const float opaque = (1.0f - m) * (1.0f - t);
  base_non_delta_ = reflect_ > 0.0f && (!smooth_ || opaque > 0.0f);
  bool non_delta = base_non_delta_ || rough_glass_;
  bool delta = (glass_ > 0.0f && !rough_glass_) || (smooth_ && reflect_ > 0.0f);
  if (coat > 0.0f) {  // KHR_materials_clearcoat
    coat_ = coat;
    coat_smooth_ = p.clearcoat_roughness < mirror_roughness;
    coat_roughness_ = p.clearcoat_roughness;
    const float len = glm::length(p.coat_normal);
    nc_ = len > 0.0f ? p.coat_normal / len : ns;
    if (glm::dot(nc_, ng) < 0.0f) nc_ = -nc_;
    non_delta = non_delta || !coat_smooth_;
    delta = delta || coat_smooth_;
  }
  if (sheen > 0.0f) {  // KHR_materials_sheen: a broad lobe of its own, never a mirror
    sheen_ = glm::max(p.sheen_color, vec3(0.0f));
    sheen_roughness_ = p.sheen_roughness;
    non_delta = true;
  }
  kind_ = non_delta ? Kind::Layered : Kind::Delta;
  has_delta_ = non_delta && delta;
}

float Bsdf::lobe_roughness() const {
  // An anisotropic lobe is followed or gathered as the isotropic one of the same peak D,
  // 1 / (pi ax ay): roughness (ax ay)^(1/4).
  if (!(brdf_.anisotropy > 0.0f)) return brdf_.roughness;
  return std::sqrt(std::sqrt(brdf_.alpha_x() * brdf_.alpha_y()));
}

}  // namespace pb
