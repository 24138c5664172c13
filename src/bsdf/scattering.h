// The scattering helpers of a surface (free functions of directions in world space, used by
// the Bsdf's construction, eval, bounds, sampling and delta branches, and by the lights and the
// photon pass): Fresnel, reflection and refraction, the Lambertian value and the direction
// samplers, and the adjoint shading-normal factor. Directions point away from the surface.
#pragma once

#include "util/math.h"

namespace pb {

// Fresnel reflectance of a smooth dielectric for unpolarised light (Born & Wolf; pbrt-v4
// FrDielectric). cos_i: cosine on the incident side (> 0); eta: eta_transmitted / eta_incident.
// Returns 1 under total internal reflection.
float fresnel_dielectric(float cos_i, float eta);

// Mirror direction of w about n.
inline vec3 reflect(const vec3& w, const vec3& n) { return 2.0f * glm::dot(w, n) * n - w; }

// Refracts w (pointing away from the surface, on n's side) into the other side.
// eta = eta_transmitted / eta_incident. Returns false under total internal reflection.
bool refract(const vec3& w, const vec3& n, float eta, vec3& wt);

// Lambertian BRDF value rho / pi (symmetric in its directions).
inline vec3 lambertian(const vec3& rho) { return rho / kPi; }

// Cosine-weighted direction about n from two uniform numbers; pdf = cos / pi.
vec3 sample_cosine_hemisphere(const vec3& n, float u1, float u2);

// Uniform direction on the unit sphere; pdf = 1 / (4 pi).
vec3 sample_uniform_sphere(float u1, float u2);

// Uniform direction in the cone of directions within acos(cos_max) of axis; pdf = 1/(2 pi
// (1-cos_max)).
vec3 sample_uniform_cone(const vec3& axis, float cos_max, float u1, float u2);

// Veach's correction for shading normals in adjoint (photon) transport, thesis eq. 5.19:
// |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|), wo toward where the photon came from, wi the new direction.
// Without it, interpolated normals create or destroy energy in photon paths.
float adjoint_shading_factor(const vec3& wo, const vec3& wi, const vec3& ng, const vec3& ns);

}  // namespace pb
