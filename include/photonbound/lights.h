// All emitters of a scene (punctual lights and emissive triangles) behind one sampler that
// chooses an emitter in proportion to its power, for photon emission and next-event estimation.
#pragma once

#include "photonbound/rng.h"
#include "photonbound/scene.h"

#include <vector>

namespace pb {

struct EmittedPhoton {
  vec3 origin{0.0f};
  vec3 dir{0.0f};
  vec3 flux{0.0f};        // power carried, already divided by every sampling probability
  vec3 normal{0.0f};      // surface normal at the origin (area lights), 0 for punctual lights
};

struct DirectSample {
  vec3 wi{0.0f};       // unit direction from the receiver toward the light
  float distance = 0;  // to the sampled light point
  vec3 li{0.0f};       // incident radiance times geometry over pdf, without the receiver's cosine
};

class Lights {
 public:
  explicit Lights(const Scene& scene);

  // Total emitted power per channel (W, in the image's radiance units times m^2 sr).
  vec3 total_power() const { return total_power_; }
  size_t emitter_count() const { return probability_.size(); }

  EmittedPhoton sample_photon(Rng& rng) const;
  // False when the sample cannot contribute (back side of a one-sided emitter, outside a cone).
  bool sample_direct(const vec3& receiver, Rng& rng, DirectSample& out) const;

 private:
  struct Triangle {
    vec3 p0, e1, e2;
    vec3 normal;  // front side, from the winding
    float area;
    vec3 radiance;
  };
  // Emitter k < punctual_.size() is a punctual light, the rest are triangles.
  size_t pick(float u) const;
  vec3 spot_falloff(const PunctualLight& light, const vec3& dir) const;

  std::vector<PunctualLight> punctual_;
  std::vector<Triangle> triangles_;
  std::vector<double> cdf_;
  std::vector<float> probability_;
  vec3 total_power_{0.0f};
};

}  // namespace pb
