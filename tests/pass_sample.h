// One pass's photon sums and owner values at one point, as the estimator tests write them by
// hand (the renderer keeps the two apart: estimator.h, PassSums and OwnerValues).
#pragma once

#include "estimator/estimator.h"

namespace pb {

struct PassSample : PassSums, OwnerValues {};

inline void accumulate_pass(PointState& state, const PassSample& g, const EstimatorParams& params,
                            uint64_t pass) {
  accumulate_pass(state, static_cast<const PassSums&>(g), static_cast<const OwnerValues&>(g),
                  params, pass);
}

}  // namespace pb
