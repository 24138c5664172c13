// The camera-path numbers of --adaptive paths (render/path_allocation.h, ESTIMATOR.md section
// 15): the root of the efficiency condition K^2 sd(K) = V_cam g / cost, monotone in what it
// weighs, and one path wherever the model has nothing to say.
#include "render/path_allocation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace pb {
namespace {

double lhs(const PathVariance& v, double k) { return k * k * std::sqrt(v.camera / k + v.photon); }

TEST(PathAllocation, NumberIsTheRoundedRootOfTheEfficiencyCondition) {
  for (double camera : {1e-4, 1e-2, 1.0})
    for (double photon : {0.0, 1e-3, 1.0})
      for (double g : {1.0, 30.0, 1e3, 1e5}) {
        const PathVariance v{camera, photon, 3.3};
        const int k = paths_for(v, g);
        ASSERT_GE(k, 1);
        ASSERT_LE(k, kMaxPaths);
        const double rhs = camera * g / v.cost;
        // The root lies within half a path of k, unless k sits at a clamp.
        if (k > 1) EXPECT_LE(lhs(v, k - 0.5), rhs);
        if (k < kMaxPaths) EXPECT_GT(lhs(v, k + 0.5), rhs);
      }
}

TEST(PathAllocation, MorePathsForMoreCameraNoiseFewerForCostOrPhotonNoise) {
  const double g = 200.0;
  int last = 0;
  for (double camera : {0.0, 0.01, 0.1, 1.0, 10.0}) {
    const int k = paths_for({camera, 0.01, 3.3}, g);
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
  choose_paths(states, history, kPathsMinPasses - 1, 1000.0, PathCosts{}, paths, scratch);
  for (uint8_t k : paths) EXPECT_EQ(k, 1);
  // With passes enough, a large spread within passes asks for more paths, none for none.
  history[3] = PathHistory{3.0f, 400.0f, 8.0f};
  choose_paths(states, history, kPathsMinPasses, 1000.0, PathCosts{}, paths, scratch);
  EXPECT_GT(paths[3], 1);
  const PathVariance quiet =
      path_variance(states[0], 8, 1000.0, PathHistory{8.0f, 0.0f, 8.0f}, PathCosts{});
  EXPECT_EQ(quiet.camera, 0.0);
}

}  // namespace
}  // namespace pb
