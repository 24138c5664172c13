// KHR_materials_iridescence's Fresnel term: thin-film interference after Belcour and Barla 2017
// ("A Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence"), in the
// approximation the extension writes out ("Iridescence Fresnel"): Schlick's reflectance at the
// two interfaces (outside/film and film/base), the first-order optical path difference, and the
// analytic spectral integration of the first two interference terms against Gaussian fits of
// the CIE XYZ sensitivities, converted to linear Rec. 709 (photonbound's RGB).
#pragma once

#include "util/math.h"

namespace pb {

// Default film of the extension: iridescenceIor 1.3, thickness range [100, 400] nm.
inline constexpr float kDefaultIridescenceIor = 1.3f;
inline constexpr float kDefaultFilmMinimum = 100.0f, kDefaultFilmMaximum = 400.0f;

// The reflectance (per RGB channel) of a film of index film_ior and thickness `thickness_nm`
// between a medium of index outside_ior (1: air) and a base whose normal-incidence reflectance
// (seen from air) is base_f0, at the cosine cos_theta1 of the view with the microfacet normal
// (v.h). The extension's `iridescent_fresnel`, with two departures, both toward what a
// reflectance is: the result is clamped to [0, 1] (the extension clamps at 0 only; the colour
// conversion can push a saturated channel slightly past 1), and a thickness of 0 or less is no
// film, base_f0's Schlick reflectance (the formula itself would keep the film's interface).
// The base's f0 + 1e-4 (the extension's guard against an index of infinity) is kept at most
// 0.9999: above, the extension's formula gives a negative index. The phase shift of each RGB
// channel's base index is applied to the XYZ component of the same position, as the
// extension's GLSL does. 1 under total internal reflection into the film.
vec3 iridescent_fresnel(float outside_ior, float film_ior, const vec3& base_f0, float thickness_nm,
                        float cos_theta1);

}  // namespace pb
