// No stop condition can hang or declare success early (issue "Honest bounds where geometry
// ends"): scenes whose points all, or partly, receive no photon end with a reason in a bounded
// number of passes, every bound finite, and the actual error within the target.
#include "analytic.h"
#include "app/progress.h"
#include "render_fixture.h"
#include "scene_builder.h"

#include <gtest/gtest.h>

#include <sstream>

namespace pb {
namespace {

struct StopCase {
  RenderReport report;
  double actual = 0.0;  // mean |L - L_exact| over pixels and channels with a point or area
};

StopCase run_plane(RenderOptions o) {
  Renderer r(load_gltf(o.scene), o);
  StopCase c;
  c.report = test::run_to_stop(r);
  const std::vector<double> truth = analytic::pixel_truth(r, analytic::plane_point);
  FilmImage img;
  r.develop(&img);
  double sum = 0.0;
  size_t n = 0;
  for (size_t p = 0; p < truth.size(); ++p) {
    if (std::isnan(truth[p])) continue;
    for (int ch = 0; ch < 3; ++ch) {
      sum += std::fabs(double(img.radiance[3 * p + size_t(ch)]) - truth[p]);
      ++n;
      EXPECT_TRUE(std::isfinite(img.bound[3 * p + size_t(ch)])) << "pixel " << p;
    }
  }
  c.actual = n ? sum / double(n) : 0.0;
  return c;
}

// Next-event estimation on the plane: the direct light is exact and no photon ever lands on a
// point (photons are stored after a bounce, and nothing bounces back). The points' bound is the
// sparse-photon bound (ESTIMATOR.md section 12), falling as 1/passes: the target is met.
TEST(Stop, EveryPointUnreachedStopsWithFiniteBounds) {
  for (Method m : {Method::PPM, Method::SPPM}) {
    RenderOptions o = test::quick_options("plane_point.gltf", 24, 1);
    o.method = m;
    o.passes = 100000;
    o.target_error = 0.002;
    o.photons_per_pass = 20000;
    const StopCase c = run_plane(o);
    EXPECT_EQ(stop_text(c.report.stop), "target-error") << int(m);
    EXPECT_LT(c.report.work.passes, 5000u) << int(m);
    EXPECT_EQ(c.report.summary.unknown_pixels, 0u);
    EXPECT_LE(c.actual, 0.002) << int(m);
  }
}

// Photons only, so few per pass that many points have seen fewer than 5 after the first test
// (16 passes): the old rule left them out of the mean and stopped at once. Now their bound is
// counted, so the render runs until the whole image is within the target.
TEST(Stop, SomePointsUnreachedDoNotStopEarly) {
  for (Method m : {Method::PPM, Method::SPPM}) {
    RenderOptions o = test::quick_options("plane_point.gltf", 24, 1);
    o.method = m;
    o.direct = DirectMode::Photons;
    o.photons_per_pass = 300;
    o.passes = 200000;
    o.target_error = 0.05;
    o.confidence = 0.9;
    const StopCase c = run_plane(o);
    EXPECT_EQ(stop_text(c.report.stop), "target-error") << int(m);
    EXPECT_GT(c.report.work.passes, 16u) << int(m);
    EXPECT_LE(c.report.summary.predicted_error_upper, 0.05);
    // The image is within the target, as the mean-error rule promises at 90%.
    EXPECT_LE(c.actual, 0.05) << int(m);
  }
}

// A light that no visible point sees: under the plane (the photons land on its back, which the
// same-side test rejects, and next-event sees the light from behind), or shut in a closed box
// beside it. The radiance is exactly 0; every pixel's bound is the sparse-photon bound of a
// point that received nothing (ESTIMATOR.md section 12), which falls as 1 / passes, so the
// target is met in a bounded number of passes with every bound finite. Bound: 0.002 needs
// lambda_u cap <= 0.002 with lambda_u = ln(10) / k at 90%, 60 passes here.
TEST(Stop, LightThatNoPointSeesStopsWithFiniteBounds) {
  for (int where = 0; where < 2; ++where)
    for (Method m : {Method::PPM, Method::SPPM}) {
      SCOPED_TRACE(std::string(where ? "light in a box" : "light under the plane") + ", " +
                   (m == Method::PPM ? "PPM" : "SPPM"));
      test::SceneBuilder b;
      const uint32_t grey = b.material(vec3(0.5f));
      b.quad(vec3(0), vec3(5, 0, 0), vec3(0, 0, -5), grey);
      if (where == 0) {
        b.point_light(vec3(0, -1, 0), vec3(10.0f));
      } else {
        // Faces outward; the light at its centre lights only the inside (the back faces).
        b.box(vec3(3.0f, 0.0f, -1.0f), vec3(4.0f, 1.0f, 0.0f), grey);
        b.point_light(vec3(3.5f, 0.5f, -0.5f), vec3(10.0f));
      }
      b.camera(vec3(0, 3, 0), vec3(0), 0.6f, vec3(0, 0, -1));
      RenderOptions o = test::quick_options("plane_point.gltf", 16, 1);
      o.method = m;
      o.passes = 100000;
      o.target_error = 0.002;
      o.photons_per_pass = 2000;
      Renderer r(std::move(b.scene), o);
      const RenderReport report = test::run_to_stop(r);
      std::printf("stopped after %llu passes, mean bound %.4g\n",
                  (unsigned long long)report.work.passes, report.summary.mean_bound);
      EXPECT_EQ(stop_text(report.stop), "target-error");
      EXPECT_LT(report.work.passes, 20000u);
      EXPECT_EQ(report.summary.unknown_pixels, 0u);
      FilmImage img;
      r.develop(&img);
      for (size_t k = 0; k < img.bound.size(); ++k) {
        ASSERT_TRUE(std::isfinite(img.bound[k])) << "pixel-channel " << k;
        ASSERT_EQ(img.radiance[k], 0.0f) << "pixel-channel " << k;
      }
    }
}

// SPPM: a pixel on the plane's edge meets the plane in some passes and the black background in
// the others, and its estimate is the mean over every pass. With the light under the plane no
// photon lands and all its samples are 0, so its bound is the sparse-photon bound alone:
// chi^2 / (2 i) x its cap = ln(10) / i x w(0) Phi_max (f / c) / (pi R^2 M_e) at 90%, with i all
// the passes (ESTIMATOR.md section 12). Dividing by the passes with a visible point instead made
// it i / k_v times wider, widest where the visible point is rare. Exact to float rounding
// (1e-5). A Lambertian plane (the scene's largest Lambertian f over the pixel's smallest c) and
// a rough metal one (glTF's default material: the largest f / c its glossy points had, which
// the bound must take as it is, not divided by c again).
TEST(Stop, SppmSparseBoundOfAPartlyCoveredPixelCountsEveryPass) {
  for (const bool metal : {false, true}) {
    SCOPED_TRACE(metal ? "rough metal" : "Lambertian");
    test::SceneBuilder b;
    const uint32_t mat = b.material(vec3(0.5f));
    if (metal) b.scene.materials[mat] = Material::metal(vec3(0.5f), 1.0f);
    b.quad(vec3(0), vec3(1, 0, 0), vec3(0, 0, -1), mat);
    b.point_light(vec3(0, -1, 0), vec3(10.0f));
    b.camera(vec3(0, 3, 0), vec3(0), 0.8f, vec3(0, 0, -1));
    RenderOptions o = test::quick_options("plane_point.gltf", 16, 1);
    o.method = Method::SPPM;
    o.photons_per_pass = 2000;
    o.confidence = 0.9;
    Renderer r(std::move(b.scene), o);
    const uint64_t passes = 40;
    for (uint64_t k = 0; k < passes; ++k) r.step();
    FilmImage img;
    r.develop(&img);
    const PixelLayout l = r.layout();
    int partial = 0, glossy = 0;
    for (size_t p = 0; p < r.states().size(); ++p) {
      const uint32_t v = l.visible_passes[p];
      if (v == 0 || v == passes) continue;
      ++partial;
      const PointState& s = r.states()[p];
      ASSERT_EQ(s.photons, 0u);
      const double c = std::max(double(l.mass[p]), kMinKernelMass);
      const double glossy_cap = l.glossy_f.empty() ? 0.0 : double(l.glossy_f[p]);
      glossy += glossy_cap > 0.0;
      for (int ch = 0; ch < 3; ++ch) {
        const double f_over_c = std::max(l.max_f[ch] / c, glossy_cap);
        const double want =
            std::log(10.0) / double(passes) * l.photon_cap * f_over_c / (kPiD * s.r2);
        EXPECT_NEAR(img.bound[3 * p + size_t(ch)], want, 1e-5 * want)
            << "pixel " << p << ", visible in " << v << " of " << passes << " passes";
      }
    }
    EXPECT_GT(partial, 4);  // the plane's edges cross pixels
    // The metal plane's pixels bound with their glossy caps, the Lambertian's with max_f.
    if (metal)
      EXPECT_EQ(glossy, partial);
    else
      EXPECT_EQ(glossy, 0);
  }
}

// A plane under a point light with, 0.3 above it, a sliver 0.12 wide across the view, at a radius
// of 20 (PPM's points are fixed): the sliver's discs hold about 0.007 of their kernel's mass,
// below kValidKernelMass, so its two rows of pixels (6% of the image) stay unknown for good, and
// the plane's (mass 0.04) are known. The pixel-share rule's 90% quantile is then finite: before
// issue 37 it stopped on the target with those pixels unknown.
Scene plane_and_sliver() {
  test::SceneBuilder b;
  b.quad(vec3(0), vec3(0, 0, 2), vec3(2, 0, 0), b.material(vec3(0.5f)));
  b.quad(vec3(0, 0.3f, 0), vec3(0, 0, 0.06f), vec3(1.8f, 0, 0), b.material(vec3(0.5f)));
  b.point_light(vec3(0, 1, 0), vec3(10.0f));
  b.camera(vec3(0, 3, 0), vec3(0, 0, 0), 0.8f, vec3(0, 0, -1));
  return b.scene;
}

TEST(Stop, NoRuleStopsOnTheTargetWithAPixelUnknown) {
  for (StopRule rule : {StopRule::Pixels, StopRule::MeanBound, StopRule::MeanError}) {
    RenderOptions o = test::quick_options("unused.gltf", 24, 1);
    o.radius = 20.0;
    o.photons_per_pass = 2000;
    o.passes = 40;
    o.target_error = 1e30;  // met by any finite figure
    o.stop_rule = rule;
    Renderer r(plane_and_sliver(), o);
    const RenderReport report = test::run_to_stop(r);
    EXPECT_GT(report.summary.unknown_pixels, 0u) << int(rule);
    EXPECT_LT(report.summary.unknown_pixels, 24u * 24u / 10u) << int(rule);
    EXPECT_EQ(stop_text(report.stop), "passes") << int(rule);
  }
  // Without the sliver the same target stops at the first check.
  RenderOptions o = test::quick_options("unused.gltf", 24, 1);
  o.radius = 20.0;
  o.passes = 40;
  o.target_error = 1e30;
  o.stop_rule = StopRule::Pixels;
  Scene s = plane_and_sliver();
  s.meshes.pop_back();
  Renderer r(std::move(s), o);
  const RenderReport report = test::run_to_stop(r);
  EXPECT_EQ(report.summary.unknown_pixels, 0u);
  EXPECT_EQ(stop_text(report.stop), "target-error");
}

TEST(Stop, TheClosingLineGivesNoMeanOverAMinorityOfPixels) {
  RenderOptions o;
  o.stop_rule = StopRule::MeanBound;
  FilmSummary s;
  s.pixels = 100;
  s.mean_bound = 0.25;
  EXPECT_EQ(stop_figures(o, s), "mean bound 0.25");
  s.unknown_pixels = 30;  // a majority known: their mean, said to be theirs
  EXPECT_EQ(stop_figures(o, s), "mean bound 0.25 over the 70 known pixels of 100, 30 unknown");
  s.unknown_pixels = 50;  // not a majority: no mean (issue 37: the background's 0)
  s.mean_bound = 0.0;
  EXPECT_EQ(stop_figures(o, s), "mean bound unknown: 50 of 100 pixels have no bound yet");
  s.unknown_pixels = 100;
  s.mean_bound = INFINITY;
  EXPECT_EQ(stop_figures(o, s), "mean bound inf");
}

// The image a render writes is its final states' development: a target stop hands over the one
// its stop test developed (it is not developed twice), a stop on passes after tests that did
// not stop develops the last states, not an earlier test's.
TEST(Stop, TheReportsImageIsTheLastStatesDevelopment) {
  struct Case {
    double target;
    uint64_t passes;
    const char* stop;
  };
  for (const Case c : {Case{1e30, 40, "target-error"}, Case{1e-12, 21, "passes"}}) {
    RenderOptions o = test::quick_options("cornell.gltf", 16, c.passes);
    o.photons_per_pass = 2000;
    o.target_error = c.target;
    Renderer r(load_gltf(o.scene), o);
    const RenderReport report = test::run_to_stop(r);
    EXPECT_EQ(stop_text(report.stop), c.stop);
    ASSERT_TRUE(report.film.has_value()) << c.stop;
    FilmImage fresh;
    const FilmSummary summary = r.develop(&fresh);
    EXPECT_EQ(report.summary.mean_bound, summary.mean_bound) << c.stop;
    EXPECT_EQ(report.summary.predicted_error, summary.predicted_error) << c.stop;
    EXPECT_EQ(report.film->radiance, fresh.radiance) << c.stop;
    EXPECT_EQ(report.film->bound, fresh.bound) << c.stop;
    EXPECT_EQ(report.film->target_ratio, fresh.target_ratio) << c.stop;
  }
}

// The stop test's schedule (ESTIMATOR.md section 7): about 10% of the passes apart, drawn in to
// the pass where the power law through two tests puts the target, never nearer than 2.5% of the
// passes, or put off to three quarters of the way to it, never beyond twice the passes; any
// quantity without a usable trend keeps the regular schedule.
TEST(Stop, TheNextTestIsAtTheExtrapolatedCrossingWithinTheRegularInterval) {
  // A quantity falling exactly as passes^-0.5: 0.02 at pass 100, 0.02 * sqrt(100 / 200) at 200.
  const double at100 = 0.02, at200 = 0.02 * std::sqrt(0.5);
  EXPECT_NEAR(passes_to_target(200, at200, 100, at100, 0.01), 400.0, 1e-9);
  // The target far off (at 400 passes): three quarters of the way there, not 10% on.
  const uint64_t later = next_check_after(200, at200, 100, at100, 0.01);
  EXPECT_GE(later, 350u);
  EXPECT_LE(later, 351u);  // the ceiling of 350 computed in floating point
  // Just beyond the regular test (at 223.5): three quarters of the way falls short of the
  // regular test, which stays.
  EXPECT_EQ(next_check_after(200, at200, 100, at100, at200 * std::sqrt(200.0 / 223.5)), 220u);
  // A quantity that barely falls is taken to fall at least as passes^-0.5 (here to 0.01 at
  // 200 x 1.1^2 = 242 passes: three quarters of the way is 231.5), as the noise does: it fell
  // little between passes 16 and 17 where --adaptive paths begins, and fast after them. A far
  // target is tested at twice the passes at the latest.
  EXPECT_EQ(next_check_after(200, 0.011, 100, 0.01101, 0.01), 232u);
  EXPECT_EQ(next_check_after(200, 0.0199, 100, 0.02, 0.01), 400u);
  // The crossing 5% on (at 210.x passes): the test there, rounded up, not at 220.
  const double target = at200 * std::sqrt(200.0 / 210.5);
  EXPECT_EQ(next_check_after(200, at200, 100, at100, target), 211u);
  // The crossing 1% on: no nearer than 2.5% (5 passes).
  EXPECT_EQ(next_check_after(200, at200, 100, at100, at200 * std::sqrt(200.0 / 202.0)), 205u);
  // Below 40 passes the nearest is the next pass; below 20 every pass is a test anyway.
  EXPECT_EQ(next_check_after(30, 0.0101, 16, 0.02, 0.01), 31u);
  EXPECT_EQ(next_check_after(16, 0.5, 0, 0.0, 0.01), 17u);
  // No earlier test, a quantity that rose, an unknown one, a met target: the regular schedule.
  EXPECT_EQ(next_check_after(200, 0.0101, 0, 0.0, 0.01), 220u);
  EXPECT_EQ(next_check_after(200, 0.0101, 100, 0.0100, 0.01), 220u);
  EXPECT_EQ(next_check_after(200, INFINITY, 100, 0.02, 0.01), 220u);
  EXPECT_EQ(next_check_after(200, NAN, 100, 0.02, 0.01), 220u);
  // An earlier test with a pixel unknown (its quantity infinite) gives no trend either: not a
  // fall so steep that the target is due at once.
  EXPECT_EQ(next_check_after(200, 0.0101, 100, INFINITY, 0.01), 220u);
  EXPECT_EQ(next_check_after(200, 0.009, 100, 0.02, 0.01), 220u);
  EXPECT_TRUE(std::isnan(passes_to_target(200, 0.0101, 200, 0.02, 0.01)));
}

// The progress line's time left (progress.h seconds_left). README's first command at 1920x1080
// showed "~890.7 s left" at its first test (pass 16, 9.3 s in, the mean error 0.01571 against
// 0.01) for a render that stopped 9 s later: with no trend yet the only figure was the rest of
// --time 900. With the noise's fall, passes^-1/2, the target is due at 16 x 1.571^2 = 39.5
// passes, 23.5 passes of 0.58 s: 13.7 s (the render needed 11 more passes, falling faster).
TEST(Stop, TheTimeLeftFollowsTheTestedQuantitysFall) {
  RenderOptions o;
  o.target_error = 0.01;
  o.time_seconds = 900.0;
  const double per_pass = 9.3 / 16.0;
  // The first test: the schedule's earlier test is this one (taken at this pass), no line before.
  DriverState first{9.3, 17, 16, 0.01571};
  const double want = (16.0 * (1.571 * 1.571) - 16.0) * per_pass;
  EXPECT_NEAR(seconds_left(o, first, 16, 9.3, 9.3, 0.01571, {}), want, 1e-9);
  // When the passes double the schedule takes the test it extrapolates from anew, at that pass
  // (32 after 16): the line's own previous figure (at 24) gives the trend then, not the budget.
  // An exact passes^-1 fall: 0.012 at 24, 0.009 at 32 against a target of 0.006: due at 48.
  o.target_error = 0.006;
  const DriverState rebased{18.6, 35, 32, 0.009};
  EXPECT_NEAR(seconds_left(o, rebased, 32, 18.6, 18.6, 0.009, {24, 0.012}), 16.0 * per_pass, 1e-9);
  // Through the schedule's earlier test where it is an earlier pass (16, at 0.018): the same 48.
  const DriverState trend{18.6, 35, 16, 0.018};
  EXPECT_NEAR(seconds_left(o, trend, 32, 18.6, 18.6, 0.009, {}), 16.0 * per_pass, 1e-9);
  bool bounded_only = true;
  EXPECT_NEAR(seconds_left(o, trend, 32, 18.6, 18.6, 0.009, {}, &bounded_only), 16.0 * per_pass,
              1e-9);
  EXPECT_FALSE(bounded_only);
  // A quantity that rose since every earlier figure, or none known yet (pass 1): no estimate
  // from the target, only what --time leaves ("<= X s left").
  const DriverState rose{18.6, 35, 16, 0.008};
  EXPECT_NEAR(seconds_left(o, rose, 32, 18.6, 18.6, 0.009, {24, 0.0085}, &bounded_only),
              900.0 - 18.6, 1e-9);
  EXPECT_TRUE(bounded_only);
  EXPECT_NEAR(seconds_left(o, DriverState{}, 1, 0.5, 0.5, INFINITY, {}, &bounded_only), 899.5,
              1e-9);
  EXPECT_TRUE(bounded_only);
  // --passes gives an estimate of its own (its passes at the mean pass's time).
  o.passes = 40;
  EXPECT_NEAR(seconds_left(o, DriverState{}, 1, 0.5, 0.5, INFINITY, {}, &bounded_only), 39.0 * 0.5,
              1e-9);
  EXPECT_FALSE(bounded_only);
  o.passes.reset();
  // At the target: the time to the next scheduled test (pass 35), never the budget.
  EXPECT_NEAR(seconds_left(o, trend, 32, 18.6, 18.6, 0.005, {}), 3.0 * per_pass, 1e-9);
  // No target and no budget: no figure.
  RenderOptions none;
  EXPECT_TRUE(std::isinf(seconds_left(none, first, 16, 9.3, 9.3, 0.01571, {})));
}

// The progress line's developments (ProgressPrinter): pass 1's line has no figure and asks for
// none; with a target, before any development (its cost unknown, taken as a pass's: an interval
// of 20 passes), none where the first test is within the interval (README's first command at
// 1920x1080 developed at pass 1 and at pass 15, a pass before its first test: 0.3 s each);
// after a development of 0.3 s (an interval of 20 x 0.3 = 6 s) one of its own only where the
// next test is more than the interval away; without a target, from pass 2 at its interval.
// The lines before the first development show the pass, photons and times, every 2 s.
TEST(Stop, TheProgressLineDevelopsOnlyWhereNoStopTestBringsItsFigures) {
  RenderOptions o = test::quick_options("plane_point.gltf", 8, 1);
  o.target_error = 0.01;
  o.time_seconds = 900.0;
  Renderer r(load_gltf(o.scene), o);
  r.step();
  r.step();
  std::ostringstream out;
  ProgressPrinter printer(out);
  DriverState state{0.4, 16, 0, 0.0};
  const FilmSummary empty;
  auto after_pass_of = [&](ProgressPrinter& p, uint64_t pass, double seconds) {
    state.seconds = seconds;
    p.after_pass(PassInfo{r, state, pass, seconds, false, empty, StopReason::None, 0.0});
  };
  auto after = [&](uint64_t pass, double seconds, bool developed, const FilmSummary& s) {
    state.seconds = seconds;
    printer.after_pass(
        PassInfo{r, state, pass, seconds, developed, s, StopReason::None, developed ? 0.3 : 0.0});
  };
  EXPECT_FALSE(printer.wants_summary(1, 0.4, 16));
  after(1, 0.4, false, empty);
  EXPECT_FALSE(printer.wants_summary(2, 0.8, 16));   // the first test is at 16, within 20
  EXPECT_FALSE(printer.wants_summary(15, 6.0, 16));  // passes (the interval before a development)
  // A first test far away (--min-passes 1000): figures once the interval, 20 passes' time, is up.
  EXPECT_FALSE(printer.wants_summary(10, 4.0, 1000));
  EXPECT_TRUE(printer.wants_summary(30, 12.0, 1000));
  after(2, 0.8, false, empty);  // within 2 s of pass 1's line: not printed
  after(6, 2.4, false, empty);
  // The first test, then a test near (17) and one far (30) at 0.4 s a pass.
  const FilmSummary tested = r.develop();
  after(16, 6.4, true, tested);
  EXPECT_FALSE(printer.wants_summary(17, 6.8, 17));
  EXPECT_FALSE(printer.wants_summary(25, 10.0, 30));  // 6 s after pass 16's line, 2 s to a test
  EXPECT_TRUE(printer.wants_summary(25, 12.5, 60));   // 6.1 s after it, 14 s to the next test
  EXPECT_FALSE(printer.wants_summary(25, 12.3, 60));  // within the interval of pass 16's line
  // Printed: pass 1 and 6 without figures, 16 with them.
  const std::string text = out.str();
  EXPECT_NE(text.find("pass 1 |"), std::string::npos) << text;
  EXPECT_EQ(text.find("pass 2 |"), std::string::npos) << text;
  const size_t six = text.find("pass 6 |"), sixteen = text.find("pass 16 |");
  ASSERT_NE(six, std::string::npos) << text;
  ASSERT_NE(sixteen, std::string::npos) << text;
  EXPECT_EQ(text.substr(0, sixteen).find("mean error"), std::string::npos) << text;
  EXPECT_NE(text.find("mean error", sixteen), std::string::npos) << text;
  // Without a target: from pass 2, where pass 1's line is 0.5 s old (a development whose line
  // would not be printed is wasted).
  ProgressPrinter plain(out);
  EXPECT_FALSE(plain.wants_summary(1, 0.2, 0));
  after_pass_of(plain, 1, 0.2);
  EXPECT_FALSE(plain.wants_summary(2, 0.4, 0));
  EXPECT_TRUE(plain.wants_summary(3, 0.8, 0));
}

}  // namespace
}  // namespace pb
