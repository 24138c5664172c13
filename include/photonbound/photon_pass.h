// Photon pass: photons leave the lights in proportion to their power and are traced with
// Russian roulette through the three reflection models; every Lambertian hit that counts
// (after the first bounce when direct light comes from next-event estimation) is recorded.
#pragma once

#include "photonbound/world.h"

#include <cstdint>
#include <vector>

namespace pb {

struct PhotonHit {
  vec3 position{0.0f};
  vec3 wi{0.0f};      // unit, toward where the photon came from
  vec3 normal{0.0f};  // geometric normal of the hit surface, on wi's side
  vec3 flux{0.0f};    // power carried (before division by the photons per pass)
};

struct PhotonPassStats {
  uint64_t rays = 0;   // closest-hit rays traced
  uint64_t paths = 0;  // photons emitted
};

class PhotonTracer {
 public:
  // deposit_first_hit: record photons at their first surface (all light from photons).
  PhotonTracer(const World& world, bool deposit_first_hit);

  // Traces photons [0, count) of `pass`; photon k draws from Rng(seed, pass, k). The hits are
  // written in photon order into `hits` (reused across passes).
  PhotonPassStats run(uint64_t seed, uint64_t pass, uint64_t count, std::vector<PhotonHit>& hits);

  // A photon path never takes more bounces than this; Russian roulette ends almost all first.
  static constexpr int kMaxBounces = 256;

 private:
  void trace(uint64_t seed, uint64_t pass, uint64_t index, std::vector<PhotonHit>& out,
             uint64_t& rays) const;

  const World& world_;
  bool deposit_first_hit_;
  std::vector<std::vector<PhotonHit>> chunk_hits_;
};

}  // namespace pb
