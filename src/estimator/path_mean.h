// The mean of several camera paths' samples of one pixel in one pass (--adaptive paths,
// ESTIMATOR.md section 15). Each path's gather is corrected by its own disc (section 11: the
// kernel mass, the truncated Laplacian and the effective R_b^2 are properties of the point the
// path found), so the paths cannot be averaged as raw PassSums when a disc is cut: PathMean
// averages the corrected quantities and hands accumulate_pass sums and owner values that
// reproduce them exactly.
#pragma once

#include "estimator/estimator.h"

namespace pb {

class PathMean {
 public:
  // One path's sums and owner values at the pixel's radius r2 of the pass, M_e photons emitted.
  void add(const PassSums& sums, const OwnerValues& owner, double r2, double photons_per_pass);
  // sum over the channels and paths of (X_k - mean X)^2, X_k each path's own sample: with
  // paths() - 1 degrees of freedom, the spread of the pixel's paths within the pass. They share
  // the pass's photons, so it measures the camera part of the variance (section 15).
  double spread() const;
  // Sums and owner values whose accumulate_pass at r2 folds the paths' mean: the sample X_j,
  // the Laplacian sample, R_b^2 and the count are the means of the paths' own (section 15); the
  // photon total takes the first path's count (OwnerValues::first_count).
  // Where every disc is whole the raw sums are averaged and the two-scale sample (section 11c)
  // is kept; otherwise the disc handed on is a synthetic cut one of mass 1 that applies no
  // further correction, and the pass has no two-scale sample.
  void finish(double r2, PassSums& sums, OwnerValues& owner) const;

 private:
  PassSums raw_;              // sums of the raw PassSums (used while every disc is whole)
  dvec3 phi_{0.0};            // sum of phi / c
  dvec3 lap_{0.0};            // sum of the corrected Laplacian samples (per R^2, as accumulate)
  dvec3 direct_{0.0};         // sum of D
  double r2_bias_ = 0.0;      // sum of the effective R_b^2
  dvec3 x_{0.0}, x2_{0.0};    // sums of the paths' samples X_k and of their squares
  double first_count_ = 0.0;  // the first path's M (what the state's photon total adds)
  int paths_ = 0;
  bool full_ = true;
};

}  // namespace pb
