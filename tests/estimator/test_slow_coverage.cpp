// Coverage of the error bound on synthetic data (ESTIMATOR.md section 9): photons drawn from a
// known 2D density, the progressive estimator of estimator.h driven pass by pass at many query
// points over independent trials, and the fraction of (point, trial) whose actual error lies
// within the reported bound compared with the nominal confidence. Then the same in a render
// whose visible points are glossy (glTF's BRDF evaluated per photon) against its exact answer.
#include "analytic.h"
#include "pass_sample.h"
#include "render_fixture.h"

#include "estimator/estimator.h"
#include "estimator/kernel.h"
#include "util/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

namespace pb {
namespace {

constexpr double kPi_ = std::numbers::pi;

// Density on the plane: half uniform on the unit square, half an isotropic Gaussian bump
// (centre (0.5, 0.5), sigma 0.1; not truncated, photons outside the square simply land where no
// query point can see them). Integrates to 1, so with photon power 1 and the estimator's
// normalisation phi / (pi R^2 M_e) the exact answer at x is the density p(x).
constexpr double kSigma = 0.1;
double density(double x, double y) {
  const double uni = (x >= 0.0 && x <= 1.0 && y >= 0.0 && y <= 1.0) ? 0.5 : 0.0;
  const double dx = x - 0.5, dy = y - 0.5;
  const double g =
      std::exp(-(dx * dx + dy * dy) / (2.0 * kSigma * kSigma)) / (2.0 * kPi_ * kSigma * kSigma);
  return uni + 0.5 * g;
}

struct Photon {
  double x, y;
};

// Photons of one pass of one trial; binned in a uniform grid of cell size >= the largest radius
// so a gather visits the 3 x 3 cells around the query.
struct PassPhotons {
  static constexpr int kCells = 20;  // cell size 0.05 = initial radius
  std::vector<Photon> photons;
  std::vector<uint32_t> start;  // kCells^2 + 1 offsets
  void build(std::vector<Photon>& raw) {
    start.assign(kCells * kCells + 1, 0);
    std::vector<int> cell(raw.size());
    for (size_t k = 0; k < raw.size(); ++k) {
      const int cx = int(std::floor(raw[k].x * kCells)), cy = int(std::floor(raw[k].y * kCells));
      cell[k] = (cx < 0 || cy < 0 || cx >= kCells || cy >= kCells) ? -1 : cy * kCells + cx;
      if (cell[k] >= 0) ++start[cell[k] + 1];
    }
    for (int c = 0; c < kCells * kCells; ++c) start[c + 1] += start[c];
    photons.resize(start.back());
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t k = 0; k < raw.size(); ++k)
      if (cell[k] >= 0) photons[fill[cell[k]]++] = raw[k];
  }
};

// Mean |error| after 16, 64 and 256 passes of one synthetic run.
using CheckErrors = std::array<double, 3>;

CheckErrors synthetic_coverage(bool adaptive_radius) {
  const int kTrials = 40;
  const int kSide = 16;  // 16 x 16 query points in [0.15, 0.85]^2 (kernels never reach the edge)
  const int kPasses = 256;
  const double kMe = 4000.0;
  const double kR0 = 0.05;
  EstimatorParams params;
  params.alpha = 0.7;
  params.photons_per_pass = kMe;
  params.adaptive_radius = adaptive_radius;

  std::vector<std::array<double, 2>> points;
  for (int a = 0; a < kSide; ++a)
    for (int b = 0; b < kSide; ++b)
      points.push_back({0.15 + 0.7 * a / (kSide - 1), 0.15 + 0.7 * b / (kSide - 1)});

  const std::array<int, 3> checks = {16, 64, 256};
  const std::array<double, 2> confidences = {0.9, 0.5};
  // covered[check][confidence], plus diagnostics: mean bound, mean |error|, mean |bias| / |err|.
  long covered[3][2] = {}, total[3] = {}, unknown[3] = {};
  // Diagnostics by region: 0 = on the bump (within 1.5 sigma of its centre, strong curvature),
  // 1 = on its flank (1.5 to 3 sigma, curvature changes sign), 2 = flat (beyond 3 sigma).
  long reg_cov[3][3][2] = {}, reg_n[3][3] = {};
  auto region = [](double x, double y) {
    const double d = std::hypot(x - 0.5, y - 0.5) / kSigma;
    return d < 1.5 ? 0 : (d < 3.0 ? 1 : 2);
  };
  double sum_bound[3][2] = {}, sum_err[3] = {};
  long noise_only[3][2] = {};  // diagnostic: coverage of t sqrt(V) alone, without |B|

  std::vector<Photon> raw(static_cast<size_t>(kMe));
  PassPhotons pp;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::vector<PointState> states(points.size());
    for (PointState& s : states) s.r2 = kR0 * kR0;
    int next_check = 0;
    for (int pass = 1; pass <= kPasses; ++pass) {
      Rng rng(2024, uint64_t(pass), uint64_t(trial), Stream::Test);
      for (Photon& p : raw) {
        if (rng.next_double() < 0.5) {
          p = {rng.next_double(), rng.next_double()};
        } else {
          // Box-Muller; 1 - u avoids log(0).
          const double u1 = 1.0 - rng.next_double(), u2 = rng.next_double();
          const double r = kSigma * std::sqrt(-2.0 * std::log(u1));
          p = {0.5 + r * std::cos(2.0 * kPi_ * u2), 0.5 + r * std::sin(2.0 * kPi_ * u2)};
        }
      }
      pp.build(raw);
      for (size_t q = 0; q < points.size(); ++q) {
        PointState& s = states[q];
        const double px = points[q][0], py = points[q][1];
        const double r2 = s.r2;
        PassSample g;
        const int cx = int(px * PassPhotons::kCells), cy = int(py * PassPhotons::kCells);
        for (int yy = cy - 1; yy <= cy + 1; ++yy) {
          for (int xx = cx - 1; xx <= cx + 1; ++xx) {
            if (xx < 0 || yy < 0 || xx >= PassPhotons::kCells || yy >= PassPhotons::kCells)
              continue;
            const int c = yy * PassPhotons::kCells + xx;
            for (uint32_t k = pp.start[c]; k < pp.start[c + 1]; ++k) {
              const double dx = pp.photons[k].x - px, dy = pp.photons[k].y - py;
              const double d2 = dx * dx + dy * dy;
              if (d2 >= r2) continue;
              const double t = std::sqrt(d2 / r2);
              g.phi += dvec3(kernel::weight(t));  // f = 1, photon power 1
              g.phi_lap_r2 += dvec3(kernel::laplacian_weight_r2(t));
              ++g.count;
            }
          }
        }
        accumulate_pass(s, g, params, uint64_t(pass));
      }
      if (next_check < 3 && pass == checks[next_check]) {
        // The bound the renderer reports (film.cpp): the quantile of |B + noise|.
        const BoundQuantile quantiles[2] = {BoundQuantile(double(pass - 1), confidences[0]),
                                            BoundQuantile(double(pass - 1), confidences[1])};
        for (size_t q = 0; q < points.size(); ++q) {
          const PointEstimate e = estimate(states[q], uint64_t(pass), kMe);
          ++total[next_check];
          if (!e.known) {
            ++unknown[next_check];
            continue;
          }
          const double err = std::fabs(e.radiance.x - density(points[q][0], points[q][1]));
          sum_err[next_check] += err;
          const int reg = region(points[q][0], points[q][1]);
          ++reg_n[next_check][reg];
          for (int ci = 0; ci < 2; ++ci) {
            const BoundQuantile& quantile = quantiles[ci];
            const double sd = std::sqrt(e.variance.x);
            const double bound = quantile(e.bias.x, sd);
            sum_bound[next_check][ci] += bound;
            if (err <= quantile.two_sided_t() * sd) ++noise_only[next_check][ci];
            if (err <= bound) {
              ++covered[next_check][ci];
              ++reg_cov[next_check][reg][ci];
            }
          }
        }
        ++next_check;
      }
    }
  }

  // Criterion (ESTIMATOR.md section 9: "near 0.9 and never far below it"): coverage at or above
  // nominal minus 5 percentage points. With 40 x 256 = 10240 (point, trial) pairs the binomial
  // standard error of a fraction near 0.9 is 0.003 (0.005 near 0.5), so 5 points is > 10 standard
  // errors even allowing for correlation between neighbouring points of one trial: a failure
  // means the bound is too narrow, not bad luck.
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(unknown[k], 0) << "after " << checks[k] << " passes";
    const long n = total[k] - unknown[k];
    for (int ci = 0; ci < 2; ++ci) {
      const double cov = double(covered[k][ci]) / double(n);
      std::printf(
          "passes %3d confidence %.2f: coverage %.4f (%ld / %ld), mean bound %.5g, "
          "mean |error| %.5g, bound/error %.3f\n",
          checks[k], confidences[ci], cov, covered[k][ci], n, sum_bound[k][ci] / n, sum_err[k] / n,
          sum_bound[k][ci] / sum_err[k]);
      std::printf("    noise-only interval (no |B|): %.4f\n",
                  double(noise_only[k][ci]) / double(n));
      std::printf("    by region (bump / flank / flat):");
      for (int r = 0; r < 3; ++r)
        std::printf(" %.4f (n=%ld)", double(reg_cov[k][r][ci]) / double(std::max(1L, reg_n[k][r])),
                    reg_n[k][r]);
      std::printf("\n");
      EXPECT_GE(cov, confidences[ci] - 0.05)
          << "coverage after " << checks[k] << " passes at confidence " << confidences[ci];
    }
  }
  CheckErrors errors{};
  for (int k = 0; k < 3; ++k) errors[k] = sum_err[k] / double(std::max(1L, total[k] - unknown[k]));
  return errors;
}

// ESTIMATOR.md section 13: with each point's radius chosen by its own error model the bound
// still covers (a radius fixed before each pass's photons keeps sections 3 and 4 whole). This
// density is noise-dominated everywhere (bound / error 2.5 at 90%, as for pure noise), where the
// schedule's radius is already at or below the optimum and the adaptive rule must leave it
// alone: its error may not exceed the schedule's by more than issue 39's 5%. Both runs draw the
// same photons (the Rng is keyed by pass and trial), so the comparison is paired. Measured with
// the 3-sd slope threshold: ratios printed below; with no threshold (1 sd) they were 1.05-1.11.
TEST(SlowCoverage, SyntheticDensityBoundsCoverWithAndWithoutAdaptiveRadius) {
  const CheckErrors fixed = synthetic_coverage(false);
  const CheckErrors adaptive = synthetic_coverage(true);
  for (int k = 0; k < 3; ++k) {
    std::printf("check %d: mean |error| PPM schedule %.5g, adaptive %.5g (ratio %.3f)\n", k,
                fixed[k], adaptive[k], adaptive[k] / fixed[k]);
    EXPECT_LT(adaptive[k], 1.05 * fixed[k]);
  }
}

// glossy_plane.gltf (glTF's metallic-roughness BRDF, roughness 0.4, under a point light; exact
// answer analytic::glossy_plane), all light from photons, 64 x 64 pixels: coverage at 50% and
// 90% confidence after 16, 64 and 256 passes, with PPM's fixed points (the glossy side table)
// and SPPM's per-pass visible points (their block scratch; pixel averages against the exact
// pixel average). The criterion is issue 17's: within 3 points of nominal either way (measured
// 0.49-0.52 at 50% and 0.895-0.906 at 90%); the 12288 pixel-channels of one render share
// photons between neighbours, so 3 points are about 1.2 binomial standard errors of 400
// independent pixels at 50%, and a fixed seed makes the check deterministic.
TEST(SlowCoverage, GlossyVisiblePointsBoundsCoverNominalConfidence) {
  for (Method method : {Method::PPM, Method::SPPM}) {
    RenderOptions o = test::quick_options("glossy_plane.gltf", 64, 256);
    o.method = method;
    o.direct = DirectMode::Photons;
    const auto rows = analytic::coverage_run("glossy", o, {16, 64, 256}, {0.5, 0.9});
    for (const auto& r : rows) {
      std::printf(
          "glossy %s: %3llu passes, %.0f%%: coverage %.3f, mean error %.5f, mean bound "
          "%.5f, bound / error %.2f\n",
          method == Method::PPM ? "ppm" : "sppm", (unsigned long long)r.passes,
          100.0 * r.confidence, r.accuracy.coverage, r.accuracy.mean_abs_error,
          r.accuracy.mean_bound, r.accuracy.mean_bound / r.accuracy.mean_abs_error);
      EXPECT_NEAR(r.accuracy.coverage, r.confidence, 0.03)
          << "after " << r.passes << " passes at " << r.confidence;
      EXPECT_GT(r.accuracy.samples, 4000u);
    }
  }
}

}  // namespace
}  // namespace pb
