// How many camera paths each pixel gets in the next SPPM pass (--adaptive paths, ESTIMATOR.md
// section 15). A pixel's pass sample has the variance V_cam / K + V_ph for K paths: the camera
// part (pixel jitter, a branch drawn at glass, the next-event sample) falls with K, the photon
// part (its paths mostly share the photons of one disc) does not. Paths cost time, so the
// numbers minimise the image's mean sd per unit of time, sum_p sd_p x sqrt(T), over a model of
// a pass's cost T in units of one photon.
#pragma once

#include "estimator/estimator.h"

#include <cstdint>
#include <span>
#include <vector>

namespace pb {

inline constexpr int kMaxPaths = 16;

// One path everywhere before this many passes: the variances have too few degrees of freedom to
// allocate by, and a render that the first stop test ends (--min-passes, 16 by default) would
// pay for paths it cannot use (measured: the Cornell box at 256x256 to 0.01, 0.90x the seconds
// with paths from pass 5; ESTIMATOR.md section 15). A constant, not --min-passes: a resume may
// change that option, and the image must not change with it.
inline constexpr uint64_t kPathsMinPasses = 16;

// What a pass costs, in units of one photon-pass ray (with its share of storing and sorting
// the hits). Measured on the caustic at 128x96 (ESTIMATOR.md section 15): a camera path with
// its next-event sample costs 3.3 photon rays, each photon its gather finds 0.1 more, a
// pixel's fold 1.
struct PathCosts {
  double per_path = 3.3;
  double per_gathered = 0.1;
  double per_pixel = 1.0;
  double rays_per_photon = 2.0;  // photon-pass rays per emitted photon (past passes)
};

// What a pixel's past passes say about its paths (kept in the state file).
struct PathHistory {
  float inv_paths = 0.0f;  // sum_j 1 / K_j
  float spread = 0.0f;     // sum over passes of PathMean::spread()
  float dof = 0.0f;        // its degrees of freedom, sum_j (K_j - 1)
};
static_assert(sizeof(PathHistory) == 3 * sizeof(float), "the state file stores three floats");

// Below this many degrees of freedom of the within-pass spread, V_cam comes from the pass
// variance less the photon model's part instead.
inline constexpr float kMinSpreadDof = 4.0f;

// E[w^2] / E[w]^2 of the kernel weight w over a uniform disc (ESTIMATOR.md section 2): the
// photon part's per-pass variance is L_ph^2 kPhotonNoise / m for m photons of equal power in a
// disc (Poisson). (49/2) integral_0^1 k(t)^2 t dt = 287/132.
inline constexpr double kPhotonNoise = 287.0 / 132.0;

// The two parts of a pixel's per-pass variance (summed over the channels) for one path, and
// what one of its paths costs, from its state after `passes` passes and its history.
struct PathVariance {
  float camera = 0.0f;  // V_cam
  float photon = 0.0f;  // V_ph at the radius of the next pass
  float cost = 1.0f;    // a path's cost in photon rays
  // The pixel's share of the image's predicted mean error (summed over the channels) at the
  // horizon below: its noise, sqrt(2 / pi) S / sqrt(i) (the mean of |sigma Z|), and what paths
  // cannot lower, beta O: its bias |B| times the rate beta at which it falls with the passes,
  // beta = -d ln mean_j(R_j^2) / d ln i, plus its sparse-photon term (sparse_at_horizon, beta 1).
  float noise = 0.0f;
  float settled = 0.0f;
};
static_assert(sizeof(PathVariance) == 20, "20 bytes a pixel during the allocation");
PathVariance path_variance(const PointState& state, uint64_t passes, double photons_per_pass,
                           const PathHistory& history, const PathCosts& costs);

// The number of paths (1 to kMaxPaths) that minimises the image's mean sd per time for one
// pixel, given g = T / S (S the image's summed sd, T a pass's cost): K^2 sd(K) = V_cam g / cost,
// to the nearest integer.
int paths_for(const PathVariance& v, double g);

// The image's error that more paths cannot lower, against the part they can (ESTIMATOR.md
// section 15): a render to a target stops when its noise N and the rest O reach it, and O (the
// bias, the sparse-photon bound) falls as passes^-beta whatever the paths, so the time to the
// target is least at K^2 sd(K) = V_cam g / (cost (1 + 2 beta O / N)). Returns 2 beta O / N
// over the pixels (+inf where no pixel has noise, 0 where nothing else).
double settled_share(std::span<const PathVariance> v);

// The parts are weighed where the render will be, not where it is: at this many times the
// passes done (a render to a target goes on for about as long as it has run when it is not
// there yet). By then a pixel's photons have doubled: a sparse pixel of n >= 3 photons has left
// the sparse-photon bound, and one of fewer keeps half its term (it falls as 1 / i).
inline constexpr double kPathsHorizon = 2.0;
// The sparse-photon term is weighed at this confidence whatever --confidence says: an option a
// resume may change (it only adjusts the stop and the report) must not change which paths are
// traced, and so the image.
inline constexpr double kPathsConfidence = 0.9;
double sparse_at_horizon(const PointState& state, const dvec3& sparse_term);

// What choose_paths works in, kept across passes so that a steady pass allocates nothing.
struct PathScratch {
  std::vector<PathVariance> variance;
  std::vector<double> chunk_sd, chunk_cost;
};

// paths[p] for every pixel from v[p] = path_variance of its state and history, with its
// sparse part (the next pass's numbers): 1 before kPathsMinPasses passes. The image-wide g is
// found by a few rounds that alternate it with the numbers, and divided by 1 + settled_share;
// sums are taken in a fixed order, so the result does not depend on the threads (nor on the
// ranks, which share v before).
void choose_paths(std::span<const PathVariance> v, uint64_t passes, double photons_per_pass,
                  const PathCosts& costs, std::span<uint8_t> paths, PathScratch& scratch);

}  // namespace pb
