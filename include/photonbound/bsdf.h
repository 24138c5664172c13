// The three reflection models (scene.h Reflection) as pure functions of directions in world
// space. Directions point away from the surface; n is the side the incoming direction is on.
#pragma once

#include "photonbound/math.h"

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

struct Material;
struct Surface;

// How a transport quantity is carried: radiance (camera paths) picks up the (eta_i/eta_t)^2
// factor at refraction; photons carry flux and do not (Veach thesis section 5.2).
enum class Transport : uint8_t { Radiance, Importance };

struct SpecularBranch {
  vec3 dir{0.0f};
  vec3 weight{0.0f};  // throughput factor of the branch (Fresnel term included)
};

// The deterministic branches of a mirror (one) or a smooth dielectric (reflection and, unless
// totally internally reflected, refraction), for a path arriving from direction wo (pointing
// away from the surface). Dielectrics are closed meshes in vacuum: the side of ng tells whether
// the path enters (eta = ior) or leaves (eta = 1/ior). Returns the number of branches.
int specular_branches(const Material& material, const Surface& surface, const vec3& wo,
                      Transport mode, SpecularBranch out[2]);

}  // namespace pb
