// One pass's contribution at one measurement point: the photons within its radius (kernel and
// Laplacian weights, ESTIMATOR.md sections 2-3) and the next-event direct-light sample (section 4).
#pragma once

#include "photonbound/estimator.h"
#include "photonbound/eye_pass.h"
#include "photonbound/hash_grid.h"
#include "photonbound/photon_pass.h"
#include "photonbound/rng.h"
#include "photonbound/world.h"

#include <vector>

namespace pb {

// Adds every photon within sqrt(r2) of the point that arrived on the point's side.
void gather_photons(const MeasurementPoint& point, double r2, const HashGrid& grid,
                    const std::vector<PhotonHit>& hits, PassGather& out);

// One light sample with a shadow ray: D_j = f Li cos / pdf.
dvec3 direct_light(const World& world, const MeasurementPoint& point, Rng& rng);

}  // namespace pb
