#include "estimator/kernel.h"

#include "util/math.h"

namespace pb::kernel {

double unit_mass(double t) { return 3.5 / kPiD * profile(t); }

double unit_laplacian(double t) { return laplacian_weight_r2(t) / kPiD; }

// Closed forms for the quintic (ESTIMATOR.md section 2): kappa(t) = 7/(2 pi) (1 - 10 t^3 + 15 t^4
// - 6 t^5), lap kappa(t) = 105/pi (-3 t + 8 t^2 - 5 t^3).
double mass_to(double a) {
  const double a2 = a * a, a5 = a2 * a2 * a;
  return 7.0 / (2.0 * kPiD) * (a2 / 2.0 + a5 * (-2.0 + a * (2.5 - a * 6.0 / 7.0)));
}
double second_to(double a) {
  const double a2 = a * a, a4 = a2 * a2, a7 = a4 * a2 * a;
  return 7.0 / (2.0 * kPiD) * (a4 / 4.0 + a7 * (-10.0 / 7.0 + a * (15.0 / 8.0 - a * 2.0 / 3.0)));
}
double laplacian_mass_to(double a) {
  const double a3 = a * a * a;
  return 105.0 / kPiD * a3 * (-1.0 + a * (2.0 - a));
}
double laplacian_second_to(double a) {
  const double a5 = a * a * a * a * a;
  return 105.0 / kPiD * a5 * (-3.0 / 5.0 + a * (4.0 / 3.0 - a * 5.0 / 7.0));
}

// Polar quadrature of the visible region (ESTIMATOR.md section 11).
DiscMoments polar_moments(const double* rho, int directions, double r) {
  // An unblocked direction adds the whole-disc constants.
  static const double full[4] = {mass_to(1.0), second_to(1.0), laplacian_mass_to(1.0),
                                 laplacian_second_to(1.0)};
  double mass = 0.0, second = 0.0, lap = 0.0, lap2 = 0.0;
  for (int k = 0; k < directions; ++k) {
    if (rho[k] >= r) {
      mass += full[0];
      second += full[1];
      lap += full[2];
      lap2 += full[3];
      continue;
    }
    const double a = rho[k] / r;
    mass += mass_to(a);
    second += second_to(a);
    lap += laplacian_mass_to(a);
    lap2 += laplacian_second_to(a);
  }
  const double w = 2.0 * kPiD / directions;
  DiscMoments m;
  m.mass = mass * w;
  m.second = second * w;
  m.lap_mass = lap * w;
  m.lap_second = lap2 * w;
  m.full = false;
  return m;
}

}  // namespace pb::kernel
