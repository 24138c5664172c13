// The camera-path numbers of --adaptive paths (render/path_allocation.h, ESTIMATOR.md section
// 15): the root of the efficiency condition K^2 sd(K) = V_cam g / cost, monotone in what it
// weighs, and one path wherever the model has nothing to say.
#include "render/path_allocation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace pb {
namespace {

double lhs(const PathVariance& v, double k) {
  return k * k * std::sqrt(double(v.camera) / k + double(v.photon));
}

TEST(PathAllocation, NumberIsTheRoundedRootOfTheEfficiencyCondition) {
  for (float camera : {1e-4f, 1e-2f, 1.0f})
    for (float photon : {0.0f, 1e-3f, 1.0f})
      for (double g : {1.0, 30.0, 1e3, 1e5}) {
        const PathVariance v{camera, photon, 3.3f};
        const int k = paths_for(v, g);
        ASSERT_GE(k, 1);
        ASSERT_LE(k, kMaxPaths);
        const double rhs = double(camera) * g / double(v.cost);
        // The root lies within half a path of k, unless k sits at a clamp.
        if (k > 1) EXPECT_LE(lhs(v, k - 0.5), rhs);
        if (k < kMaxPaths) EXPECT_GT(lhs(v, k + 0.5), rhs);
      }
}

TEST(PathAllocation, MorePathsForMoreCameraNoiseFewerForCostOrPhotonNoise) {
  const double g = 200.0;
  int last = 0;
  for (float camera : {0.0f, 0.01f, 0.1f, 1.0f, 10.0f}) {
    const int k = paths_for({camera, 0.01f, 3.3f}, g);
    EXPECT_GE(k, last);
    last = k;
  }
  EXPECT_EQ(paths_for({0.0, 1.0, 3.3}, g), 1);  // no camera noise: one path
  EXPECT_GT(paths_for({1.0, 0.01, 3.3}, g), 1);
  EXPECT_LE(paths_for({1.0, 0.01, 30.0}, g), paths_for({1.0, 0.01, 3.3}, g));
  EXPECT_LE(paths_for({1.0, 1.0, 3.3}, g), paths_for({1.0, 0.01, 3.3}, g));
}

// Where the camera part is all of the variance, the optimum of sum sqrt(V / K) under a fixed
// sum of K is K proportional to V^(1/3): eight times the variance, twice the paths.
TEST(PathAllocation, CameraNoiseAloneGivesPathsAsTheCubeRootOfTheVariance) {
  const int a = paths_for({1.0, 0.0, 1.0}, 4.0), b = paths_for({8.0, 0.0, 1.0}, 4.0);
  EXPECT_EQ(a, 3);  // K^(3/2) = g sqrt(V) / cost = 4: K = 2.52
  EXPECT_EQ(b, 5);  // K^(3/2) = 4 sqrt(8) = 11.3: K = 5.04
}

std::vector<PathVariance> variances(const std::vector<PointState>& states,
                                    const std::vector<PathHistory>& history, uint64_t passes) {
  std::vector<PathVariance> v;
  for (size_t p = 0; p < states.size(); ++p)
    v.push_back(path_variance(states[p], passes, 1000.0, history[p], PathCosts{}));
  return v;
}

TEST(PathAllocation, OnePathBeforeTheModelHasPasses) {
  std::vector<PointState> states(10);
  for (PointState& s : states) {
    s.r2 = 0.01;
    s.mean_r2 = 0.012;
    s.photons = 1000;
    s.c_xx = dvec3(50.0);
    s.mean_x = dvec3(1.0);
  }
  std::vector<PathHistory> history(10, PathHistory{3.0f, 0.0f, 0.0f});
  std::vector<uint8_t> paths(10, 7);
  PathScratch scratch;
  choose_paths(variances(states, history, kPathsMinPasses - 1), kPathsMinPasses - 1, 1000.0,
               PathCosts{}, paths, scratch);
  for (uint8_t k : paths) EXPECT_EQ(k, 1);
  // With passes enough, a large spread within passes asks for more paths, none for none.
  history[3] = PathHistory{3.0f, 400.0f, 8.0f};
  choose_paths(variances(states, history, kPathsMinPasses), kPathsMinPasses, 1000.0, PathCosts{},
               paths, scratch);
  EXPECT_GT(paths[3], 1);
  const PathVariance quiet =
      path_variance(states[0], 8, 1000.0, PathHistory{8.0f, 0.0f, 8.0f}, PathCosts{});
  EXPECT_EQ(quiet.camera, 0.0);
}

// The condition with the error paths cannot lower (ESTIMATOR.md section 15): N + O at the
// stop, O ~ i^-beta. Where O is nothing, the numbers are those of the noise alone; where the
// sparse-photon term is most of the image's error (a pixel behind glass with 0-2 photons, the
// case that made paths 0.66x on Blender's transmission export), the noisy pixel gets fewer.
TEST(PathAllocation, ErrorThatPathsCannotLowerBuysFewerPaths) {
  std::vector<PathVariance> v(64, PathVariance{1e-4f, 1e-4f, 3.3f, 0.01f, 0.0f});
  v[5].camera = 1.0f;  // one pixel whose camera part is large
  EXPECT_EQ(settled_share(v), 0.0);
  std::vector<uint8_t> alone(v.size()), with(v.size());
  PathScratch scratch;
  choose_paths(v, kPathsMinPasses, 1000.0, PathCosts{}, alone, scratch);
  EXPECT_GT(alone[5], 2);
  // 2 beta O / N: the noises sum to 0.64, a sparse term of 3.2 (beta 1) gives 10.
  v[9].settled = 3.2f;
  EXPECT_NEAR(settled_share(v), 10.0, 1e-5);
  // A pixel of which nothing is known (NaN) weighs nothing either way.
  std::vector<PathVariance> with_nan = v;
  with_nan.push_back(PathVariance{1.0f, 1.0f, 3.3f, std::nanf(""), 1.0f});
  EXPECT_NEAR(settled_share(with_nan), 10.0, 1e-5);
  choose_paths(v, kPathsMinPasses, 1000.0, PathCosts{}, with, scratch);
  EXPECT_LT(with[5], alone[5]);
  for (size_t p = 0; p < v.size(); ++p) EXPECT_LE(with[p], alone[p]);
  // Where no pixel has noise left, nothing buys paths.
  for (PathVariance& p : v) p.noise = 0.0f;
  EXPECT_TRUE(std::isinf(settled_share(v)));
  choose_paths(v, kPathsMinPasses, 1000.0, PathCosts{}, with, scratch);
  for (uint8_t k : with) EXPECT_EQ(k, 1);
}

// A sparse pixel's term at the horizon: gone once its photons, doubled, reach the bound's
// threshold; otherwise halved (it falls as 1 / i).
TEST(PathAllocation, SparseTermAtTheHorizon) {
  PointState s;
  s.photons = 2;
  EXPECT_DOUBLE_EQ(sparse_at_horizon(s, dvec3(1.0, 2.0, 3.0)), 3.0);
  s.photons = 3;
  EXPECT_EQ(sparse_at_horizon(s, dvec3(1.0, 2.0, 3.0)), 0.0);
}

}  // namespace
}  // namespace pb
