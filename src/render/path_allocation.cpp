#include "render/path_allocation.h"

#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace pb {

PathVariance path_variance(const PointState& s, uint64_t passes, double photons_per_pass,
                           const PathHistory& h, const PathCosts& costs) {
  PathVariance v;
  v.cost = float(costs.per_path);
  if (passes < kAdaptiveMinPasses || s.photons < kMinPhotonsForBound || !(h.inv_paths > 0.0f) ||
      !(s.mean_r2 > 0.0))
    return v;
  const double i = double(passes);
  const auto [s2, bias] = pass_spread(s, passes, photons_per_pass);
  const double total = s2.x + s2.y + s2.z;
  // Photons per path and pass, averaged over the passes (the state counts the first path's).
  const double per_path = double(s.photons) / i;
  const dvec3 lph = photon_radiance(s, passes, photons_per_pass);
  const double photon_mean = glm::dot(lph, lph) * kPhotonNoise / per_path;
  // The next pass's radius holds R^2 / mean R^2 of the photons and so much more photon noise.
  const double shrink = s.r2 / s.mean_r2;
  v.photon = float(photon_mean / shrink);
  v.cost = float(costs.per_path + costs.per_gathered * per_path * shrink);
  // V_cam from the spread of the pixel's own paths within passes where it had several (they
  // share the photons); before that, S^2 = V_cam mean_j(1 / K_j) + V_ph less the model's V_ph.
  if (h.dof >= kMinSpreadDof)
    v.camera = h.spread / h.dof;
  else
    v.camera = float(std::max(0.0, total - photon_mean) * i / double(h.inv_paths));
  // The pixel's part of the image's predicted mean error (ESTIMATOR.md section 7): noise of sd
  // sigma adds E|sigma Z| = sqrt(2 / pi) sigma, the bias its size. mean_j(R_j^2) moves by
  // (R_i^2 - mean) / i a pass, so B ~ mean_j(R_j^2) falls as i^-beta, beta = 1 - R_i^2 / mean.
  // B's own noise (section 6b) is not bias: only B^2 - Var(B) counts. Both parts are taken at
  // twice the passes done (kPathsHorizon), where a render that goes on spends most of its time.
  const double beta = std::clamp(1.0 - s.r2 / s.mean_r2, 0.0, 1.0);
  const double shrink2 = (s.mean_r2 / s.r2) * (s.mean_r2 / s.r2);
  double b = 0.0, sd = 0.0;
  for (int c = 0; c < 3; ++c) {
    sd += std::sqrt(s2[c] / i);
    b += std::sqrt(std::max(0.0, bias[c] * bias[c] - kBiasNoiseRatio * shrink2 * s2[c] / i));
  }
  v.noise = float(std::sqrt(2.0 / kPiD) * sd / std::sqrt(kPathsHorizon));
  v.settled = float(beta * b * std::pow(kPathsHorizon, -beta));
  if (!std::isfinite(v.camera) || !std::isfinite(v.photon) || !std::isfinite(v.cost) ||
      !std::isfinite(v.noise) || !std::isfinite(v.settled))
    return PathVariance{0.0f, 0.0f, float(costs.per_path)};
  return v;
}

double sparse_at_horizon(const PointState& s, const dvec3& term) {
  if (double(s.photons) * kPathsHorizon >= double(kMinPhotonsForBound)) return 0.0;
  return (term.x + term.y + term.z) / kPathsHorizon;
}

double settled_share(std::span<const PathVariance> v) {
  // In pixel order: the same sums for any threads.
  double noise = 0.0, settled = 0.0;
  for (const PathVariance& p : v) {
    if (std::isnan(p.noise) || std::isnan(p.settled)) continue;  // nothing known of the pixel
    noise += double(p.noise);
    settled += double(p.settled);
  }
  if (!(settled > 0.0)) return 0.0;
  if (!(noise > 0.0)) return std::numeric_limits<double>::infinity();
  // N + O reaches the target; with O ~ i^-beta and N ~ i^-1/2 the time is least where the
  // paths' cost weighs 1 + 2 beta O / N times more (ESTIMATOR.md section 15).
  return 2.0 * settled / noise;
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

void choose_paths(std::span<const PathVariance> v, uint64_t passes, double photons_per_pass,
                  const PathCosts& costs, std::span<uint8_t> paths, PathScratch& scratch) {
  const size_t n = v.size();
  std::fill(paths.begin(), paths.end(), uint8_t(1));
  if (passes < kPathsMinPasses || n == 0) return;
  constexpr size_t kChunk = 4096;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  const double settled = settled_share(v);
  if (!std::isfinite(settled)) return;  // nothing paths can lower
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
    const double g = cost / sd / (1.0 + settled);
    parallel_for(chunks, 1, [&](size_t b, size_t e) {
      for (size_t c = b; c < e; ++c)
        for (size_t p = c * kChunk; p < std::min(n, (c + 1) * kChunk); ++p)
          paths[p] = uint8_t(paths_for(v[p], g));
    });
  }
}

}  // namespace pb
