// The smooth quintic kernel of ESTIMATOR.md section 2. Its first two derivatives vanish at the
// rim, so its Laplacian exists everywhere and integrates to zero, which the bias estimate needs.
#pragma once

namespace pb::kernel {

// Per-axis second moment of the unit-mass kernel: integral of t_1^2 kappa over the disk.
inline constexpr double kSecondMoment = 5.0 / 48.0;

// Profile k(t) = 1 - 10 t^3 + 15 t^4 - 6 t^5 for t < 1, 0 beyond.
inline double profile(double t) {
  if (t >= 1.0) return 0.0;
  const double t3 = t * t * t;
  return 1.0 + t3 * (-10.0 + t * (15.0 - 6.0 * t));
}

// Unit-mass 2D kernel kappa(t) = 7/(2 pi) k(t).
double unit_mass(double t);
// Laplacian of kappa with respect to position (radius 1): 105/pi t(1-t)(5t-3).
double unit_laplacian(double t);

// Photon weight normalised like a box kernel: w(t) = pi kappa(t) = 3.5 k(t).
inline double weight(double t) { return 3.5 * profile(t); }

// Laplacian photon weight without its 1/R^2: w_lap(t) R^2 = 105 t (1-t)(5t-3). The caller divides
// by the R^2 of the pass in double (ESTIMATOR.md section 8).
inline double laplacian_weight_r2(double t) {
  if (t >= 1.0) return 0.0;
  return 105.0 * t * (1.0 - t) * (5.0 * t - 3.0);
}

}  // namespace pb::kernel
