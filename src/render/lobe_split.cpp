// SPPM's lobe split (lobe_split.h, ESTIMATOR.md section 10), from the Bsdf's terms.
#include "render/lobe_split.h"

#include <algorithm>

namespace pb {

namespace {

bool follows_lobe(const Bsdf& bsdf, float below) {
  // With rough glass or diffuse transmission, followed anyway, the base's lobe is followed too:
  // a part then always splits as the lobes and the diffuse base.
  const TermSet t = bsdf.terms();
  return t.has(Term::Lobe) &&
         (bsdf.lobe_roughness() < below || t.has(Term::Glass) || t.has(Term::Transmission)) &&
         bsdf.lobe_reflects();
}

bool follows_coat(const Bsdf& bsdf, float below) {
  return bsdf.terms().has(Term::Coat) && bsdf.coat_roughness() < below;
}

}  // namespace

bool has_lobe_below(const Bsdf& bsdf, float below) {
  if (bsdf.is_restricted() || bsdf.is_lambertian() || bsdf.is_delta()) return false;
  const TermSet t = bsdf.terms();
  if (t.has(Term::Glass) || t.has(Term::Transmission)) return true;  // always followed
  if (bsdf.layered()) return follows_lobe(bsdf, below) || follows_coat(bsdf, below);
  if (!t.has(Term::Lobe) || !(bsdf.lobe_roughness() < below)) return false;
  return bsdf.lobe_reflects();
}

float lobe_probability(const Bsdf& bsdf, const vec3& wo, float below) {
  // Rough glass and diffuse transmission are followed, always.
  const TermSet t = bsdf.terms();
  const bool rough_glass = t.has(Term::Glass), dt = t.has(Term::Transmission);
  const float glass =
      (rough_glass ? bsdf.glass_albedo(wo) : 0.0f) + (dt ? bsdf.dt_albedo(wo) : 0.0f);
  if (bsdf.layered()) {  // the followed terms' share of the albedo estimates
    float all[Bsdf::kLayerTerms], lobe[Bsdf::kLayerTerms];
    bsdf.term_albedos(wo, all);
    lobe_part(bsdf, below).term_albedos(wo, lobe);
    float sum = glass, followed = glass;
    for (int j = 0; j < Bsdf::kLayerTerms; ++j) {
      sum += all[j];
      followed += lobe[j];
    }
    return sum > 0.0f ? std::min(1.0f, followed / sum) : 0.0f;
  }
  const float share = bsdf.lobe_share(wo);
  if (!rough_glass && !dt) return share;
  const float rest = t.has(Term::Diffuse) ? bsdf.unlayered_albedo(wo) : 0.0f;
  const float lobe = follows_lobe(bsdf, below) ? share * rest : 0.0f;
  return std::min(1.0f, (glass + lobe) / (glass + rest));
}

Bsdf base_part(const Bsdf& bsdf, float below) {
  // Without a layer the base is the diffuse base alone: a lobe not followed there is a mirror
  // (a delta branch) or reflects nothing.
  return bsdf.restricted(TermSet{}
                             .with(Term::Diffuse)
                             .with(Term::Sheen)
                             .with(Term::Lobe, bsdf.layered() && !follows_lobe(bsdf, below))
                             .with(Term::Coat, !follows_coat(bsdf, below)));
}

Bsdf lobe_part(const Bsdf& bsdf, float below) {
  return bsdf.restricted(TermSet{}
                             .with(Term::Lobe, follows_lobe(bsdf, below))
                             .with(Term::Coat, follows_coat(bsdf, below))
                             .with(Term::Glass)
                             .with(Term::Transmission));
}

}  // namespace pb
