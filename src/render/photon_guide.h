// Photons sent where the error is (`--adaptive photons`, ESTIMATOR.md section 14): emission
// importance-sampled in its primary sample space (lights.h PrimarySample) from a histogram learnt
// from earlier passes, mixed with the power-proportional emission, frozen for a pass.
//
// The histogram's cells split three of the emission's uniform numbers: the emitter choice u0
// into P bins (emitters in the order of the power CDF, so a bin is a group of lights) and the
// picked emitter's direction pair into D x D bins. A photon draws a cell c with probability q_c
// and its numbers uniformly within the cell, so its primary-sample density is
// q_c P D^2 and its flux is divided by that: E[flux] is that of the power-proportional emission
// for any q with every q_c > 0, and the uniform share m keeps q_c >= m / (P D^2).
//
// What a cell learns (the first moment of the error-weighted contribution, section 14): every
// photon a visible point gathers adds its contribution to the point's pass sample times the
// point's relative error, to the cell the photon came from. Summed over a pass and divided by
// the photons, that estimates, for each cell, the integral over the cell of the error-weighted
// contribution of unit-weight emission (the photon's 1 / density and the sampling cancel).
// q follows the cells' normalised sums, averaged over the recent passes.
#pragma once

#include "lights/lights.h"

#include <cstdint>
#include <span>
#include <vector>

namespace pb {

class EmissionGuide {
 public:
  // The share of every pass's photons emitted in proportion to power: keeps every region
  // reachable however the histogram learnt (issue 39 names 30%).
  static constexpr double kUniformShare = 0.3;
  // A pass's normalised sums enter the running histogram with weight max(1 / passes, this):
  // the mean of all passes at first, then about the last 16 passes (errors move as the render
  // goes on; a pass's 100k photons over 4096 cells are too few to follow alone).
  static constexpr double kMinBlend = 1.0 / 16.0;

  EmissionGuide() = default;  // no guide: every photon power-proportional
  // A guide for `emitters` emitters (Lights::emitter_count()): P = min(emitters, 16) bins of u0,
  // D = 64, 32 or 16 direction bins per axis for P = 1, 2-4 or more (at most 4096 cells).
  explicit EmissionGuide(size_t emitters);

  size_t cells() const { return size_t(pick_bins_) * size_t(dir_bins_) * size_t(dir_bins_); }
  // True once a pass has been learnt: photons are then drawn from the mixture.
  bool guiding() const { return learnt_ > 0; }

  // Warps a photon's primary sample: draws the cell from u_cell, places u.u[0] and the direction
  // pair of the emitter it then picks inside the cell. Returns the cell; `density` is the
  // primary-sample density q_c P D^2 the photon's flux is divided by. Without guiding the
  // sample is left alone (cell of its numbers, density 1).
  uint32_t warp(float u_cell, PrimarySample& u, const Lights& lights, float& density) const;

  // Folds one pass's per-cell sums (GuideTally) in; a pass whose sums are all 0 changes nothing.
  void learn(std::span<const double> pass_sums);
  // The largest factor a photon's flux is multiplied by (1 / the smallest density), at most
  // 1 / kUniformShare: the sparse-photon bound's largest photon power follows it (section 12).
  double max_weight() const;

  // The running histogram and the passes learnt, for a state file; restore throws
  // std::invalid_argument when the size is not this guide's.
  const std::vector<double>& histogram() const { return mean_; }
  uint64_t learnt() const { return learnt_; }
  void restore(std::vector<double> histogram, uint64_t learnt);

 private:
  void rebuild();  // q and its CDF from mean_

  uint32_t pick_bins_ = 1, dir_bins_ = 1;
  std::vector<double> mean_;  // running normalised histogram (sums to 1 once learnt)
  std::vector<double> cdf_;   // of q, cells() + 1 entries
  // Cutpoints (Chen and Asau 1974): start_[k] is the first cell whose CDF passes k / cells, so
  // a draw scans one or two cells from there instead of a binary search of 12 cache misses
  // (the search was 6% of a pass).
  std::vector<uint32_t> start_;
  std::vector<float> density_;
  uint64_t learnt_ = 0;
};

// One pass's learning sums, gathered chunk by chunk and reduced in chunk order, so that the
// histogram, and with it the image, does not depend on the threads.
class GuideTally {
 public:
  // A chunk's accumulator: adds into this thread's dense scratch and, when the chunk ends, moves
  // the cells it touched (in the order first touched) into the chunk's list.
  class Chunk {
   public:
    Chunk(GuideTally& tally, size_t index);
    ~Chunk();
    Chunk(const Chunk&) = delete;
    Chunk& operator=(const Chunk&) = delete;
    void add(uint32_t cell, double value) {
      if (!(value > 0.0)) return;
      if (scratch_[cell] == 0.0) touched_.push_back(cell);
      scratch_[cell] += value;
    }

   private:
    std::vector<double>& scratch_;
    std::vector<uint32_t>& touched_;
    std::vector<std::pair<uint32_t, double>>& list_;
  };

  // Zeroes the pass's sums for a guide of `cells` cells, with room for `chunks` chunks a block.
  void begin_pass(size_t cells, size_t chunks);
  // Adds the lists of chunks [0, chunks) of a fold block, in order, to the pass's sums.
  void reduce_block(size_t chunks);
  std::span<const double> sums() const { return sums_; }

 private:
  size_t cells_ = 0;
  std::vector<std::vector<std::pair<uint32_t, double>>> lists_;  // per chunk of a block
  std::vector<double> sums_;
};

}  // namespace pb
