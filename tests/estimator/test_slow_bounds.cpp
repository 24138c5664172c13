// The error bounds against exact answers in rendered scenes (issue "Error bounds", ESTIMATOR.md
// section 9): coverage at 50% and 90% confidence, and renders to halving target errors.
// Labelled slow. build/tools/bounds_study prints the same figures as tables for
// docs/error-bounds.md.
#include "analytic.h"
#include "reference_truth.h"
#include "render_fixture.h"

#include <gtest/gtest.h>

namespace pb {
namespace {

// Coverage must lie within 5 points of nominal or above it. Each check pools 64 x 64 pixels x 3
// (identical) channels of one render; neighbouring pixels share photons, so the effective sample
// is smaller than 4096, but a binomial standard error even for 400 independent pixels is 0.025
// at 50%: a 5-point shortfall is two such errors and would mean a bound that is too narrow.
void expect_coverage(const std::string& name, RenderOptions o) {
  const auto rows = analytic::coverage_run(name, o, {16, 64, 256}, {0.5, 0.9});
  for (const auto& r : rows) {
    std::printf("%s: %3llu passes, %.0f%%: coverage %.3f, mean bound / mean error %.2f\n",
                name.c_str(), (unsigned long long)r.passes, 100.0 * r.confidence,
                r.accuracy.coverage, r.accuracy.mean_bound / r.accuracy.mean_abs_error);
    EXPECT_GE(r.accuracy.coverage, r.confidence - 0.05)
        << name << " after " << r.passes << " passes at " << r.confidence;
    EXPECT_GT(r.accuracy.samples, 4000u);
  }
}

TEST(SlowBounds, CoverageOnAnalyticPlane) {
  RenderOptions o = test::quick_options("plane_point.gltf", 64, 256);
  o.direct = DirectMode::Photons;
  expect_coverage("plane", o);
}

TEST(SlowBounds, CoverageOnClosedEmittingBox) {
  RenderOptions o = test::quick_options("closed_box.gltf", 64, 256);
  o.direct = DirectMode::Photons;
  o.photons_per_pass = 25000;
  expect_coverage("box", o);
}

// The default mode: one next-event sample per point and pass (emitters chosen by solid angle at
// the receiver) plus photons after their first bounce.
TEST(SlowBounds, CoverageOnClosedEmittingBoxWithNextEvent) {
  RenderOptions o = test::quick_options("closed_box.gltf", 64, 256);
  o.photons_per_pass = 25000;
  expect_coverage("box", o);
}

// The closed box with a block floating inside (a furnace too, L = 2): the block's edges,
// creases and silhouettes, every pixel counted.
TEST(SlowBounds, CoverageOnClosedBoxWithBlockWithNextEvent) {
  RenderOptions o = test::quick_options("closed_block.gltf", 64, 256);
  o.photons_per_pass = 25000;
  expect_coverage("block", o);
}

// Issue "Bounds along geometric edges": the pixels within two radii of an edge (of the walls or
// the block) as their own set, after 64 passes, 2 seeds pooled (about 2400 edge pixel-channels):
// coverage at least nominal minus 3 points (a binomial standard error of 0.010 at 50% for
// independent pixels; neighbours share photons, so the true one is larger), and the band's mean
// error at most 1.5x the interior's (the edge darkening the boundary correction removes).
TEST(SlowBounds, EdgeBandOfTheBoxWithABlock) {
  for (double conf : {0.5, 0.9}) {
    double edge_err = 0, edge_n = 0, inner_err = 0, inner_n = 0, covered = 0;
    for (uint64_t seed : {1, 2}) {
      RenderOptions o = test::quick_options("closed_block.gltf", 64, 64);
      o.photons_per_pass = 25000;
      o.seed = seed;
      o.confidence = conf;
      const Scene scene = load_gltf(o.scene);
      Renderer r(scene, o);
      while (r.passes() < 64) r.step();
      const std::vector<double> truth = analytic::pixel_truth(r, analytic::closed_box);
      const std::vector<int> band = analytic::box_edge_band(r, 2.0);
      const analytic::Accuracy e = analytic::measure(r, truth, conf, &band, 1);
      const analytic::Accuracy i = analytic::measure(r, truth, conf, &band, 0);
      edge_err += e.mean_abs_error * double(e.samples);
      edge_n += double(e.samples);
      covered += e.coverage * double(e.samples);
      inner_err += i.mean_abs_error * double(i.samples);
      inner_n += double(i.samples);
    }
    const double coverage = covered / edge_n, ratio = (edge_err / edge_n) / (inner_err / inner_n);
    std::printf(
        "block, 64 passes, %.0f%%: edge band %.0f pixel-channels, coverage %.3f, mean "
        "error edge / interior %.2f\n",
        100 * conf, edge_n, coverage, ratio);
    EXPECT_GT(edge_n, 1000.0);
    EXPECT_GE(coverage, conf - 0.03);
    EXPECT_LE(ratio, 1.5);
  }
}

// Issue "Bounds along geometric edges" on the Cornell box, against its reference (a long SPPM
// render, tools/study/cornell_64x64_sppm_reference.exr; docs/error-bounds.md "The Cornell box
// against its reference" says how it was made).
// SPPM at 10k photons per pass, 4 seeds pooled, every pixel counted, the reference's own noise
// counted (reference::Accuracy): coverage within 2 points of nominal at 16, 64 and 256 passes
// (16,000+ correlated pixel-channels per check: a binomial standard error of 0.004 at 50% for
// independent ones, and the same pixels are measured at three pass counts), and the band within
// two radii of an edge (about 40% of the pixels) at least nominal minus 3. The band's mean
// relative error after 64 passes is at most 1.5x the interior's: the absolute ratio measures the
// brightness of the light's rim and the corners, not a darkening, so brightness is divided out
// (measured: 1.42 pooled, 1.42 and 1.47 for one and two seeds; absolute ratio 3.97).
void expect_cornell_coverage(const RenderOptions& o) {
  const reference::Truth truth =
      reference::load(std::string(PHOTONBOUND_REFERENCES) + "/cornell_64x64_sppm_reference.exr");
  reference::PooledCoverage pc =
      reference::pooled_coverage(o, 4, truth, {16, 64, 256}, {0.5, 0.9, 0.95});
  using S = reference::Sums;
  for (size_t ci = 0; ci < 3; ++ci)
    for (int bi = 0; bi < 2; ++bi)
      for (size_t k = 0; k < 3; ++k) {
        const S& s = pc.at(ci, bi, k);
        const double c = s.mean(&S::covered_ref), conf = pc.confidences[k];
        std::printf("cornell, %3llu passes, %s, %.0f%%: coverage %.3f over %.0f\n",
                    (unsigned long long)pc.checks[ci], bi == 0 ? "all" : "edge band", 100 * conf, c,
                    s.n);
        EXPECT_GT(s.n, bi == 0 ? 16000.0 : 4000.0);
        EXPECT_GE(c, conf - (bi == 0 ? 0.02 : 0.03))
            << pc.checks[ci] << " passes, band " << bi << ", confidence " << conf;
        if (bi == 0) EXPECT_LE(c, conf + 0.02) << pc.checks[ci] << " passes, " << conf;
      }
  const double ratio = pc.at(1, 1, 0).mean(&S::rel) / pc.at(1, 2, 0).mean(&S::rel);
  std::printf("cornell, 64 passes: mean relative error edge / interior %.2f\n", ratio);
  EXPECT_LE(ratio, 1.5);
}

RenderOptions cornell_options() {
  RenderOptions o = test::quick_options("cornell.gltf", 64, 256);
  o.method = Method::SPPM;
  o.photons_per_pass = 10000;
  return o;
}

TEST(SlowBounds, CoverageOnCornellBoxAgainstItsReference) {
  expect_cornell_coverage(cornell_options());
}

// Issue 39's calibration with every adaptive part on (ESTIMATOR.md sections 13-15): the
// radius, the guided photons and several camera paths where the camera part is the noise.
TEST(SlowBounds, CoverageOnCornellBoxWithEveryAdaptivePart) {
  RenderOptions o = cornell_options();
  o.adaptive_radius = o.adaptive_photons = o.adaptive_paths = true;
  expect_cornell_coverage(o);
}

// Three targets halving in turn, three seeds each, with the default rule (mean-error: the
// predicted mean |error| at the confidence is at most the target, ESTIMATOR.md section 7).
// Issue 15's figures: the actual mean error is within the target in at least a fraction C of
// the runs, and the mean specified / actual is at most 1.2. Nine runs cannot resolve a
// fraction, so at 50% no run may end more than 25% above its target and at 90% at most one of
// the nine above it (0.9^9 = 0.39 of a calibrated rule's sets have none, 0.39 + 0.39 one: a
// second would be a 22% event for a rule that was right, and a sign of an optimistic one).
// The mean ratio is held to 1.2 at both (the figure) and to at least 0.8 at 50%.
void expect_termination(Method method, double confidence, std::initializer_list<double> targets) {
  double ratio_sum = 0.0;
  int runs = 0, above = 0;
  for (double target : targets) {
    for (uint64_t seed : {1, 2, 3}) {
      RenderOptions o = test::quick_options("plane_point.gltf", 32, 1);
      o.method = method;
      o.seed = seed;
      o.passes = 20000;  // a safety net only: the target must stop it first
      o.direct = DirectMode::Photons;
      o.confidence = confidence;
      o.target_error = target;
      const analytic::TerminationRow r = analytic::termination_run("plane", o);
      std::printf(
          "%s target %.4f at %.0f%% seed %llu: actual %.5f, specified/actual %.2f, %llu passes\n",
          method == Method::SPPM ? "sppm" : "ppm", target, 100.0 * confidence,
          (unsigned long long)seed, r.actual, target / r.actual, (unsigned long long)r.passes);
      EXPECT_EQ(r.stop_reason, "target-error");
      ratio_sum += target / r.actual;
      ++runs;
      if (r.actual > target) ++above;
      if (confidence <= 0.5) EXPECT_GE(target / r.actual, 0.8);
    }
  }
  const double mean_ratio = ratio_sum / runs;
  std::printf("mean specified/actual %.3f, %d of %d runs above the target\n", mean_ratio, above,
              runs);
  EXPECT_LE(mean_ratio, 1.2);
  if (confidence <= 0.5) EXPECT_GE(mean_ratio, 0.8);
  if (confidence >= 0.9) EXPECT_LE(above, 1);
}

TEST(SlowBounds, TerminationAtHalvingTargetsFiftyPercent) {
  expect_termination(Method::SPPM, 0.5, {0.016, 0.008, 0.004});
}

TEST(SlowBounds, TerminationAtHalvingTargetsNinetyPercent) {
  expect_termination(Method::SPPM, 0.9, {0.016, 0.008, 0.004});
}

TEST(SlowBounds, TerminationAtHalvingTargetsNinetyPercentPpm) {
  expect_termination(Method::PPM, 0.9, {0.016, 0.008, 0.004});
}

// pixels:0.9 at 90% (issue 15): at least 90% of the pixels have a bound at or below the target,
// and each bound holds with probability 0.9, so at least 0.81 of the pixels are within the
// target for a calibrated bound even if every failure fell on a pixel whose bound was just at
// the target; in practice most bounds at the stop are well below it. The closed box (32x32, next
// event, 5k photons per pass), targets 0.06 and 0.03, three seeds: every run keeps at least 0.85
// of its pixels within the target, and the mean over the six at least 0.9.
TEST(SlowBounds, PixelsRuleAtNinetyPercentKeepsNinetyPercentOfPixelsWithinTheTarget) {
  double mean = 0.0;
  int runs = 0;
  for (double target : {0.06, 0.03})
    for (uint64_t seed : {1, 2, 3}) {
      RenderOptions o = test::quick_options("closed_box.gltf", 32, 1000000);
      o.method = Method::SPPM;
      o.photons_per_pass = 5000;
      o.confidence = 0.9;
      o.target_error = target;
      o.stop_rule = StopRule::Pixels;
      o.stop_fraction = 0.9;
      o.seed = seed;
      const analytic::TerminationRow r = analytic::termination_run("box", o);
      std::printf(
          "box, pixels:0.9 at 90%%, target %.3f, seed %llu: %llu passes, %.3f of pixels "
          "within the target, mean error %.4f\n",
          target, (unsigned long long)seed, (unsigned long long)r.passes, r.pixels_within,
          r.actual);
      EXPECT_EQ(r.stop_reason, "target-error");
      EXPECT_GE(r.pixels_within, 0.85);
      mean += r.pixels_within;
      ++runs;
    }
  EXPECT_GE(mean / runs, 0.9);
}

// HJJ10's rule (mean-bound): the mean of the per-pixel 90% bounds at the target. It is
// conservative at 90% (2.45-2.85x below the target when this test was written; docs/error-bounds.md
// "The stop rules side by side" has the 20-seed figures), so every run ends below it.
TEST(SlowBounds, MeanBoundRuleAtNinetyPercentEndsBelowTheTarget) {
  for (double target : {0.02, 0.01}) {
    RenderOptions o = test::quick_options("plane_point.gltf", 32, 1);
    o.passes = 20000;
    o.direct = DirectMode::Photons;
    o.confidence = 0.9;
    o.target_error = target;
    o.stop_rule = StopRule::MeanBound;
    const analytic::TerminationRow r = analytic::termination_run("plane", o);
    std::printf("mean-bound target %.4f at 90%%: actual %.5f, specified/actual %.2f, %llu passes\n",
                target, r.actual, target / r.actual, (unsigned long long)r.passes);
    EXPECT_EQ(r.stop_reason, "target-error");
    EXPECT_LE(r.mean_bound, target);
    EXPECT_LT(r.actual, target);
  }
}

}  // namespace
}  // namespace pb
