// Several camera paths of one pixel in one pass (--adaptive paths, ESTIMATOR.md section 15):
// PathMean must hand accumulate_pass sums whose fold equals the mean of the paths' own folds,
// disc corrections included, and its within-pass spread must be the paths' sum of squares.
#include "estimator/estimator.h"
#include "estimator/kernel.h"
#include "estimator/path_mean.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace pb {
namespace {

constexpr double kR2 = 0.04, kPhotons = 1000.0;

struct Path {
  PassSums sums;
  OwnerValues owner;
};

Path random_path(std::mt19937& gen, bool cut) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Path p;
  p.sums.phi = dvec3(u(gen), u(gen), u(gen)) * 50.0;
  p.sums.phi_lap_r2 = dvec3(u(gen) - 0.5, u(gen) - 0.5, u(gen) - 0.5) * 80.0;
  p.sums.phi_half = p.sums.phi * 0.3;
  p.sums.count = double(int(u(gen) * 40.0));
  p.owner.direct = dvec3(u(gen), u(gen), u(gen));
  if (cut) {  // a disc cut by an edge: the moments of some part of the unit disc
    p.owner.disc.full = false;
    p.owner.disc.mass = 0.3 + 0.6 * u(gen);
    p.owner.disc.second = 0.05 + 0.1 * u(gen);
    p.owner.disc.lap_mass = u(gen) - 0.5;
    p.owner.disc.lap_second = 0.5 + 3.0 * u(gen);
  }
  return p;
}

// The state after folding one pass of these sums into a fresh point at radius kR2.
PointState fold_one(const PassSums& g, const OwnerValues& o) {
  PointState s;
  s.r2 = kR2;
  EstimatorParams params;
  params.photons_per_pass = kPhotons;
  accumulate_pass(s, g, o, params, 1);
  return s;
}

void expect_mean_of_folds(const std::vector<Path>& paths) {
  PathMean mean;
  dvec3 x(0.0), lap(0.0);
  double r2_bias = 0.0;
  for (const Path& p : paths) {
    mean.add(p.sums, p.owner, kR2, kPhotons);
    // Each path alone: after one pass, mean_x is its sample X, mean_r2 its R_b^2, and
    // tau_lap / applied its Laplacian sample (the update scales both by the same factor).
    const PointState s = fold_one(p.sums, p.owner);
    const double applied = s.r2 / kR2;
    x += s.mean_x;
    r2_bias += s.mean_r2;
    lap += s.tau_lap / applied;
  }
  const double k = double(paths.size());
  PassSums g;
  OwnerValues o;
  mean.finish(kR2, g, o);
  const PointState s = fold_one(g, o);
  const double applied = s.r2 / kR2;
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(s.mean_x[c], x[c] / k, 1e-12 * (1.0 + std::abs(x[c])));
    EXPECT_NEAR(s.tau_lap[c] / applied, lap[c] / k, 1e-9 * (1.0 + std::abs(lap[c])));
  }
  EXPECT_NEAR(s.mean_r2, r2_bias / k, 1e-15);
  // The photon total is the first path's count: the paths share their photons (section 15).
  EXPECT_EQ(s.photons, uint64_t(paths[0].sums.count));
}

TEST(PathMean, FoldsTheMeanOfThePathsSamplesOnWholeDiscs) {
  std::mt19937 gen(7);
  for (int paths : {1, 2, 5, 16}) {
    std::vector<Path> v;
    for (int k = 0; k < paths; ++k) v.push_back(random_path(gen, false));
    expect_mean_of_folds(v);
  }
}

TEST(PathMean, FoldsTheMeanOfThePathsSamplesWhereDiscsAreCut) {
  std::mt19937 gen(11);
  for (int paths : {1, 2, 3, 8}) {
    std::vector<Path> v;
    for (int k = 0; k < paths; ++k) v.push_back(random_path(gen, k % 2 == 0));
    expect_mean_of_folds(v);
  }
}

// Whole discs: the sums are linear, so the two-scale sample of the mean is the mean of the
// paths' two-scale samples, and it is kept; with a cut disc among them the pass has none.
TEST(PathMean, KeepsTheTwoScaleSampleOnlyWhereEveryDiscIsWhole) {
  std::mt19937 gen(3);
  std::vector<Path> whole{random_path(gen, false), random_path(gen, false)};
  double y = 0.0;
  PathMean mean;
  for (const Path& p : whole) {
    y += fold_one(p.sums, p.owner).scale_mean;
    mean.add(p.sums, p.owner, kR2, kPhotons);
  }
  PassSums g;
  OwnerValues o;
  mean.finish(kR2, g, o);
  const PointState s = fold_one(g, o);
  EXPECT_EQ(s.scale_passes, 1u);
  EXPECT_NEAR(s.scale_mean, y / 2.0, 1e-12 * (1.0 + std::abs(y)));
  mean.add(random_path(gen, true).sums, random_path(gen, true).owner, kR2, kPhotons);
  mean.finish(kR2, g, o);
  EXPECT_EQ(fold_one(g, o).scale_passes, 0u);
}

// One path: the same fold bit for bit as without PathMean (a pixel of one path is untouched).
TEST(PathMean, OnePathOnAWholeDiscFoldsBitForBitAsItself) {
  std::mt19937 gen(5);
  const Path p = random_path(gen, false);
  PathMean mean;
  mean.add(p.sums, p.owner, kR2, kPhotons);
  PassSums g;
  OwnerValues o;
  mean.finish(kR2, g, o);
  const PointState a = fold_one(p.sums, p.owner), b = fold_one(g, o);
  EXPECT_EQ(a.mean_x, b.mean_x);
  EXPECT_EQ(a.tau, b.tau);
  EXPECT_EQ(a.tau_lap, b.tau_lap);
  EXPECT_EQ(a.scale_mean, b.scale_mean);
}

TEST(PathMean, SpreadIsTheSumOfSquaredDeviationsOfThePathsSamples) {
  std::mt19937 gen(13);
  std::vector<Path> v;
  for (int k = 0; k < 6; ++k) v.push_back(random_path(gen, k == 2));
  PathMean mean;
  std::vector<dvec3> x;
  for (const Path& p : v) {
    mean.add(p.sums, p.owner, kR2, kPhotons);
    x.push_back(fold_one(p.sums, p.owner).mean_x);
  }
  dvec3 m(0.0);
  for (const dvec3& xi : x) m += xi / double(x.size());
  double ss = 0.0;
  for (const dvec3& xi : x) ss += glm::dot(xi - m, xi - m);
  EXPECT_NEAR(mean.spread(), ss, 1e-9 * ss);
  PathMean one;
  one.add(v[0].sums, v[0].owner, kR2, kPhotons);
  EXPECT_EQ(one.spread(), 0.0);
}

}  // namespace
}  // namespace pb
