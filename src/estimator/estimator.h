// Per-measurement-point progressive estimator: the PPM radius update (Hachisuka, Ogaki, Jensen
// 2008) plus the statistics for error bounds (Hachisuka, Jarosz, Jensen 2010), exactly as
// ESTIMATOR.md sections 3 and 4 specify. Depends on math only: tested without a scene.
#pragma once

#include "estimator/disc_moments.h"
#include "util/math.h"

#include <algorithm>
#include <cstdint>

namespace pb {

// What one pass's photons add at one point (ESTIMATOR.md section 3, "During pass j"): sums
// over photons, so the sums over two disjoint sets of a pass's photons add up to the sums over
// their union. A pass split across threads or machines reduces arrays of these (ten doubles,
// nothing else) before the fold.
struct PassSums {
  dvec3 phi{0.0};         // sum of w(t) f Phi
  dvec3 phi_lap_r2{0.0};  // sum of w_lap(t) R_j^2 f Phi (divided by R_j^2 in the update)
  dvec3 phi_half{0.0};    // sum of w(2t) f Phi over t < 1/2: the same kernel at radius R_j / 2
  double count = 0.0;     // M_j: photons that landed within R_j on the point's side (exact)
};
static_assert(sizeof(PassSums) == 10 * sizeof(double), "a reduction moves plain doubles");

// What the owner of a point computes once per pass, whatever the photons: these are not summed
// over photon subsets, and a split pass computes them once.
struct OwnerValues {
  // D_j: the light the camera path saw (SPPM: emission along it, followed lobes' light) plus
  // the point's next-event estimate (0 with --direct photons).
  dvec3 direct{0.0};
  DiscMoments disc;  // the kernel's moments over the reachable part of the disc (section 11)
  // Several camera paths whose mean the pass sample is (--adaptive paths, section 15): the
  // PassSums' count is their mean count (for the radius update), and the state's photon total
  // adds the first path's count alone. A pixel's paths share the pass's photons: one photon
  // near the pixel is gathered by all of them, so their sum would count it K times, and the
  // sparse-photon bound and kMinPhotonsForBound take counts of independent arrivals. Negative:
  // one path, whose count is the PassSums'.
  double first_count = -1.0;
};

// Everything the estimator keeps for one point, in double (ESTIMATOR.md section 8).
struct PointState {
  double n = 0.0;   // N: alpha-thinned photon count
  double r2 = 0.0;  // current squared radius, used by the next pass
  dvec3 tau{0.0};
  dvec3 tau_lap{0.0};
  // No sum of the direct parts D_j: the radiance is mean_x, and the direct part alone, when
  // wanted, is mean_x - photon_radiance() (the key identity of section 3).
  uint64_t photons = 0;  // all photons ever gathered (sum of M_j)
  // Bivariate streaming moments of the per-pass samples (X_j, R_j^2), ESTIMATOR.md section 4.
  dvec3 mean_x{0.0};
  double mean_r2 = 0.0;
  dvec3 c_xx{0.0};
  dvec3 c_xr{0.0};
  double c_rr = 0.0;
  // Alternating sums sum_j s_j X_j and sum_j s_j R_j^2 (s_j = +1 on odd passes, -1 on even
  // ones): with the means, a replica of the estimate's noise
  // with the same covariance between points, free of the drift (ESTIMATOR.md section 7).
  dvec3 alt_x{0.0};
  double alt_r2 = 0.0;
  // The two-scale check (ESTIMATOR.md section 11c): Welford moments of
  // Y_j = X_j(R_j) - X_j(R_j / 2) - 0.75 R_j^2 a_j summed over the channels, zero in expectation
  // while the bias is a R^2; only passes whose whole disc lies on the surface are counted.
  double scale_mean = 0.0;
  // Its spread, in units of scale_c2_unit() (the square of mean_x's channel sum): a float keeps
  // the state at 208 bytes, and in those units it neither overflows nor underflows however
  // bright the light (the spread is also the variance of the fourth-order bias, section 6c,
  // which must scale with the light as the other moments do). scale_spread() is the raw M2.
  float scale_c2 = 0.0f;
  uint32_t scale_passes = 0;
};
static_assert(sizeof(PointState) == 208, "the per-point memory budget counts on 208 bytes");

// The unit the two-scale spread is kept in, and the spread itself (sum_j (Y_j - mean Y)^2).
double scale_c2_unit(const PointState& s);
inline double scale_spread(const PointState& s) { return double(s.scale_c2) * scale_c2_unit(s); }

// The smallest kernel mass a boundary correction divides by: a point whose disc is almost all
// off its surface (the tip of a sliver) is not amplified beyond 1000x.
inline constexpr double kMinKernelMass = 1e-3;

// Below this kernel mass on the surface the disc is mostly beyond it (a radius far above the
// surface's size): the estimate is then an average over the whole surface, and no second-order
// model of the bias holds. Such a state's bound is unknown until the radius shrinks
// (ESTIMATOR.md section 11). A strip a hundredth of the radius wide still passes.
inline constexpr double kValidKernelMass = 1e-2;

struct EstimatorParams {
  double alpha = 0.7;             // PPM radius reduction, in (0, 1]
  double photons_per_pass = 1.0;  // M_e
  double min_r2 = 0.0;            // floor on R^2 (ESTIMATOR.md section 8)
  // --adaptive radius: each point's radius between the schedules of kAdaptiveSlowAlpha and
  // alpha, by the cost of its photons against its other noise, and below that where its bias
  // model prefers (ESTIMATOR.md section 13); never above the slow schedule's.
  bool adaptive_radius = false;
};

// Section 13's safeguards: no radius choice before this many passes (the slope and variance
// estimates need a few samples), and R^2 shrinks by at most this factor in one pass beyond the
// PPM update, so that one noisy Laplacian cannot collapse a radius (and its photon count).
inline constexpr uint64_t kAdaptiveMinPasses = 4;
inline constexpr double kAdaptiveMaxShrink = 0.5;
// A bias slope moves a radius only where it exceeds this many of its own sds (section 13).
inline constexpr double kAdaptiveSlopeZ = 3.0;
// The slowest schedule --adaptive radius keeps a radius on (section 13): R^2 ~ i^-0.11, so every
// radius shrinks at a guaranteed rate, where --alpha's 0.7 gives i^-0.43. Where the photons are
// the noise a larger radius is worth more than its bias; the cost rule brings a radius down to
// --alpha's schedule where they are not, and the bias rule below it.
inline constexpr double kAdaptiveSlowAlpha = 0.9;
inline double adaptive_cap_alpha(double alpha) { return std::max(alpha, kAdaptiveSlowAlpha); }
// A pass's work at a point beyond its photons (camera path, next-event sample, grid lookup,
// update), in gathered photons: about 0.55 us against 14 ns a photon at 512x512 (ESTIMATOR.md
// section 13 derives it from bench/README.md's pass figures).
inline constexpr double kAdaptiveCostPhotons = 40.0;

// The squared radius that minimises the predicted mean squared error of a point's estimate
// over the next passes (ESTIMATOR.md section 13): R^2 = (v / (2 A^2 (i + 1)))^(1/3), with
// A^2 the bias slopes' squares net of their own noise and v the per-pass variance times R^2,
// both summed over the channels. +inf where the model has nothing to say (too few passes or
// photons, no significant slope): the cost rule's band then decides alone.
double preferred_r2(const PointState& state, uint64_t passes, double photons_per_pass);

// The cost rule (section 13): the factor on a point's last squared radius that minimises the
// time to an error when a pass's photon part has the variance P^2 E[w^2] / M of M Poisson
// arrivals and the rest of its variance does not depend on the radius, for a pass that costs as
// much as kAdaptiveCostPhotons gathered photons beyond its photons. At most 1; 1 where the model
// has nothing to say (fewer than 2 passes or 5 photons, no variance beyond the photons').
double cost_r2_factor(const PointState& state, uint64_t passes, double photons_per_pass);

// A point's predicted error relative to its radiance, sqrt(mean_c(S_c^2 / i + B_c^2)) /
// mean_c L_c, at most 1; 1 where it cannot be formed (fewer than 2 passes, no radiance). The
// photon guide weighs what a photon brings to the point by it (ESTIMATOR.md section 14).
double relative_error(const PointState& state, uint64_t passes, double photons_per_pass);

// Per channel, 0 before 2 passes: S^2, the variance of one pass's sample X_j after the
// retroactive bias correction (section 4), and B = a mean_j(R_j^2) (section 3; estimate's bias
// without the fourth-order part). The camera-path allocation (section 15) splits the first and
// weighs the error paths cannot lower by the second.
struct PassSpread {
  dvec3 variance{0.0};
  dvec3 bias{0.0};
};
PassSpread pass_spread(const PointState& state, uint64_t passes, double photons_per_pass);

// The PPM radius update (HOJ08; ESTIMATOR.md section 3) for m photons that could contribute:
// R^2 *= (N + alpha m) / (N + m), N += alpha m, R^2 floored at min_r2. Returns the factor R^2
// actually changed by, which tau and tauLap must follow exactly.
double ppm_radius_update(double& n, double& r2, double m, double alpha, double min_r2);

// One pass's kernel sums at a point whose disc is `disc`, at the pass's R^2, corrected for the
// part of the disc beyond the surface (section 11): phi / c, the Laplacian sample (per R^2) and
// the effective R_b^2 the bias streams in place of R^2. A whole disc passes them through.
struct CorrectedSums {
  dvec3 phi{0.0};
  dvec3 lap{0.0};
  double r2_bias = 0.0;
};
CorrectedSums corrected_sums(const PassSums& sums, const DiscMoments& disc, double r2_pass);

// Folds pass number `pass` (1-based) into the state: its photons' sums and its owner's values.
// state.r2 must be the radius the pass used.
void accumulate_pass(PointState& state, const PassSums& sums, const OwnerValues& owner,
                     const EstimatorParams& params, uint64_t pass);

// The point's estimate after `passes` passes.
struct PointEstimate {
  dvec3 radiance{0.0};  // L_i = mean_j X_j (mean_x)
  dvec3 bias{0.0};      // B_i = 0.5 k2 Lap_i mean_j(R_j^2), signed
  dvec3 variance{0.0};  // S^2 / i: variance of the mean after the retroactive bias correction
  // Variance of the bias estimate B_i itself (section 6b): the Laplacian estimate is noisy.
  dvec3 bias_variance{0.0};
  // The bias's fourth-order part a R^2 leaves out, measured by the two scales (section 6c):
  // (16/15) mean(Y) in the photon part's colour, and the variance of that estimate. 0 before
  // section 11c's test can be formed. The film shrinks them by a prior of their own and adds
  // them to B and Var B (film.cpp, shrink_fourth).
  dvec3 fourth{0.0};
  dvec3 fourth_variance{0.0};
  // A replica of the noise of L_i - B_i: sum_j (-1)^j X'_j / i, of the same variance and the
  // same covariance with other points' replicas as the noise itself (section 7).
  dvec3 replica{0.0};
  // The second-order model's own check (section 11b): (b - a) / sd, b = C_XR / C_RR the
  // samples' regression slope on R^2, a the Laplacian's, sd of their difference, rescaled by
  // 3 / t_{i-2, Phi(3)} so that few passes' heavy tails do not fire the check; 0 where it
  // cannot be formed (fewer than 3 passes, a radius that never changed, a state without photons).
  dvec3 slope_z{0.0};
  // The two-scale check (section 11c): the t statistic of mean Y over its standard error,
  // rescaled so that kSlopeZ is its two-sided 0.27% point at its degrees of freedom (normal
  // sds for many passes); 0 where fewer than 3 passes had a whole disc or a state has too few
  // photons.
  double scale_z = 0.0;
  bool known = false;  // false until kMinPhotonsForBound photons and passes >= 2
};

PointEstimate estimate(const PointState& state, uint64_t passes, double photons_per_pass);

// The model check (ESTIMATOR.md section 11b): a state-channel whose two slopes differ by more
// than kSlopeZ of their sd disagrees; where more than kRefutedShare of an image's state-channels
// disagree, the second-order bias model is refuted for the image and every bound is unknown.
// Measured at the default radius on the shipped scenes, 0-2.5% of state-channels exceed 3 sd;
// where the radius is 10 or 30 times the default on the analytic plane, 39-100% from 64 passes on.
inline constexpr double kSlopeZ = 3.0;
inline constexpr double kRefutedShare = 0.2;
// The two-scale check (section 11c) is pooled the same way, over states: where more than
// kRefutedShare of the tested states have |scale_z| > kSlopeZ the model is refuted too. It has
// power from the first passes, where the slope on R^2 has almost none: on the analytic plane at
// 10x the default radius 60% of states disagree after 4 passes, at 30x all of them.

// Variance of the kernel estimate's bias estimate against that of the estimate itself, for
// photons of a Poisson process: (0.5 k2)^2 integral (lap kappa)^2 / integral kappa^2 over the
// unit disc (ESTIMATOR.md section 6b; the kernel test checks it by quadrature).
inline constexpr double kBiasNoiseRatio = 0.36025628811821314;

// Beyond ESTIMATOR.md section 7 (a point without photons is unknown): a t-interval over a
// handful of Poisson arrivals is too short on the high side. Measured with a photon once per
// 1,000 passes, points with 1-4 photons covered 69-80% at a nominal 90%, points with 5 or more
// 90-100% (tests/render/test_slow_extremes.cpp). Below this many photons the bound is unknown
// (+inf).
inline constexpr uint64_t kMinPhotonsForBound = 5;

// The photon part of L_i computed from the PPM accumulators, tau / (pi R^2 i M_e). Equal to the
// mean of the photon parts of X_j (ESTIMATOR.md section 3, key identity).
dvec3 photon_radiance(const PointState& state, uint64_t passes, double photons_per_pass);

// Points with few photons (ESTIMATOR.md section 12): after n photons over k passes in which the
// point could receive them, the expected photons per pass have the one-sided upper confidence
// limit lambda_u = chi2_{conf}(2n + 2) / (2k) (Garwood 1936; for n = 0 it is -ln(1 - conf) / k),
// and a photon adds at most `cap` to a pass sample, so the photon part's mean is at most
// lambda_u cap. 0 when k = 0 (no photon part).
double sparse_photon_bound(uint64_t photons, uint64_t passes, double cap, double confidence);

// The kernel's peak weight w(0) = 3.5: no photon weighs more in phi (ESTIMATOR.md section 2).
inline constexpr double kPeakWeight = 3.5;

// t_{nu, Phi(3)}: the Student-t point a t statistic with nu degrees of freedom exceeds as often
// as a normal one exceeds 3 sd (infinite for nu = 0; 3 to within 0.1% from nu = 1024 on).
double t_at_three_sd(uint64_t nu);

// Student-t quantile t_{nu, p} (Boost.Math), ESTIMATOR.md section 6. nu >= 1.
double student_t_quantile(double nu, double p);

// Error bound half-width for an estimate whose error is its estimated bias B plus noise of
// standard deviation s with nu degrees of freedom: the smallest q with
// P(|B + s T_nu| <= q) = confidence (ESTIMATOR.md section 4). HJJ10 adds the two-sided noise
// half-width to |B| instead: that sum covers the noise on the side away from B too, and is
// conservative by up to the difference between the two- and one-sided quantiles. q lies between |B|
// + s t_{nu,conf} and |B| + s t_{nu,(1+conf)/2}; it equals the latter when B = 0.
class BoundQuantile {
 public:
  BoundQuantile(double nu, double confidence);
  double operator()(double bias, double sd) const;
  double two_sided_t() const { return t_two_; }  // t_{nu, (1+conf)/2}: the noise half-width factor

 private:
  // (q/s - x) tabulated over u = x / (1 + x), x = |B| / s, u in [0, 1].
  static constexpr int kTable = 256;
  double table_[kTable + 1];
  double t_two_;
};

}  // namespace pb
