// All emitters of a scene (punctual and directional lights, emissive triangles and the
// environment) behind one sampler that chooses an emitter in proportion to its power, for photon
// emission and next-event estimation.
#pragma once

#include "scene/environment.h"
#include "scene/scene.h"
#include "util/rng.h"

#include <optional>
#include <span>
#include <vector>

namespace pb {

struct EmittedPhoton {
  vec3 origin{0.0f};
  vec3 dir{0.0f};
  vec3 flux{0.0f};     // power carried, already divided by every sampling probability
  vec3 normal{0.0f};   // surface normal at the origin (area lights), 0 off any surface
  float error = 0.0f;  // the origin's position error bound along normal (ray_offset.h)
};

// The uniform numbers a photon's emission draws, in the order Lights::sample_photon draws them
// from an Rng: the emitter choice, then two pairs (a punctual light's direction; a triangle's
// position, then its direction; the environment's direction, then the point it enters by) and
// the side of a two-sided triangle. A photon guide (render/photon_guide.h) warps some of them
// before the emission reads them: importance sampling in this primary sample space.
struct PrimarySample {
  static constexpr int kDims = 7;
  float u[kDims] = {};
  int next = 0;
  float next_float() { return next < kDims ? u[next++] : 0.5f; }
};

struct DirectSample {
  vec3 wi{0.0f};       // unit direction from the receiver toward the light
  float distance = 0;  // to the sampled light point; infinite for directional and environment
  vec3 li{0.0f};       // incident radiance times geometry over pdf, without the receiver's cosine
  // How far before `distance` a shadow ray must stop so as not to find the light's own surface
  // by rounding (World::occluded): the sample's error bound on an emissive triangle, 0 for
  // punctual lights.
  float margin = 0.0f;
  // Drawn from the environment: the solid-angle density of that draw, its choice included
  // (next-event MIS against the Bsdf's own draws, render/next_event.cpp); 0 otherwise.
  float environment_pdf = 0.0f;
};

// Direction from p uniform in the solid angle the triangle (v0, v1, v2) subtends, from two
// uniform numbers. False when the solid angle is too small or too close to 2 pi to sample
// reliably (the caller then samples by area).
bool sample_spherical_triangle(const vec3& v0, const vec3& v1, const vec3& v2, const vec3& p,
                               float u0, float u1, vec3& dir, float& solid_angle);

// atan2(y, x) for y >= 0, in [0, pi], within 1e-5 (next-event choice weights, lights_direct.cpp).
float atan2_upper(float y, float x);

// The power formulas the light sampler and the loader's range check share (W per channel).
// A one-sided Lambertian emitter of radiance Le and area A emits pi A Le; a double-sided one
// twice that.
template <class S, class V>
V lambertian_emitter_power(S area, const V& radiance) {
  return S(kPiD) * area * radiance;
}
//
// Directional and environment light enter the scene through a disc of radius
// emission_radius(bounds) perpendicular to their direction, just outside the bounding sphere
// (pbrt-v4's DistantLight and infinite lights do the same): a directional light of irradiance E
// delivers pi r^2 E, an environment pi r^2 times its radiance integrated over the sphere.
float emission_radius(const Bounds& bounds);
vec3 punctual_power(const PunctualLight& light, float radius);
vec3 environment_power(const EnvironmentLight& env, float radius);
// Every emitter of the scene, summed over channels, in double (so that a float overflow shows).
double total_emitted_power(const Scene& scene);
// True when the scene has an emitter of positive power (a light, an emissive triangle or the
// environment).
bool has_light(const Scene& scene);

class Lights {
 public:
  // At most about piece_budget pieces of textured emitters in all (see kPieceBudget).
  static constexpr double kPieceBudget = double(1 << 20);
  explicit Lights(const Scene& scene, double piece_budget = kPieceBudget);

  // Total emitted power per channel (W, in the image's radiance units times m^2 sr); textured
  // emitters by the midpoint rule on their pieces (photon fluxes carry the exact radiance).
  vec3 total_power() const { return total_power_; }
  size_t emitter_count() const { return probability_.size(); }  // pieces counted one by one

  EmittedPhoton sample_photon(Rng& rng) const;
  EmittedPhoton sample_photon(PrimarySample& u) const;
  // The first of the two primary-sample dimensions that choose the direction of a photon of
  // the emitter u0 picks: 1 for punctual lights and the environment (the first pair), 3 for a
  // triangle (the second pair; the first places it on the triangle).
  int direction_pair(float u0) const;
  // The largest channel of the power any emitted photon can carry (before the division by the
  // photons per pass): emitter power over its choice probability; for a map, its largest
  // radiance over its sampling density.
  float max_photon_flux() const { return max_photon_flux_; }
  // One emitter and one direction toward it for a receiver with unit normal `normal` (the side
  // it is seen from; a uniform environment is sampled by the cosine about it). False when the
  // sample cannot contribute (back side of a one-sided emitter, outside a cone).
  bool sample_direct(const vec3& receiver, const vec3& normal, Rng& rng, DirectSample& out) const;

  // The density with which sample_direct draws wi through the environment for this receiver
  // (its choice of the environment times the environment's solid-angle density about `normal`);
  // 0 without an environment.
  float environment_pdf(const vec3& receiver, const vec3& normal, const vec3& wi) const;

  // Radiance of the environment seen along dir (camera rays that leave the scene); 0 without one.
  vec3 environment_radiance(const vec3& dir) const {
    return environment_ ? environment_->radiance(dir) : vec3(0.0f);
  }
  const std::optional<EnvironmentLight>& environment() const { return environment_; }

 private:
  // An emissive triangle, or a piece of a textured one: a textured emitter is cut into n^2
  // pieces (n from the texels it covers) so that choosing pieces by their power follows the
  // texture; the radiance at a sampled point is then looked up (radiance_at).
  struct Triangle {
    vec3 p0, e1, e2;
    vec3 normal;  // front side, from the winding
    float area;
    float error;             // position error bound along normal of points on it (ray_offset.h)
    vec3 radiance;           // emitted radiance; textured: its mean over the piece
    float select = 0.0f;     // radiance the choice weights use: average(radiance), or for a
                             // textured piece at least a tenth of its brightest texel
    float peak = 0.0f;       // textured: the largest channel its radiance can reach
    bool two_sided = false;  // doubleSided: emits from both sides
    int32_t source = -1;     // textured: index into sources_
    float coat = 0.0f;       // KHR_materials_clearcoat's clearcoatFactor: darkens the emission
  };
  // Where a textured piece lies in its mesh triangle: the triangle's barycentrics (b1, b2) of
  // the piece's vertex 0 and the steps along its two edges.
  struct Source {
    const Mesh* mesh;
    const Material* material;
    uint32_t tri;
    vec2 b0, d1, d2;
  };
  void add_textured(const Mesh& mesh, const Material& mat, uint32_t tri, const Triangle& whole);
  // Pieces per side a textured triangle asks for (about a quarter texel each, at most 32), and
  // the texels it covers (-1 without a texture or a finite count).
  int textured_split(const Mesh& mesh, const Material& mat, uint32_t tri, double* texels) const;
  // At most kPieceBudget pieces in all (about 130 bytes each): a model with large emissive maps
  // (glTF-Sample-Assets' StainedGlassLamp: 2048^2 maps on every material, 16M quarter-texel
  // pieces, 2.1 GB and 34 s of setup) gets pieces of several texels instead. Each triangle's
  // pieces per side are scaled by split_scale_ (1 below the budget).
  float split_scale_ = 1.0f;
  // The radiance at barycentrics (c1, c2) of piece t (of its vertices 1 and 2).
  vec3 radiance_at(const Triangle& t, float c1, float c2) const;
  // Emitter k < punctual_.size() is a punctual or directional light, then come the triangles,
  // then the environment (when there is one).
  size_t pick(float u) const;
  // Next-event choice weight of emitter k at a receiver (used for small emitter sets).
  float local_weight(size_t k, const vec3& receiver) const;
  // Every emitter's local_weight for this receiver, and their sum (at most kLocalSelectionMax).
  float local_weights(const vec3& receiver, float* weights) const;
  // The probability that sample_direct chooses emitter k for this receiver.
  float choice_probability(size_t k, const vec3& receiver) const;
  // Up to this many emitters, the choice is by radiance x solid angle at the receiver; beyond,
  // by power, which is heavy-tailed where a weak emitter is close: with the 24 emitting
  // triangles of closed_block.gltf chosen by power, the 90% bound covered 80% after 16 passes
  // (90% with the local choice). A light tree (pbrt-v4's BVHLightSampler) would remove the cap.
  static constexpr size_t kLocalSelectionMax = 32;
  static float plane_tolerance(const Triangle& t, const vec3& receiver);
  static float shadow_margin(const Triangle& t, const vec3& receiver, float cos_light);
  vec3 spot_falloff(const PunctualLight& light, const vec3& dir) const;
  // A photon entering through the disc (emission_radius) perpendicular to `travel`.
  EmittedPhoton from_disc(const vec3& travel, float u0, float u1) const;
  template <class Random>
  EmittedPhoton sample_photon_from(Random& rng) const;
  bool sample_environment(const vec3& normal, float p_pick, Rng& rng, DirectSample& out) const;

  std::vector<PunctualLight> punctual_;
  std::vector<Triangle> triangles_;
  std::vector<Source> sources_;
  std::span<const Image> images_;
  std::optional<EnvironmentLight> environment_;
  vec3 centre_{0.0f};    // of the scene's bounds
  float radius_ = 0.0f;  // emission_radius of the bounds
  std::vector<double> cdf_;
  std::vector<float> probability_;
  vec3 total_power_{0.0f};
  float max_photon_flux_ = 0.0f;
};

}  // namespace pb
