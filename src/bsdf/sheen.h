// KHR_materials_sheen's BRDF (the extension's "Implementation Notes", as Khronos's sample
// renderer evaluates them): the "Charlie" microfibre distribution and visibility of Conty
// Estevez and Kulla 2017, and the directional albedo E the albedo-scaling layering needs.
// Local shading frame, +z the normal; cosines of the two directions above the surface.
#pragma once

#include "util/math.h"

namespace pb {

// The smallest sheen roughness used: below it the distribution's exponent 1 / roughness^2
// exceeds 200 and its peak along the horizon outgrows what float directions resolve (pbrt-v4
// and other renderers of this model clamp there too).
inline constexpr float kMinSheenRoughness = 0.07f;

// alpha = roughness^2 of the clamped roughness.
float sheen_alpha(float roughness);

// D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi), from h.z (Conty Estevez and Kulla,
// eq. 2). Its largest value, along the horizon, is (2 + 1/alpha) / (2 pi).
float charlie_d(float cos_h, float alpha);
inline float charlie_d_max(float alpha) { return (2.0f + 1.0f / alpha) / (2.0f * kPi); }

// V = 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 (n.v) (n.l)), clamped to [0, 1] as the sample
// renderer does, with the extension's fit of Lambda (its "Sheen visibility").
float charlie_visibility(float cos_o, float cos_i, float alpha);

// The sheen BRDF of white sheen colour: D V (no Fresnel term: "F = 1").
float sheen_dv(const vec3& wo, const vec3& wi, float alpha);

// E(cos_o) = integral of D V cos_i over the hemisphere: the directional albedo of the white
// sheen BRDF, from a table over (sqrt(cos_o), roughness) made once by quadrature (bilinear
// between its 33 x 33 entries; tests/bsdf/test_bsdf_sheen.cpp checks it against a finer
// quadrature). The model does not conserve energy toward the horizon at small roughness (E
// reaches 1.3 at cos_o = 0.02, roughness 0.07: V's clamp at 1 lets it), as the extension
// defines it.
float sheen_albedo(float cos_o, float roughness);

}  // namespace pb
