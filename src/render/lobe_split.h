// SPPM's lobe split (ESTIMATOR.md section 10): at a GGX lobe rougher than the mirror but below
// --follow-roughness a camera path chooses to follow the lobe (sampling it) or to gather
// photons at the rest of the non-delta part, the diffuse base (camera_paths.cpp). The split is
// the integrator's: it is made of the Bsdf's general operations, its terms (Bsdf::terms), their
// albedo estimates and Bsdf::restricted. Rough glass and diffuse transmission are always
// followed (photons that cross the surface are not gathered), and with them the base's GGX
// lobe. All but is_base_part take an unrestricted Bsdf (World::surface's).
#pragma once

#include "bsdf/bsdf.h"

namespace pb {

// True when the non-delta part has a GGX lobe that is not a mirror, of roughness below
// `below`, that can reflect something (metal, or a dielectric layer with specular > 0), or a
// clear coat's lobe (not a mirror) of roughness below `below`, or rough glass or diffuse
// transmission. The lobes below `below` are followed, the rest (the diffuse base, and a lobe at
// or above `below`) gathered. False for a restricted Bsdf.
bool has_lobe_below(const Bsdf& bsdf, float below);

// The probability of following the lobe instead of gathering at the base: the followed terms'
// share of the terms' albedo estimates (without layers MetalRoughBrdf::specular_probability,
// Bsdf::lobe_share); 1 where the base is black (metal).
float lobe_probability(const Bsdf& bsdf, const vec3& wo, float below);

// The Bsdf restricted to the base (base_part: the diffuse base, the sheen and the lobes not
// followed) or to the followed part (lobe_part: the followed lobes, rough glass and diffuse
// transmission): eval, max_f and pdf of those terms alone, and sample() draws from them alone
// (never a delta branch). base_part + lobe_part = the non-delta part. Only for a Bsdf with
// has_lobe_below(1) (any lobe).
Bsdf base_part(const Bsdf& bsdf, float below);
Bsdf lobe_part(const Bsdf& bsdf, float below);

// A visible point on a base_part() is where a camera path chose not to follow the lobe after
// it had counted the vertex's direct light with the whole Bsdf: the next-event stage skips it.
// (base_part keeps the diffuse base, lobe_part never does.)
inline bool is_base_part(const Bsdf& bsdf) {
  return bsdf.is_restricted() && bsdf.kept().has(Term::Diffuse);
}

}  // namespace pb
