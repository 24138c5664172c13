// The "error estimation off" variant of the per-pass update, for the overhead figure: plain
// progressive photon mapping with the same smooth kernel (the radiance estimate needs it), fed
// by pb::gather_photons<false> (no Laplacian sum, ESTIMATOR.md section 3), and without the
// streaming moments of section 4. Its PPM update is accumulate_pass()'s, so tau and R^2 come
// out bit-identical to the full estimator's (the bench checks that).
#pragma once

#include "estimator/estimator.h"

#include <cstdint>
#include <vector>

namespace bench {

// What a renderer without error bounds keeps per point (64 bytes instead of PointState's 160).
struct PlainState {
  double n = 0.0;
  double r2 = 0.0;
  pb::dvec3 tau{0.0};
  pb::dvec3 direct_sum{0.0};
  uint64_t photons = 0;
};

void accumulate_plain(PlainState& s, const pb::PassSums& g, const pb::dvec3& direct, double alpha,
                      double min_r2);

}  // namespace bench
