#include "photonbound/estimator.h"

#include "photonbound/kernel.h"

#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>

#include <algorithm>
#include <limits>

namespace pb {

void accumulate_pass(PointState& s, const PassGather& g, const EstimatorParams& params,
                     uint64_t pass) {
  const double r2_pass = s.r2;  // R_j: the radius every deposit of this pass was made with
  const double inv_area = 1.0 / (kPiD * r2_pass * params.photons_per_pass);

  // Per-pass sample X_j = D_j + phi_j / (pi R_j^2 M_e) (section 4), streamed into bivariate
  // Welford moments with R_j^2: C_xy += (x - mean_x_old)(y - mean_y_new).
  const dvec3 x = g.direct + g.phi * inv_area;
  const double inv_i = 1.0 / double(pass);
  const dvec3 dx = x - s.mean_x;
  const double dr = r2_pass - s.mean_r2;
  s.mean_x += dx * inv_i;
  s.mean_r2 += dr * inv_i;
  s.c_xx += dx * (x - s.mean_x);
  s.c_xr += dx * (r2_pass - s.mean_r2);
  s.c_rr += dr * (r2_pass - s.mean_r2);
  s.direct_sum += g.direct;
  s.photons += g.count;

  // PPM update (section 3, HOJ08): only photons that could contribute shrink the radius.
  const double m = double(g.count);
  double shrink = 1.0;
  if (s.n + m > 0.0) {
    shrink = (s.n + params.alpha * m) / (s.n + m);
    s.n += params.alpha * m;
  }
  // At the radius floor the shrink actually applied is smaller; tau must follow R^2 exactly or
  // tau / (pi R^2 i M_e) stops being the mean of the per-pass estimates.
  s.r2 = std::max(r2_pass * shrink, params.min_r2);
  const double applied = s.r2 / r2_pass;
  s.tau = (s.tau + g.phi) * applied;
  s.tau_lap = (s.tau_lap + g.phi_lap_r2 / r2_pass) * applied;  // w_lap carries 1 / R_j^2
}

dvec3 photon_radiance(const PointState& s, uint64_t passes, double photons_per_pass) {
  return s.tau / (kPiD * s.r2 * double(passes) * photons_per_pass);
}

PointEstimate estimate(const PointState& s, uint64_t passes, double photons_per_pass) {
  PointEstimate e;
  if (passes == 0) return e;
  const double i = double(passes);
  e.radiance = s.direct_sum / i + photon_radiance(s, passes, photons_per_pass);

  // Bias (section 3): a = 0.5 k2 Lap_i with Lap_i = tauLap / (pi R^2 i M_e); B = a mean_j(R_j^2).
  const dvec3 lap = s.tau_lap / (kPiD * s.r2 * i * photons_per_pass);
  const dvec3 a = 0.5 * kernel::kSecondMoment * lap;
  e.bias = a * s.mean_r2;

  e.known = passes >= 2 && s.photons > 0;
  if (passes >= 2) {
    // Retroactive correction X'_j = X_j - a R_j^2 with the newest a (section 4).
    const dvec3 s2 = glm::max(dvec3(0.0), (s.c_xx - 2.0 * a * s.c_xr + a * a * s.c_rr) / (i - 1.0));
    e.variance = s2 / i;
  }
  return e;
}

double student_t_quantile(double nu, double p) {
  // Beyond 1e7 degrees of freedom the t and normal quantiles agree to ~1e-8 and Boost's t
  // evaluation loses accuracy; use the normal there.
  if (nu > 1e7) return boost::math::quantile(boost::math::normal_distribution<double>(), p);
  return boost::math::quantile(boost::math::students_t_distribution<double>(nu), p);
}

}  // namespace pb
