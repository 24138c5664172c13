// The glTF 2.0 metallic-roughness BRDF (glTF 2.0 specification, appendix B "BRDF
// Implementation"): GGX microfacet reflection with height-correlated Smith masking-shadowing,
// Schlick's Fresnel, a Lambertian base, and sampling of the visible normals (Heitz 2018).
//
// Everything is in a local shading frame whose normal is +z; the caller maps directions to and
// from world space with an orthonormal basis. Directions are unit vectors pointing away from the
// surface: wo toward the viewer (where light goes), wi toward the light (where it came from).
// Reflection only: any direction with z <= 0 gets value and density 0.
#pragma once

#include "bsdf/mirror_roughness.h"

#include "util/math.h"

namespace pb {

// Smallest GGX alpha the functions below use (roughness 0.01); smaller alphas are raised to it,
// so roughness 0 gives no NaN or infinity (the peak of D is 1/(pi alpha^2) = 3.2e7). Down to it,
// values and densities are exact to float rounding for the float directions given. What float
// directions cannot do is resolve a lobe close to their spacing (6e-8): the reflected lobe is
// about 2 alpha wide in the plane of incidence and 2 alpha wo.z across it, so the directions
// sample() draws follow pdf() (chi-square, 4e5 samples) only while alpha wo.z >= 1e-6, and
// integrals over float directions are good to 1e-3 at alpha = 1e-4, wo.z = 0.01
// (tests/test_microfacet*.cpp). A renderer should treat smaller roughness as a perfect mirror:
// roughness >= 0.032 (alpha >= 1e-3) keeps alpha wo.z >= 1e-6 down to wo.z = 1e-3.
inline constexpr float kMinGgxAlpha = 1e-4f;

// glTF's remapping of perceptual roughness: alpha = roughness^2 (appendix B "Specular BRDF"),
// roughness clamped to [0, 1] and alpha raised to kMinGgxAlpha.
float ggx_alpha(float roughness);

// The functions below take alpha in [kMinGgxAlpha, 1] (smaller values are raised to the
// minimum) and unit vectors in the local frame.

// GGX (Trowbridge-Reitz) normal distribution D(h) (Walter et al. 2007, eq. 33; glTF appendix B
// "Specular BRDF"). Normalised over projected area: integral of D(h) h.z over the hemisphere is
// 1. Zero for h.z <= 0.
float ggx_d(const vec3& h, float alpha);

// Smith's Lambda for GGX (Heitz 2014, eq. 72):
// (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2, written without cancellation. Infinite for w.z <= 0.
float smith_lambda(const vec3& w, float alpha);

// Smith masking G1(w) = 1 / (1 + Lambda(w)) (Heitz 2014; for GGX the same as Walter et al.
// 2007, eq. 34). Zero for w.z <= 0.
float smith_g1(const vec3& w, float alpha);

// Height-correlated masking-shadowing G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014,
// eq. 99), which is glTF appendix B's G for directions above the surface. Zero if either is below.
float smith_g2(const vec3& wo, const vec3& wi, float alpha);

// glTF's visibility term V = G2 / (4 |n.l| |n.v|) from the cosines of the two directions
// (appendix B "Specular BRDF"): 1 / (2 (|n.v| sqrt(a^2 + (1-a^2)(n.l)^2) + |n.l| sqrt(a^2 +
// (1-a^2)(n.v)^2))). Symmetric in its two cosines. Cosines below kMinCosine are raised to it,
// which keeps V D finite when both directions graze the surface.
inline constexpr float kMinCosine = 1e-7f;
float ggx_visibility(float cos_o, float cos_i, float alpha);

// Distribution of visible normals D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z (Heitz 2018,
// eq. 3); integrates to 1 over h for every wo above the surface. Zero when wo.z <= 0.
float ggx_vndf(const vec3& wo, const vec3& h, float alpha);

// A microfacet normal h distributed by D_wo, from two uniform numbers in [0, 1) (Heitz 2018,
// "Sampling the GGX Distribution of Visible Normals", listing 1, isotropic). wo.z > 0.
vec3 sample_ggx_vndf(const vec3& wo, float alpha, float u1, float u2);

// Density, per solid angle of wi, of wi = reflect(wo, h) with h from sample_ggx_vndf:
// D_wo(h) / (4 |wo.h|) (Heitz 2018, eq. 17) = D(h) / (2 (wo.z + sqrt(alpha^2 + (1 - alpha^2)
// wo.z^2))), which stays finite at grazing wo. Zero unless wo.z > 0 and wi.z > 0 (the sampler's
// reflections below the surface are rejected by the caller).
float ggx_reflection_pdf(const vec3& wo, const vec3& wi, float alpha);

// Anisotropic GGX (KHR_materials_anisotropy; Heitz 2014, section 5.4; Burley 2012): the
// same functions with the roughness alpha_x along the local frame's x (the anisotropy
// direction) and alpha_y along y. With alpha_x = alpha_y they equal the isotropic ones above to
// float rounding (tests/test_microfacet_aniso.cpp); the isotropic ones stay what isotropic
// materials use, bit for bit.
// D(h) = 1 / (pi ax ay (hx^2/ax^2 + hy^2/ay^2 + hz^2)^2), normalised over projected area.
float ggx_d(const vec3& h, float alpha_x, float alpha_y);
// Smith's G1 with Lambda(w) = (-1 + sqrt(1 + (ax^2 wx^2 + ay^2 wy^2) / wz^2)) / 2.
float smith_g1(const vec3& w, float alpha_x, float alpha_y);
// V = G2 / (4 |n.l| |n.v|) = 1 / (2 (zi |(ax wo.x, ay wo.y, zo)| + zo |(ax wi.x, ay wi.y, zi)|))
// (the extension's V_GGX_anisotropic without its clamp to 1, which the isotropic V of glTF's
// core BRDF does not have either: the two agree as the strength goes to 0). Symmetric in wo, wi.
float ggx_visibility(const vec3& wo, const vec3& wi, float alpha_x, float alpha_y);
// D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z, and Heitz 2018's sampling of it (listing 1 with
// the stretch (ax, ay)).
float ggx_vndf(const vec3& wo, const vec3& h, float alpha_x, float alpha_y);
vec3 sample_ggx_vndf(const vec3& wo, float alpha_x, float alpha_y, float u1, float u2);
// Density of wi = reflect(wo, h), h by sample_ggx_vndf: D(h) / (2 (wo.z + |(ax wo.x, ay wo.y,
// wo.z)|)).
float ggx_reflection_pdf(const vec3& wo, const vec3& wi, float alpha_x, float alpha_y);

// Schlick's weight (1 - |cos|)^5 and Fresnel f0 + (1 - f0)(1 - |cos|)^5 (Schlick 1994; glTF
// appendix B "Fresnel"), with cos = v.h.
float schlick_weight(float cos_theta);
inline float schlick_fresnel(float f0, float cos_theta) {
  return f0 + (1.0f - f0) * schlick_weight(cos_theta);
}
inline vec3 schlick_fresnel(const vec3& f0, float cos_theta) {
  return f0 + (vec3(1.0f) - f0) * schlick_weight(cos_theta);
}

// KHR_materials_clearcoat's layer weight k = clearcoat x Schlick's Fresnel of ior 1.5 (f0 =
// 0.04) at |cos| with the coat's normal: what the coat reflects of the view (Bsdf), and 1 - k
// what it lets through of the emission below it (the extension's "Emission").
inline float clearcoat_fresnel(float coat, float cos_theta) {
  return coat == 0.0f ? 0.0f : coat * schlick_fresnel(0.04f, cos_theta);
}

// Normal-incidence reflectance of a dielectric: ((ior - 1) / (ior + 1))^2 (glTF appendix B
// "Fresnel", fresnel_mix); 0.04 at ior 1.5.
float dielectric_f0(float ior);

// glTF's metallic-roughness material as a BRDF (appendix B "Metal BRDF and Dielectric BRDF"):
//   specular   = V D                                    (alpha = roughness^2)
//   metal      = specular * schlick_fresnel(base_color, v.h)
//   dielectric = mix(base_color / pi, specular, schlick_fresnel(dielectric_f0(ior), v.h))
//   material   = mix(dielectric, metal, metallic)
// with KHR_materials_specular's generalisation of the dielectric's Fresnel term (its README,
// "Implementation"): F = f0 + (f90 - f0) (1 - v.h)^5, f0 = min(dielectric_f0(ior)
// specular_color, 1) specular, f90 = specular, dielectric = F specular + (1 - max(F)) base / pi,
// which is appendix B's dielectric when specular = 1 and specular_color = 1 (the defaults).
// The spec says (appendix B "Coupling Diffuse and Specular Reflection") that this model is not
// energy conserving: fresnel_mix weights the diffuse base by 1 - F(v.h) at the half vector of
// each pair of directions, so a bright dielectric reflects more than it receives at oblique
// angles. A white one (roughness 0.05) has albedo 1.15 at wo.z = 0.3 and 1.84 near grazing, 1.04
// averaged over incidence; tests/bsdf/test_microfacet.cpp gives the brightest base colour that
// stays
// <= 1 per roughness. The metal lobe conserves energy (single scattering loses some when rough).
struct MetalRoughBrdf {
  vec3 base_color{1.0f};      // linear RGB in [0, 1]: diffuse colour, and f0 of the metal
  float metallic = 0.0f;      // [0, 1]: 0 dielectric, 1 metal
  float roughness = 1.0f;     // [0, 1], perceptual; alpha = roughness^2
  float ior = 1.5f;           // > 0, index of refraction of the dielectric's specular layer
  vec3 specular_color{1.0f};  // KHR_materials_specular specularColorFactor (>= 0)
  float specular = 1.0f;      // KHR_materials_specular specularFactor in [0, 1]; 0: no layer
  // KHR_materials_anisotropy strength in [0, 1]: the lobe's alpha along the local x axis is
  // mix(alpha, 1, anisotropy^2), along y alpha (the extension's at and ab). 0: isotropic.
  float anisotropy = 0.0f;
  // KHR_materials_iridescence: the film's weight in [0, 1] (0: none), index and thickness (nm).
  // Its Fresnel term (thin_film.h) is mixed into both layers' by the weight (below).
  float iridescence = 0.0f;
  float iridescence_ior = 1.3f;
  float iridescence_thickness = 400.0f;
  // KHR_materials_diffuse_transmission: the share of the diffuse base reflected (1 - dt).
  float diffuse_weight = 1.0f;

  // The Fresnel terms of the two layers at cos = v.h: the dielectric's F = f0 + (f90 - f0)
  // (1 - cos)^5 and the metal's Schlick of base_color, each mixed with the iridescent Fresnel
  // of its own f0 by `iridescence` (the extension's iridescent_dielectric_layer with
  // KHR_materials_specular, and iridescent_conductor_layer). Without iridescence, Schlick's.
  vec3 layer_fresnel(float cos_theta) const;
  vec3 metal_fresnel(float cos_theta) const;

  // The lobe's alphas along x and y (equal without anisotropy).
  float alpha_x() const;
  float alpha_y() const { return ggx_alpha(roughness); }
  // The lobe's own density of wi = reflect(wo, h), h by its visible normals, and a draw of h.
  float specular_pdf(const vec3& wo, const vec3& wi) const;
  vec3 sample_specular_normal(const vec3& wo, float u1, float u2) const;

  // The dielectric layer's Fresnel terms at normal and grazing incidence (above).
  vec3 dielectric_f0() const;
  float dielectric_f90() const { return specular; }

  // f(wo, wi) without the cosine. Zero unless wo.z > 0 and wi.z > 0. Reciprocal: every term is
  // symmetric in wo and wi, so eval(wo, wi) == eval(wi, wo) bit for bit (unless the compiler
  // contracts a*b + c*d into a fused multiply-add, which costs one rounding).
  vec3 eval(const vec3& wo, const vec3& wi) const;

  // The two terms eval() is the sum of (up to float rounding): the diffuse base
  // (1 - metallic) (1 - max F) base_color / pi, and the GGX lobe, (1 - metallic) F V D +
  // metallic F_metal V D. SPPM's camera paths follow the lobe and gather at the base
  // (camera_paths.h).
  vec3 eval_diffuse(const vec3& wo, const vec3& wi) const;
  vec3 eval_specular(const vec3& wo, const vec3& wi) const;
  // The GGX lobe alone: wi = reflect(wo, h), h by its visible normals, pdf =
  // ggx_reflection_pdf, weight = eval_specular(wo, wi) wi.z / pdf. False when wo.z <= 0 or wi
  // falls below the surface. A failed draw counts as 0: weight divides by the density over the
  // upper hemisphere, so E[weight g(wi)] = integral of f_lobe cos g for every g.
  bool sample_specular(const vec3& wo, float u1, float u2, vec3& wi, vec3& weight,
                       float& pdf) const;

  // Density per solid angle of wi that sample() draws from wo: the mixture
  // p_spec * ggx_reflection_pdf + (1 - p_spec) * wi.z / pi, p_spec = specular_probability(wo).
  // Zero unless wo.z > 0 and wi.z > 0. Its integral over the hemisphere is below 1 by the
  // probability that the specular lobe's reflection falls below the surface (sample() fails).
  float pdf(const vec3& wo, const vec3& wi) const;

  // Draws wi: the specular lobe by its visible normals with probability
  // specular_probability(wo) (chosen by u_lobe < p_spec), else the cosine-weighted diffuse
  // lobe, from the uniform numbers u1, u2. Returns false (wi, weight, pdf unspecified) when
  // wo.z <= 0 or the reflection falls below the surface. On success pdf = pdf(wo, wi) > 0 and
  // weight = eval(wo, wi) * wi.z / pdf, finite.
  bool sample(const vec3& wo, float u_lobe, float u1, float u2, vec3& wi, vec3& weight,
              float& pdf) const;

  // Probability that sample() takes the specular lobe, from estimates of the two lobes'
  // albedos (Schlick's Fresnel at the macro normal for the specular, (1 - f0) max(base_color)
  // for the diffuse; F and f0 of the dielectric layer are their largest channel):
  //   s = (1 - metallic) F(f0, f90, wo.z) + metallic max(F(base_color, wo.z))
  //   d = (1 - metallic) (1 - f0) max(base_color)
  //   p_spec = s / (s + d), or 1 when s + d = 0.
  // Either way the mixture density is positive wherever the BRDF is: when p_spec < 1 the
  // cosine lobe covers the whole hemisphere, and when p_spec = 1 (metallic = 1, black base
  // colour, or f0 = 1: exactly where the diffuse lobe vanishes) so does the visible-normal lobe,
  // since D > 0 for every h above the surface.
  float specular_probability(const vec3& wo) const;
};

}  // namespace pb
