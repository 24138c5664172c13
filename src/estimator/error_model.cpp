#include "estimator/error_model.h"

#include <boost/math/distributions/normal.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pb {

double expected_abs_error(double mu, double sigma) {
  const double a = std::fabs(mu);
  if (!(sigma > 0.0)) return a;
  const double x = a / sigma;
  return sigma * std::sqrt(2.0 / std::numbers::pi) * std::exp(-0.5 * x * x) +
         a * std::erf(x / std::numbers::sqrt2);
}

double abs_error_variance(double mu, double sigma) {
  const double m = expected_abs_error(mu, sigma);
  return std::max(0.0, mu * mu + sigma * sigma - m * m);
}

double correlated_pixels(double radius, double footprint) {
  // 1 / integral over the unit disc of kappa^2 (kernel.h's quintic, by quadrature).
  constexpr double kInverseSquaredMass = 1.444913694367901;
  if (!(footprint > 0.0)) return 1.0;
  const double q = radius / footprint;
  return std::max(1.0, kInverseSquaredMass * q * q);
}

double normal_quantile(double p) {
  return boost::math::quantile(boost::math::normal_distribution<double>(), p);
}

}  // namespace pb
