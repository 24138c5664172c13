// Photon pass: photons leave the lights in proportion to their power and are traced with
// Russian roulette through the materials' Bsdfs; every hit on a surface with a non-delta part
// that counts (after the first bounce when direct light comes from next-event estimation) is
// recorded.
#pragma once

#include "render/photon_guide.h"
#include "util/timer.h"
#include "world/world.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace pb {

struct PhotonHit {
  vec3 position{0.0f};
  vec3 wi{0.0f};      // unit, toward where the photon came from
  vec3 normal{0.0f};  // geometric normal of the hit surface, on wi's side
  vec3 flux{0.0f};    // power carried (before division by the photons per pass)
  uint32_t cell = 0;  // the photon guide's cell it was emitted from (0 without a guide)
};

struct PhotonPassStats {
  uint64_t rays = 0;         // closest-hit rays traced
  uint64_t paths = 0;        // photons emitted
  double order_seconds = 0;  // wall clock spent ordering the hits (part of run())
  float max_flux = 0.0f;     // largest channel of any stored hit's power (ESTIMATOR.md section 12)
  bool cut = false;          // the cutoff was reached: `hits` and the rest are not the range's
};

class PhotonTracer {
 public:
  // deposit_first_hit: record photons at their first surface (all light from photons).
  PhotonTracer(const World& world, bool deposit_first_hit);

  // Traces photons [first, last) of `pass`; photon k draws from Rng(seed, pass, k) whatever the
  // range, so the photons of a pass split into ranges (across machines) are the photons of the
  // whole pass, and the ranges' gathered sums add up to the whole pass's. The hits are
  // written into `hits` (reused across passes) in spatial order: sorted by the Morton code of
  // their position on a 1024^3 lattice over the hits' bounds, ties in photon order. The order
  // depends only on the hits, not on the threads. Why: a gather reads hits[k] for every photon
  // near its point; in photon order each is a cache miss, in Morton order a point's photons are
  // a few contiguous runs that the neighbouring points read again (bench/README.md: a 2.1-2.4x
  // faster gather at 1 M photons per pass, and a faster grid build).
  // With a cutoff, each batch of kChunk photons first polls it; once it is reached the run
  // stops early and returns with `cut` set (the caller discards the pass).
  // With a `guide`, photons are emitted from it (photon_guide.h) and each hit records its cell.
  // With `combine` (a distributed render, exchange.h), the range's hits are handed to it in
  // photon order before they are ordered, and it returns the whole pass's in photon order: the
  // hits ordered are then those of the whole pass, in the same order as one process's, and
  // max_flux is theirs (rays and paths stay the range's).
  using Combine = std::function<void(std::vector<PhotonHit>&)>;
  PhotonPassStats run(uint64_t seed, uint64_t pass, uint64_t first, uint64_t last,
                      std::vector<PhotonHit>& hits, const Cutoff* cutoff = nullptr,
                      const EmissionGuide* guide = nullptr, const Combine* combine = nullptr);

  // Photons per batch: large enough to amortise scheduling, small enough to balance 2 cores.
  static constexpr size_t kChunk = 2048;

  // A photon path never takes more bounces than this; Russian roulette ends almost all first.
  static constexpr int kMaxBounces = 256;

 private:
  void trace(uint64_t seed, uint64_t pass, uint64_t index, const EmissionGuide* guide,
             std::vector<PhotonHit>& out, uint64_t& rays) const;

  // Sorts the chunks' hits into `hits` (see run()).
  void order_hits(std::vector<PhotonHit>& hits);
  // Replaces the chunks' hits by what `combine` makes of them (see run()); returns their
  // chunk count.
  size_t combine_chunks(size_t chunks, const Combine& combine);

  const World& world_;
  bool deposit_first_hit_;
  // Scratch reused across passes, so a warm pass does not allocate.
  std::vector<std::vector<PhotonHit>> chunk_hits_;
  std::vector<Bounds> chunk_bounds_;
  std::vector<float> chunk_max_;
  std::vector<size_t> chunk_offset_;           // first global hit index of each chunk
  std::vector<uint32_t> chunk_of_;             // chunk of each global hit index
  std::vector<uint64_t> keys_, keys_scratch_;  // Morton code << 32 | global hit index
  std::vector<uint32_t> histogram_;
  std::vector<PhotonHit> combined_;  // a distributed pass's hits, before ordering
};

}  // namespace pb
