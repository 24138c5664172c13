// One pass's contribution at one measurement point: the photons within its radius (kernel and
// Laplacian weights, ESTIMATOR.md sections 2-3) and the next-event direct-light sample (section 4).
#pragma once

#include "photonbound/estimator.h"
#include "photonbound/eye_pass.h"
#include "photonbound/hash_grid.h"
#include "photonbound/photon_pass.h"
#include "photonbound/rng.h"
#include "photonbound/world.h"

#include <cmath>
#include <vector>

namespace pb {

// The float radius a point with squared radius r2 queries the grid with. The grid is built for
// these same values (Renderer keeps one per point), so both must come from here.
inline float search_radius(double r2) { return float(std::sqrt(r2)); }

// Adds every photon within search_radius(r2) of the point that arrived on the point's side.
void gather_photons(const MeasurementPoint& point, double r2, const HashGrid& grid,
                    const std::vector<PhotonHit>& hits, PassGather& out);

// One light sample with a shadow ray: D_j = f Li cos / pdf.
dvec3 direct_light(const World& world, const MeasurementPoint& point, Rng& rng);

}  // namespace pb
