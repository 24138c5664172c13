// The smooth quintic kernel of ESTIMATOR.md section 2. Its first two derivatives vanish at the
// rim, so its Laplacian exists everywhere and integrates to zero, which the bias estimate needs.
#pragma once

#include "estimator/disc_moments.h"

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

// E[w(t)^2] for t uniform over the unit disc, 2 integral_0^1 w(t)^2 t dt = 287 / 132 (E[w] = 1):
// the variance of a kernel sum over Poisson arrivals of equal power, per arrival.
inline constexpr double kWeightSecondMoment = 287.0 / 132.0;

// Photon weight normalised like a box kernel: w(t) = pi kappa(t) = 3.5 k(t).
inline double weight(double t) { return 3.5 * profile(t); }

// Laplacian photon weight without its 1/R^2: w_lap(t) R^2 = 105 t (1-t)(5t-3). The caller divides
// by the R^2 of the pass in double (ESTIMATOR.md section 8).
inline double laplacian_weight_r2(double t) {
  if (t >= 1.0) return 0.0;
  return 105.0 * t * (1.0 - t) * (5.0 * t - 3.0);
}

// The radial integrals of the boundary quadrature (ESTIMATOR.md section 11), in closed form, for
// 0 <= a <= 1: G(a) = integral from 0 to a of g(t) t dt for g = kappa, |u|^2 kappa, lap kappa,
// |u|^2 lap kappa. Over the whole disc 2 pi G(1) gives 1, 5/24, 0 and 4.
double mass_to(double a);
double second_to(double a);
double laplacian_mass_to(double a);
double laplacian_second_to(double a);

// The moments of the kernel and its Laplacian over the star-shaped part of a disc of radius r
// that a point at its centre sees (ESTIMATOR.md section 11): rho[k] is the visible extent in the
// k-th of `directions` equally spaced angles, (k + 0.5) 2 pi / directions (midpoint rule); an
// extent of r or more is the whole radius.
DiscMoments polar_moments(const double* rho, int directions, double r);

}  // namespace pb::kernel
