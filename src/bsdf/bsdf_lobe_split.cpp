// SPPM's lobe split (camera_paths.h, ESTIMATOR.md section 10), kept whole in this file so that it
// can move to src/render/: has_lobe_below, follows_lobe, lobe_roughness, follows_coat,
// lobe_probability, base_part and lobe_part. Called by render/camera_paths.cpp (has_lobe_below,
// lobe_probability, lobe_part, base_part); is_base_part (bsdf.h) by render/pass_stages.cpp.
#include "bsdf/bsdf.h"

#include <algorithm>

namespace pb {

bool Bsdf::has_lobe_below(float below) const {
  if ((rough_glass_ || dt_ > 0.0f) && part_ == Part::All) return true;  // always followed
  if (layered())
    return kind_ == Kind::Layered && part_ == Part::All &&
           (follows_lobe(below) || follows_coat(below));
  if (kind_ != Kind::Layered || smooth_ || part_ != Part::All || !(lobe_roughness() < below))
    return false;
  return brdf_.metallic > 0.0f || brdf_.specular > 0.0f;
}

bool Bsdf::follows_lobe(float below) const {
  // With rough glass or diffuse transmission, followed anyway, the base's lobe is followed too:
  // a part then always splits as the lobes and the diffuse base.
  return base_non_delta_ && !smooth_ && (lobe_roughness() < below || rough_glass_ || dt_ > 0.0f) &&
         (brdf_.metallic > 0.0f || brdf_.specular > 0.0f);
}

float Bsdf::lobe_roughness() const {
  // An anisotropic lobe is followed or gathered as the isotropic one of the same peak D,
  // 1 / (pi ax ay): roughness (ax ay)^(1/4).
  if (!(brdf_.anisotropy > 0.0f)) return brdf_.roughness;
  return std::sqrt(std::sqrt(brdf_.alpha_x() * brdf_.alpha_y()));
}

bool Bsdf::follows_coat(float below) const { return coat_lobe() && coat_roughness_ < below; }

float Bsdf::lobe_probability(const vec3& wo, float below) const {
  // Rough glass and diffuse transmission are followed, always.
  const float glass =
      (rough_glass_ ? glass_albedo(wo) : 0.0f) + (dt_ > 0.0f ? dt_albedo(wo) : 0.0f);
  if (layered()) {  // the followed terms' share of the albedo estimates
    float all[kTerms], lobe[kTerms];
    term_albedos(wo, all);
    lobe_part(below).term_albedos(wo, lobe);
    float sum = glass, followed = glass;
    for (int j = 0; j < kTerms; ++j) {
      sum += all[j];
      followed += lobe[j];
    }
    return sum > 0.0f ? std::min(1.0f, followed / sum) : 0.0f;
  }
  // specular_probability reads only the cosine of wo with the shading normal.
  const float share = brdf_.specular_probability(vec3(0.0f, 0.0f, std::fabs(glm::dot(wo, ns_))));
  if (!rough_glass_ && !(dt_ > 0.0f)) return share;
  const float rest = base_non_delta_ ? non_delta_albedo(std::fabs(glm::dot(wo, ns_))) : 0.0f;
  const float lobe = follows_lobe(below) ? share * rest : 0.0f;
  return std::min(1.0f, (glass + lobe) / (glass + rest));
}

Bsdf Bsdf::base_part(float below) const {
  Bsdf b = *this;
  b.part_ = Part::Base;
  b.follow_lobe_ = follows_lobe(below);
  b.follow_coat_ = follows_coat(below);
  return b;
}

Bsdf Bsdf::lobe_part(float below) const {
  Bsdf b = *this;
  b.part_ = Part::Lobe;
  b.follow_lobe_ = follows_lobe(below);
  b.follow_coat_ = follows_coat(below);
  return b;
}

}  // namespace pb
