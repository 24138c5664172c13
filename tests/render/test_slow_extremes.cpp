// Extremes suite, long cases (issue 6): the rare-arrival coverage at full size, in the estimator
// and in a render; one photon per pass for 10^5 passes (10^6 with PHOTONBOUND_FULL_EXTREMES=1);
// the alpha sweep to 512 passes. ctest -R Extremes selects these with the fast ones
// (test_extremes.cpp); the file name gives them the label "slow".
#include "extremes.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace pb {
namespace {

using extremes::Render;

// Estimator level: 4000 points with a photon once in 1000 passes, to 20000 passes; 1000 points
// with a photon once in 10^4 passes, to 50000 passes. Asserted per check: unknown exactly where
// no photon arrived, no bound tighter than the photons allow, coverage at 90% >= 0.68 (the
// printed table is the measurement the issue asks for).
TEST(SlowExtremes, RareArrivalsSynthetic) {
  extremes::rare_arrivals(4000, 1e-3, {1000, 2000, 5000, 10000, 20000}, 0.68, 5);
  extremes::rare_arrivals(1000, 1e-4, {10000, 20000, 50000}, 0.68, 6);
}

// A render whose points receive a photon once in a few hundred passes: the analytic plane
// (16x16, photons only, 2000 photons per pass) with an initial radius of 3 mm. Per check the
// film contract holds (+inf exactly where no photon arrived), no pixel's bound is tighter than
// t L / sqrt(k) for its k photons, and the coverage against the exact answer does not collapse.
// Prints the coverage of the pixels with few photons and of those in a long empty streak.
TEST(SlowExtremes, RareArrivalsRendered) {
  RenderOptions o = extremes::options(test::scene_path("plane_point.gltf"), 16, 2000);
  o.radius = 0.003;
  Render run(o.scene, o);
  const size_t n = run.r->states().size();
  ASSERT_EQ(n, 256u);
  std::vector<uint64_t> last_photon(n, 0), before(n, 0);
  for (uint64_t check : {250, 500, 1000, 2000, 4000}) {
    while (run.r->passes() < check) {
      run.r->step();
      for (size_t k = 0; k < n; ++k) {
        if (run.r->states()[k].photons != before[k]) last_photon[k] = run.r->passes();
        before[k] = run.r->states()[k].photons;
      }
    }
    extremes::check_states(run);
    uint64_t ksum = 0, kmax = 0;
    for (const PointState& s : run.r->states()) {
      ksum += s.photons;
      kmax = std::max(kmax, s.photons);
    }
    for (double conf : {0.5, 0.9}) {
      FilmSettings fs = run.r->film_settings();
      fs.confidence = conf;
      FilmImage img;
      const extremes::FilmCounts c = extremes::check_film(*run.r, fs, &img);
      const BoundQuantile q(double(check - 1), conf);
      long known = 0, covered = 0, streak = 0, streak_covered = 0, few = 0, few_covered = 0;
      for (size_t p = 0; p < n; ++p) {
        const PointState& s = run.r->states()[p];
        if (s.photons < kMinPhotonsForBound) continue;
        const double exact = analytic::plane_point(run.r->camera_pass().points[p].position);
        const double l = img.radiance[3 * p], b = img.bound[3 * p];
        EXPECT_GE(b, 0.999 * q.two_sided_t() * l / std::sqrt(double(s.photons)))
            << "pixel " << p << " with " << s.photons << " photons";
        const bool cov = std::fabs(l - exact) <= b;
        ++known;
        covered += cov;
        if (s.photons <= 4) {
          ++few;
          few_covered += cov;
        }
        if (check - last_photon[p] >= 500) {
          ++streak;
          streak_covered += cov;
        }
      }
      const double coverage = double(covered) / double(std::max(known, 1L));
      std::printf(
          "rare render, %4llu passes, %2.0f%%: unknown %3zu/%zu, photons per point mean %.2f max "
          "%llu; coverage of known %.3f (%ld), with <= 4 photons %.3f (%ld), 500+ passes since "
          "the last photon %.3f (%ld)\n",
          (unsigned long long)check, 100 * conf, c.unknown, c.with_points, double(ksum) / double(n),
          (unsigned long long)kmax, coverage, known,
          double(few_covered) / double(std::max(few, 1L)), few,
          double(streak_covered) / double(std::max(streak, 1L)), streak);
      // Few points are known (54 to 167 here), so the 50% threshold is two binomial standard
      // errors below nominal (0.077 at 167 points; they share photons, so that is if anything
      // generous to the bound) and at least the 5 points of the other coverage tests; at 90% a
      // fixed 0.7: with about 5 photons a point's estimate is far from normal, and the
      // Poisson-limit bound only has to be of the right size, not calibrated.
      const double slack = std::max(0.05, 2.0 * std::sqrt(conf * (1.0 - conf) / double(known)));
      if (known >= 50) EXPECT_GE(coverage, conf > 0.7 ? 0.7 : conf - slack);
    }
  }
}

// One photon per pass on a 4x4 image: N and R^2 follow the formulas exactly on every pass and
// never freeze. 10^5 passes by default; the 10^6 with PHOTONBOUND_FULL_EXTREMES=1.
TEST(SlowExtremes, OnePhotonPerPassManyPasses) {
  extremes::one_photon_per_pass(extremes::full_extremes() ? 1000000 : 100000);
}

// alpha in {0.01, 0.5, 2/3, 0.99, 1} from 64 to 512 passes (plane, 16x16, R0 = 0.2): the bound
// shrinks as the passes grow (for alpha = 1 only its noise part can; for 0.01 the noise of the
// mean falls like i^{-alpha/2}, so no visible shrink is promised), the coverage holds at 90%, and
// the radius stays positive, above the floor, and unchanged for alpha = 1.
TEST(SlowExtremes, AlphaSweepLong) {
  for (double alpha : {0.01, 0.5, 2.0 / 3.0, 0.99, 1.0}) {
    RenderOptions o = extremes::options(test::scene_path("plane_point.gltf"), 16, 10000);
    o.alpha = alpha;
    o.radius = 0.2;
    o.adaptive_radius = false;  // the --alpha schedule itself (the default moves radii below it)
    Render run(o.scene, o);
    const double r2_initial = run.r->states().at(0).r2;
    run.passes(64);
    const double b64 = extremes::mean_bound(*run.r, 0.9);
    const double noise64 =
        develop(run.r->camera_pass(), run.r->states(), 64, run.r->film_settings(), nullptr)
            .mean_noise;
    run.passes(512);
    extremes::check_states(run);
    EXPECT_EQ(extremes::check_film(*run.r, run.r->film_settings()).unknown, 0u);
    const FilmSummary s512 =
        develop(run.r->camera_pass(), run.r->states(), 512, run.r->film_settings(), nullptr);
    const analytic::Accuracy a = analytic::measure(*run.r, analytic::plane_point, 0.9);
    std::printf(
        "alpha %.4f, 64 -> 512 passes: mean bound %.4g -> %.4g, noise %.4g -> %.4g, "
        "|bias| %.4g; mean error %.4g, coverage at 90%% %.3f\n",
        alpha, b64, s512.mean_bound, noise64, s512.mean_noise, s512.mean_abs_bias, a.mean_abs_error,
        a.coverage);
    if (alpha >= 0.5) {
      EXPECT_LT(s512.mean_bound, b64);
      EXPECT_LT(s512.mean_noise, noise64);
      EXPECT_GE(a.coverage, 0.85);
    }
    if (alpha == 1.0)
      for (const PointState& s : run.r->states()) EXPECT_EQ(s.r2, r2_initial);
  }
}

}  // namespace
}  // namespace pb
