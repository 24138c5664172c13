// The "error estimation off" variant of the gather and the per-pass update, for the overhead
// figure: plain progressive photon mapping with the same smooth kernel (the radiance estimate
// needs it), without the Laplacian sum (ESTIMATOR.md section 3) and without the streaming moments
// of section 4. It mirrors src/gather.cpp and accumulate_pass() line for line otherwise, so tau
// and R^2 come out bit-identical to the full estimator's (the bench checks that).
#pragma once

#include "photonbound/eye_pass.h"
#include "photonbound/hash_grid.h"
#include "photonbound/photon_pass.h"

#include <cstdint>
#include <vector>

namespace bench {

// What a renderer without error bounds keeps per point (64 bytes instead of 184).
struct PlainState {
  double n = 0.0;
  double r2 = 0.0;
  pb::dvec3 tau{0.0};
  pb::dvec3 direct_sum{0.0};
  uint64_t photons = 0;
};

void gather_plain(const pb::MeasurementPoint& point, double r2, const pb::HashGrid& grid,
                  const std::vector<pb::PhotonHit>& hits, pb::dvec3& phi, uint64_t& count);

void accumulate_plain(PlainState& s, const pb::dvec3& phi, uint64_t count, const pb::dvec3& direct,
                      double alpha, double min_r2);

}  // namespace bench
