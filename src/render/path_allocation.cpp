#include "render/path_allocation.h"

#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace pb {

PathVariance path_variance(const PointState& s, uint64_t passes, double photons_per_pass,
                           const PathHistory& h, const PathCosts& costs) {
  PathVariance v;
  v.cost = costs.per_path;
  if (passes < kAdaptiveMinPasses || s.photons < kMinPhotonsForBound || !(h.inv_paths > 0.0f) ||
      !(s.mean_r2 > 0.0))
    return v;
  const double i = double(passes);
  const dvec3 s2 = pass_variance(s, passes, photons_per_pass);
  const double total = s2.x + s2.y + s2.z;
  // Photons per path and pass, averaged over the passes (the state counts the first path's).
  const double per_path = double(s.photons) / i;
  const dvec3 lph = photon_radiance(s, passes, photons_per_pass);
  const double photon_mean = glm::dot(lph, lph) * kPhotonNoise / per_path;
  // The next pass's radius holds R^2 / mean R^2 of the photons and so much more photon noise.
  const double shrink = s.r2 / s.mean_r2;
  v.photon = photon_mean / shrink;
  v.cost = costs.per_path + costs.per_gathered * per_path * shrink;
  // V_cam from the spread of the pixel's own paths within passes where it had several (they
  // share the photons); before that, S^2 = V_cam mean_j(1 / K_j) + V_ph less the model's V_ph.
  if (h.dof >= kMinSpreadDof)
    v.camera = double(h.spread) / double(h.dof);
  else
    v.camera = std::max(0.0, total - photon_mean) * i / double(h.inv_paths);
  if (!std::isfinite(v.camera) || !std::isfinite(v.photon) || !std::isfinite(v.cost))
    return PathVariance{0.0, 0.0, costs.per_path};
  return v;
}

int paths_for(const PathVariance& v, double g) {
  if (!(v.camera > 0.0) || !(g > 0.0) || !(v.cost > 0.0)) return 1;
  // K^2 sd(K) = sqrt(V_cam K^3 + V_ph K^4) grows with K: the largest K whose K - 1/2 still
  // lies below the root is the root rounded.
  const double rhs = v.camera * g / v.cost;
  const double rhs2 = rhs * rhs;
  int k = 1;
  while (k < kMaxPaths) {
    const double h = double(k) + 0.5;
    if (v.camera * h * h * h + v.photon * h * h * h * h > rhs2) break;
    ++k;
  }
  return k;
}

void choose_paths(std::span<const PointState> states, std::span<const PathHistory> history,
                  uint64_t passes, double photons_per_pass, const PathCosts& costs,
                  std::span<uint8_t> paths, PathScratch& scratch) {
  const size_t n = states.size();
  std::fill(paths.begin(), paths.end(), uint8_t(1));
  if (passes < kPathsMinPasses || n == 0) return;
  std::vector<PathVariance>& v = scratch.variance;
  v.resize(n);
  constexpr size_t kChunk = 4096;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  parallel_for(chunks, 1, [&](size_t b, size_t e) {
    for (size_t c = b; c < e; ++c)
      for (size_t p = c * kChunk; p < std::min(n, (c + 1) * kChunk); ++p)
        v[p] = path_variance(states[p], passes, photons_per_pass, history[p], costs);
  });
  // Alternate g with the numbers, from one path everywhere; three rounds settle it (the
  // numbers are integers and g moves little once the sum of sds does).
  std::vector<double>& part_sd = scratch.chunk_sd;
  std::vector<double>& part_cost = scratch.chunk_cost;
  part_sd.resize(chunks);
  part_cost.resize(chunks);
  for (int round = 0; round < 3; ++round) {
    parallel_for(chunks, 1, [&](size_t b, size_t e) {
      for (size_t c = b; c < e; ++c) {
        double sd = 0.0, k_sum = 0.0;
        for (size_t p = c * kChunk; p < std::min(n, (c + 1) * kChunk); ++p) {
          const double k = double(paths[p]);
          sd += std::sqrt(v[p].camera / k + v[p].photon);
          k_sum += k * v[p].cost;
        }
        part_sd[c] = sd;
        part_cost[c] = k_sum;
      }
    });
    double sd = 0.0, k_sum = 0.0;
    for (size_t c = 0; c < chunks; ++c) {  // in chunk order: the same sums for any threads
      sd += part_sd[c];
      k_sum += part_cost[c];
    }
    if (!(sd > 0.0)) return;
    // k_sum is the paths' cost here: sum_p K_p cost_p.
    const double cost =
        photons_per_pass * costs.rays_per_photon + costs.per_pixel * double(n) + k_sum;
    const double g = cost / sd;
    parallel_for(chunks, 1, [&](size_t b, size_t e) {
      for (size_t c = b; c < e; ++c)
        for (size_t p = c * kChunk; p < std::min(n, (c + 1) * kChunk); ++p)
          paths[p] = uint8_t(paths_for(v[p], g));
    });
  }
}

}  // namespace pb
