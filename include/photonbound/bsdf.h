// The three reflection models (scene.h Reflection): the Bsdf every stage asks, and the pure
// functions it is made of, of directions in world space. Directions point away from the
// surface; n is the side the incoming direction is on.
#pragma once

#include "photonbound/math.h"
#include "photonbound/rng.h"
#include "photonbound/scene.h"

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

// How a transport quantity is carried: radiance (camera paths) picks up the (eta_i/eta_t)^2
// factor at refraction; photons carry flux and do not (Veach thesis section 5.2).
enum class Transport : uint8_t { Radiance, Importance };

struct SpecularBranch {
  vec3 dir{0.0f};
  vec3 weight{0.0f};  // throughput factor of the branch (Fresnel term included)
};

struct BsdfSample {
  vec3 wi{0.0f};      // the new direction, unit
  vec3 weight{0.0f};  // f |cos| / pdf; for a delta lobe, the branch weight over its probability
  float pdf = 0.0f;   // solid-angle pdf; 0 for a delta lobe
  bool delta = false;
};

// A material's scattering at one surface point, as World::surface() makes it: the one thing
// the eye pass, the photon pass, next-event estimation and the gather ask about a surface.
// Directions point away from the surface; either side may be hit (the normals are flipped to
// the side of wo where that matters).
class Bsdf {
 public:
  Bsdf() = default;
  Bsdf(const Material& material, const vec3& ng, const vec3& ns);

  // Mirrors and smooth dielectrics scatter into isolated directions: no eval, only branches.
  bool is_delta() const { return model_ != Reflection::Lambertian; }
  // The Lambertian fast path: f is the constant diffuse_f() for every pair of directions on the
  // same side, so a gather may sum photon powers first and multiply once (bit for bit what
  // PPM did before this interface).
  bool is_lambertian() const { return model_ == Reflection::Lambertian; }
  vec3 diffuse_f() const { return lambertian(color_); }

  // f(wo, wi) without the cosine; 0 for delta lobes and for wi on the other side of ng.
  vec3 eval(const vec3& wo, const vec3& wi) const;
  // Solid-angle pdf of sample(); 0 for delta lobes.
  float pdf(const vec3& wo, const vec3& wi) const;
  // Draws wi (random numbers from rng, as many as the lobe needs); false when the sample is
  // absorbed (below the true surface) or carries nothing. Delta lobes choose one branch in
  // proportion to its average throughput.
  bool sample(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const;
  // The deterministic branches of a mirror (one) or a smooth dielectric (reflection and, unless
  // totally internally reflected, refraction). Dielectrics are closed meshes in vacuum: the side
  // of ng tells whether the path enters (eta = ior) or leaves (eta = 1/ior). Returns the count.
  int delta_branches(const vec3& wo, Transport mode, SpecularBranch out[2]) const;

 private:
  Reflection model_ = Reflection::Lambertian;
  vec3 color_{0.0f};  // reflectance (Lambertian, Mirror) or transmission tint (Dielectric)
  float ior_ = 1.5f;
  vec3 ng_{0.0f}, ns_{0.0f};
};

}  // namespace pb
