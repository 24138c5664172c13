// What a render split over several processes exchanges (docs/distributed.md). The renderer
// talks to this interface only; dist/ implements it with MPI, and a render in one process has
// none.
//
// The split: rank r traces the photons [r N / K, (r + 1) N / K) of every pass (photon k draws
// from Rng(seed, pass, k) whichever rank traces it) and computes the states of the chunks it
// owns (pass_stages.h Share: chunk c of kStageChunk states is rank c mod K's). Between the two,
// every rank receives every rank's hits, in rank order, which is photon order: each rank then
// orders, grids and gathers exactly the hits one process would, and its states come out bit
// for bit as one process's. After the fold, every rank receives the new search radii of every
// state (the grid of the next pass is built for all of them). The states themselves and the
// method's per-state side arrays go to rank 0 only when it needs them (a develop, a checkpoint,
// the end): rank 0 decides everything and writes every file; the other ranks follow its
// commands.
#pragma once

#include "render/photon_pass.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pb {

// What rank 0 tells the others between passes.
enum class FollowerCommand : int { Pass = 1, Collect = 2, End = 3 };

class Exchange {
 public:
  Exchange(int rank, int ranks) : rank_(rank), ranks_(ranks) {}
  virtual ~Exchange() = default;
  int rank() const { return rank_; }
  int ranks() const { return ranks_; }

  // The photons [first, last) this rank traces of a pass of n.
  void photon_range(uint64_t n, uint64_t& first, uint64_t& last) const {
    first = n * uint64_t(rank_) / uint64_t(ranks_);
    last = n * uint64_t(rank_ + 1) / uint64_t(ranks_);
  }

  // `hits` holds this rank's hits in photon order; afterwards every rank's, in rank order.
  virtual void all_hits(std::vector<PhotonHit>& hits) = 0;
  virtual uint64_t sum(uint64_t value) = 0;
  virtual float max(float value) = 0;
  // An array of n items of item_bytes each, one per state: the chunks each rank owns are sent
  // from it to every rank (to_all) or to rank 0 alone; the other items are left as they are.
  virtual void share_owned(void* data, size_t item_bytes, size_t n, bool to_all) = 0;
  // Rank 0's command, received by every rank (rank 0 passes it, the others anything).
  virtual FollowerCommand command(FollowerCommand c) = 0;

  // What this rank received (rank 0: every other rank's items) and the seconds it spent in
  // exchanges, waits for slower ranks included, over the whole run: the photon hits, and the
  // per-state arrays (radii every pass, states when rank 0 collects).
  struct Traffic {
    uint64_t bytes = 0;
    double seconds = 0.0;
  };
  Traffic hits, states;

 private:
  int rank_, ranks_;
};

}  // namespace pb
