#include "estimator/estimator.h"

#include "estimator/kernel.h"

#include <algorithm>
#include <limits>

namespace pb {

namespace {

// a = 0.5 k2 Lap_i with Lap_i = tauLap / (pi R^2 i M_e) (section 3), and the variance S^2 of
// the samples corrected with it, X'_j = X_j - a R_j^2 (section 4; needs i >= 2).
struct SlopeAndSpread {
  dvec3 a, s2;
};
SlopeAndSpread slope_and_spread(const PointState& s, double i, double photons_per_pass) {
  SlopeAndSpread r;
  const dvec3 lap = s.tau_lap / (kPiD * s.r2 * i * photons_per_pass);
  r.a = 0.5 * kernel::kSecondMoment * lap;
  r.s2 = glm::max(dvec3(0.0),
                  (s.c_xx - 2.0 * r.a * s.c_xr + r.a * r.a * s.c_rr) / std::max(i - 1.0, 1.0));
  return r;
}

double cost_factor(const PointState& s, uint64_t passes, double photons_per_pass,
                   const SlopeAndSpread& spread);
double preferred(const PointState& s, uint64_t passes, const SlopeAndSpread& spread);

}  // namespace

double relative_error(const PointState& s, uint64_t passes, double photons_per_pass) {
  const double level = s.mean_x.x + s.mean_x.y + s.mean_x.z;
  if (passes < 2 || !(level > 0.0) || !(s.r2 > 0.0)) return 1.0;
  const double i = double(passes);
  const auto [a, s2] = slope_and_spread(s, i, photons_per_pass);
  const dvec3 b = a * s.mean_r2;
  const double e2 = (s2.x + s2.y + s2.z) / i + glm::dot(b, b);
  const double r = std::sqrt(3.0 * e2) / level;  // sqrt(mean e_c^2) / mean L_c
  return std::isfinite(r) ? std::min(r, 1.0) : 1.0;
}

PassSpread pass_spread(const PointState& s, uint64_t passes, double photons_per_pass) {
  if (passes < 2 || !(s.r2 > 0.0)) return {};
  const SlopeAndSpread r = slope_and_spread(s, double(passes), photons_per_pass);
  return {r.s2, r.a * s.mean_r2};
}

double ppm_radius_update(double& n, double& r2, double m, double alpha, double min_r2) {
  const double r2_pass = r2;
  double shrink = 1.0;
  if (n + m > 0.0) {
    shrink = (n + alpha * m) / (n + m);
    n += alpha * m;
  }
  // At the radius floor the shrink actually applied is smaller; tau must follow R^2 exactly or
  // tau / (pi R^2 i M_e) stops being the mean of the per-pass estimates.
  r2 = std::max(r2_pass * shrink, min_r2);
  return r2 / r2_pass;
}

CorrectedSums corrected_sums(const PassSums& g, const DiscMoments& disc, double r2_pass) {
  // Where the disc reaches past the end of the surface (section 11): the kernel sum is divided
  // by the kernel's mass c on the surface; the Laplacian sample loses the truncated Laplacian
  // kernel's response l0 L / R^2 to the constant part and is rescaled by its second moment; and
  // the bias, (R^2 / 4c) tr(M2) Lap for an isotropic Hessian, is 0.5 k2 Lap R_b^2 with the
  // effective R_b^2 = R^2 tr(M2) / (2 k2 c), which the moments stream in place of R_j^2. The
  // whole disc (every interior point) takes the plain path, bit for bit.
  CorrectedSums r{g.phi, g.phi_lap_r2 / r2_pass, r2_pass};  // w_lap carries 1 / R_j^2
  if (!disc.full) {
    const double c = std::max(disc.mass, kMinKernelMass);
    r.phi = g.phi / c;
    // A disc cut to a sliver leaves the Laplacian kernel little sensitivity to curvature:
    // its second moment is kept at least a sixteenth of the whole disc's.
    r.lap = (r.lap - (disc.lap_mass / r2_pass) * r.phi) * (4.0 / std::max(disc.lap_second, 0.25));
    r.r2_bias = r2_pass * disc.second / (2.0 * kernel::kSecondMoment * c);
  }
  return r;
}

double scale_c2_unit(const PointState& s) {
  const double m = std::fabs(s.mean_x.x) + std::fabs(s.mean_x.y) + std::fabs(s.mean_x.z);
  return m > 0.0 && std::isfinite(m * m) && m * m > 0.0 ? m * m : 1.0;
}

void accumulate_pass(PointState& s, const PassSums& g, const OwnerValues& o,
                     const EstimatorParams& params, uint64_t pass) {
  const double r2_pass = s.r2;  // R_j: the radius every deposit of this pass was made with
  const double inv_area = 1.0 / (kPiD * r2_pass * params.photons_per_pass);

  const auto [phi, lap, r2_bias] = corrected_sums(g, o.disc, r2_pass);

  // Per-pass sample X_j = D_j + phi_j / (pi R_j^2 M_e) (section 4), streamed into bivariate
  // Welford moments with R_j^2: C_xy += (x - mean_x_old)(y - mean_y_new).
  const dvec3 x = o.direct + phi * inv_area;
  // Section 11c: the kernel at R_j / 2 over the same photons. Under E[X(R)] = L + a R^2 the
  // difference of the two scales is 0.75 a R_j^2 (the direct part cancels), so Y_j below has
  // mean 0; the R^4 terms the model leaves out give it a mean, with a noise of its own that the
  // samples measure. Where the disc is cut by an edge the half disc's kernel mass would be
  // needed too: those passes are left out.
  const double scale_unit_before = scale_c2_unit(s);
  const double inv_i = 1.0 / double(pass);
  const dvec3 dx = x - s.mean_x;
  const double dr = r2_bias - s.mean_r2;
  s.mean_x += dx * inv_i;
  if (o.disc.full) {
    const dvec3 y3 =
        (g.phi - 4.0 * g.phi_half - 0.375 * kernel::kSecondMoment * g.phi_lap_r2) * inv_area;
    const double y = y3.x + y3.y + y3.z;
    ++s.scale_passes;
    const double dy = y - s.scale_mean;
    s.scale_mean += dy / double(s.scale_passes);
    const double c2 = double(s.scale_c2) * scale_unit_before + dy * (y - s.scale_mean);
    s.scale_c2 = float(c2 / scale_c2_unit(s));
  }
  s.mean_r2 += dr * inv_i;
  s.c_xx += dx * (x - s.mean_x);
  s.c_xr += dx * (r2_bias - s.mean_r2);
  s.c_rr += dr * (r2_bias - s.mean_r2);
  s.photons += uint64_t(o.first_count < 0.0 ? g.count : o.first_count);
  const double sign = (pass & 1u) ? 1.0 : -1.0;
  s.alt_x += sign * x;
  s.alt_r2 += sign * r2_bias;

  // PPM update (section 3, HOJ08): only photons that could contribute shrink the radius. With
  // --adaptive radius the update is the slow schedule's (section 13), the most a radius may keep.
  const double alpha = params.adaptive_radius ? adaptive_cap_alpha(params.alpha) : params.alpha;
  const double applied = ppm_radius_update(s.n, s.r2, g.count, alpha, params.min_r2);
  s.tau = (s.tau + phi) * applied;
  s.tau_lap = (s.tau_lap + lap) * applied;

  // Section 13: the radius of the next pass is a function of the passes so far, fixed before
  // its photons, so section 3's identity and section 4's samples hold as for the PPM schedule.
  // It may only be smaller than the slow schedule's (so it shrinks at least at that rate); the
  // cost rule takes it down to --alpha's schedule where the photons are not the noise, and the
  // bias rule below that by at most kAdaptiveMaxShrink per pass; N, tau and tauLap follow R^2
  // as in the PPM update.
  if (params.adaptive_radius) {
    const double ip = double(pass);
    const double floor_r2 = r2_pass * params.alpha * ip / (params.alpha * (ip - 1.0) + 1.0);
    const SlopeAndSpread spread = slope_and_spread(s, ip, params.photons_per_pass);
    const double cost = r2_pass * cost_factor(s, pass, params.photons_per_pass, spread);
    const double base = std::min(s.r2, std::max(floor_r2, cost));
    const double want = preferred(s, pass, spread);
    const double r2 =
        std::max(params.min_r2, std::max(base * kAdaptiveMaxShrink, std::min(base, want)));
    if (r2 < s.r2) {
      const double f = r2 / s.r2;
      s.r2 = r2;
      s.n *= f;
      s.tau *= f;
      s.tau_lap *= f;
    }
  }
}

namespace {

// cost_r2_factor and preferred_r2 with the point's slope and spread taken once (accumulate_pass
// asks both every pass; slope_and_spread was 1.2% of a pass computed twice).
double cost_factor(const PointState& s, uint64_t passes, double photons_per_pass,
                   const SlopeAndSpread& spread) {
  if (passes < 2 || s.photons < kMinPhotonsForBound || !(s.r2 > 0.0) || !(s.mean_r2 > 0.0))
    return 1.0;
  const double i = double(passes);
  // M: the photons a pass brings at the current radius (they scale with the disc's area; mean_r2
  // streams the edge-corrected R_b^2 of section 11, R_j^2 itself on a whole disc).
  const double m = double(s.photons) / i * (s.r2 / s.mean_r2);
  const dvec3 p = photon_radiance(s, passes, photons_per_pass);
  // The photon part's variance for M Poisson arrivals of equal power: P^2 E[w^2] / M with
  // E[w^2] = kWeightSecondMoment for arrivals uniform over the disc. Unequal powers and
  // densities only add to it, so this is the photons' least share and the rest's most.
  const double v_photons = glm::dot(p, p) * kernel::kWeightSecondMoment / m;
  const dvec3 s2 = spread.s2;
  const double v_rest = (s2.x + s2.y + s2.z) - v_photons;
  if (!(v_rest > 0.0) || !(v_photons > 0.0)) return 1.0;
  // A pass costs c0 + c1 M at a point, and N passes reach the variance (v_rest + v_photons) /
  // N with v_photons ~ 1 / M: the time to an error, (v_rest + k / M)(c0 + c1 M) with k = v_photons
  // M, is least at M*^2 = k c0 / (v_rest c1), so R^2 should scale by M* / M.
  const double f = std::sqrt(v_photons * kAdaptiveCostPhotons / (v_rest * m));
  return std::isfinite(f) ? std::min(f, 1.0) : 1.0;
}

double preferred(const PointState& s, uint64_t passes, const SlopeAndSpread& spread) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  if (passes < kAdaptiveMinPasses || s.photons < kMinPhotonsForBound || !(s.r2 > 0.0) ||
      !(s.mean_r2 > 0.0))
    return kNone;
  const double i = double(passes);
  const auto& [a, s2] = spread;
  double a2 = 0.0, v = 0.0;
  for (int c = 0; c < 3; ++c) {
    // Var(a) <= V_B / mean(R^2)^2 (section 6b). E[a_hat^2] = a^2 + Var(a), but subtracting
    // Var(a) once is not enough: the radius may only shrink, so a noisy slope's upward swings
    // act and its downward ones do not, and where the noise dominates they shrank radii for
    // nothing (the indirect room 7% worse, the synthetic bump 5-11%). So the slopes count only
    // beyond kAdaptiveSlopeZ^2 Var(a), a 3-sd slope summed over the channels (section 13).
    a2 += a[c] * a[c] -
          kAdaptiveSlopeZ * kAdaptiveSlopeZ * kBiasNoiseRatio * s2[c] / (i * s.r2 * s.r2);
    // The photon part of a pass's variance falls as 1 / R^2, so Var(X_j) ~ v / R_j^2 and S^2
    // averages v mean_j(1 / R_j^2) >= v / mean_j(R_j^2). Taking v = S^2 mean_j(R_j^2) and
    // counting all of S^2 as photon noise (next-event and jitter noise do not fall with a
    // larger radius) both overstate v, which errs toward the larger radius: the PPM schedule.
    v += s2[c] * s.mean_r2;
  }
  if (!(a2 > 0.0) || !(v > 0.0) || !std::isfinite(a2 / v)) return kNone;
  // MSE(R^2) = A^2 R^4 + v / (N R^2) for N passes at one radius; its minimum is at
  // R^6 = v / (2 A^2 N), taken with N = i + 1, the passes once the next one is in.
  return std::cbrt(v / (2.0 * a2 * (i + 1.0)));
}

}  // namespace

double cost_r2_factor(const PointState& s, uint64_t passes, double photons_per_pass) {
  return cost_factor(s, passes, photons_per_pass,
                     slope_and_spread(s, double(passes), photons_per_pass));
}

double preferred_r2(const PointState& s, uint64_t passes, double photons_per_pass) {
  return preferred(s, passes, slope_and_spread(s, double(passes), photons_per_pass));
}

dvec3 photon_radiance(const PointState& s, uint64_t passes, double photons_per_pass) {
  return s.tau / (kPiD * s.r2 * double(passes) * photons_per_pass);
}

namespace {

// Section 11c's measured fourth-order term in the bias (section 6c): E[Y_j] = (15/16) c4 R_j^4,
// so (16/15) mean(Y) estimates the part of the estimate's bias that a R^2 leaves out, with the
// variance (16/15)^2 s_Y^2 / n. Y is summed over the channels; each channel takes the photon
// part's share of it (the two kernels see the same photons, whose colour is tau's).
void add_fourth_order(const PointState& s, double n, PointEstimate& e) {
  constexpr double kScale = 16.0 / 15.0;
  const double b4 = kScale * s.scale_mean;
  const double v4 = kScale * kScale * scale_spread(s) / ((n - 1.0) * n);
  if (!std::isfinite(b4) || !std::isfinite(v4)) return;
  const dvec3 tau = glm::abs(s.tau);
  const double total = tau.x + tau.y + tau.z;
  for (int c = 0; c < 3; ++c) {
    const double share = total > 0.0 ? tau[c] / total : 1.0 / 3.0;
    e.fourth[c] = b4 * share;
    e.fourth_variance[c] = v4 * share * share;
  }
}

}  // namespace

PointEstimate estimate(const PointState& s, uint64_t passes, double photons_per_pass) {
  PointEstimate e;
  if (passes == 0) return e;
  const double i = double(passes);
  // L_i = mean_j X_j. Equal to D-bar + tau / (pi R^2 i M_e) by the key identity, but read from
  // the streaming mean, so the state keeps no separate sum of the D_j.
  e.radiance = s.mean_x;

  // Bias (section 3): B = a mean_j(R_j^2); S^2 with the retroactive correction (section 4).
  const auto [a, s2] = slope_and_spread(s, i, photons_per_pass);
  e.bias = a * s.mean_r2;

  e.known = passes >= 2 && s.photons >= kMinPhotonsForBound;
  if (passes >= 2) {
    e.variance = s2 / i;  // the retroactive correction X'_j = X_j - a R_j^2 with the newest a
    // sum_j s_j (X'_j - mean X') / i with s_j = +1 on odd passes and -1 on even ones: the
    // corrected samples' deviations with alternating signs. For independent samples its variance
    // is (i - sbar^2 i) Var X / i^2 (sbar = sum s_j / i, 1 / i or 0), that of the mean's noise to
    // within 1 / i^2, and its covariance with another point's replica is the noises' covariance
    // to the same order; a slow drift of the mean cancels pairwise.
    const double odd = (passes & 1u) ? 1.0 : 0.0;
    e.replica = (s.alt_x - a * s.alt_r2 - odd * (s.mean_x - a * s.mean_r2)) / i;
    // Var(B) from the variance of the mean by the kernels' noise ratio; the radius shrank over
    // the passes, and the Laplacian's noise grows as 1/R^3 against the estimate's 1/R, so the
    // ratio is scaled by (mean R^2 / R^2)^2 (section 6b). An upper estimate where next-event
    // noise is part of the variance.
    const double shrink = s.mean_r2 / s.r2;
    e.bias_variance = kBiasNoiseRatio * shrink * shrink * e.variance;
    // Section 11b: under the model E[X_j] = L + a R_j^2, the least-squares slope of the samples
    // on R_j^2 estimates the same a as the Laplacian; a radius far above the scale on which the
    // radiance varies bends E[X] in R^2, and the two part. The regression slope's variance is
    // the residual variance over C_RR; the Laplacian's is Var(B) / mean(R^2)^2.
    if (passes >= 3 && s.c_rr > 0.0 && s.mean_r2 > 0.0 && s.photons >= kMinPhotonsForBound)
      for (int c = 0; c < 3; ++c) {
        const double b = s.c_xr[c] / s.c_rr;
        const double resid = std::max(0.0, s.c_xx[c] - s.c_xr[c] * b) / (i - 2.0);
        const double var = resid / s.c_rr + e.bias_variance[c] / (s.mean_r2 * s.mean_r2);
        // Rescaled like scale_z below: with i - 2 degrees of freedom a plain |z| > 3 fires for
        // 9.5% of states after 4 passes under the model (6% of state-channels measured).
        if (var > 0.0 && std::isfinite(var))
          e.slope_z[c] = (b - a[c]) / std::sqrt(var) * (kSlopeZ / t_at_three_sd(passes - 2));
      }
  }
  if (s.scale_passes >= 3 && s.scale_c2 > 0.0f && s.photons >= kMinPhotonsForBound) {
    const double n = double(s.scale_passes);
    const double t = s.scale_mean / std::sqrt(scale_spread(s) / ((n - 1.0) * n));
    e.scale_z = t * (kSlopeZ / t_at_three_sd(s.scale_passes - 1));
    if (passes >= 2) add_fourth_order(s, n, e);
  }
  return e;
}

}  // namespace pb
