// The distributions' quantiles the bounds are taken from (ESTIMATOR.md sections 4, 6 and 12):
// Student's t, the exact quantile of |B + s T| (BoundQuantile), the t at three sds of the model
// checks, and the Garwood limit of the sparse-photon bound. Declared in estimator.h.
#include "estimator/estimator.h"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace pb {

double t_at_three_sd(uint64_t nu) {
  // The Student-t quantile at the normal's 3-sd point, Phi(3), by degrees of freedom; the
  // table ends where it is within 0.1% of 3.
  static constexpr uint64_t kTable = 1024;
  static const std::vector<double> table = [] {
    const double p = boost::math::cdf(boost::math::normal_distribution<double>(), kSlopeZ);
    std::vector<double> t(kTable + 1, kSlopeZ);
    for (uint64_t k = 1; k <= kTable; ++k) t[k] = student_t_quantile(double(k), p);
    return t;
  }();
  return nu == 0 ? std::numeric_limits<double>::infinity() : table[std::min(nu, kTable)];
}

namespace {

// CDF and density of Student's t (normal beyond 1e7 degrees of freedom, like the quantile).
struct StudentT {
  double nu;
  double cdf(double x) const {
    if (nu > 1e7) return boost::math::cdf(boost::math::normal_distribution<double>(), x);
    return boost::math::cdf(boost::math::students_t_distribution<double>(nu), x);
  }
  double pdf(double x) const {
    if (nu > 1e7) return boost::math::pdf(boost::math::normal_distribution<double>(), x);
    return boost::math::pdf(boost::math::students_t_distribution<double>(nu), x);
  }
};

}  // namespace

BoundQuantile::BoundQuantile(double nu, double confidence)
    : t_two_(student_t_quantile(nu, 0.5 + 0.5 * confidence)) {
  const StudentT t{nu};
  const double t_one = student_t_quantile(nu, confidence);
  for (int k = 0; k < kTable; ++k) {
    const double x = double(k) / double(kTable - k);  // u / (1 - u) with u = k / kTable
    // Solve P(|x + T| <= q) = F(q - x) - F(-q - x) = confidence for q. The root lies between
    // the one- and two-sided bounds; Newton steps from the upper end, kept inside the bracket,
    // with a bisection step whenever Newton would leave it.
    // Warm start from the previous node: q - x changes slowly with x.
    double lo = x + t_one, hi = x + t_two_;
    double q = k == 0 ? hi : std::clamp(x + table_[k - 1], lo, hi);
    for (int it = 0; it < 50; ++it) {
      const double g = t.cdf(q - x) - t.cdf(-q - x) - confidence;
      if (g > 0.0)
        hi = q;
      else
        lo = q;
      const double slope = t.pdf(q - x) + t.pdf(-q - x);
      double next = slope > 0.0 ? q - g / slope : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::fabs(next - q) <= 1e-10 * q || hi - lo <= 1e-10 * hi) {
        q = next;
        break;
      }
      q = next;
    }
    table_[k] = q - x;
  }
  table_[kTable] = t_one;  // x -> infinity: the far tail vanishes, one-sided quantile
}

double BoundQuantile::operator()(double bias, double sd) const {
  const double b = std::fabs(bias);
  if (!(sd > 0.0)) return b;
  const double x = b / sd;
  if (!std::isfinite(x)) return b + sd * table_[kTable];
  const double pos = x / (1.0 + x) * kTable;
  const int k = std::min(int(pos), kTable - 1);
  const double f = pos - k;
  return b + sd * (table_[k] * (1.0 - f) + table_[k + 1] * f);
}

namespace {

// lambda_u k of sparse_photon_bound: the Garwood limit on the photons expected over the passes.
double garwood_total(uint64_t photons, double confidence) {
  if (photons == 0) return -std::log1p(-confidence);
  return 0.5 * boost::math::quantile(
                   boost::math::chi_squared_distribution<double>(2.0 * double(photons) + 2.0),
                   confidence);
}

}  // namespace

double sparse_photon_bound(uint64_t photons, uint64_t passes, double cap, double confidence) {
  if (passes == 0 || !(cap > 0.0)) return 0.0;
  // The film asks for the same few photon counts (those below kMinPhotonsForBound) at one
  // confidence for every sparse pixel and channel; the chi-squared quantile (Boost, in long
  // double) cost a fifth of a one-pass 1080p render. Kept per thread, so no lock.
  struct Cache {
    double confidence = -1.0;
    std::array<double, 16> total{};
  };
  thread_local Cache cache;
  double total = 0.0;
  if (photons < cache.total.size()) {
    if (cache.confidence != confidence) {
      for (size_t n = 0; n < cache.total.size(); ++n) cache.total[n] = garwood_total(n, confidence);
      cache.confidence = confidence;
    }
    total = cache.total[photons];
  } else {
    total = garwood_total(photons, confidence);
  }
  return total / double(passes) * cap;
}

double student_t_quantile(double nu, double p) {
  // Beyond 1e7 degrees of freedom the t and normal quantiles agree to ~1e-8 and Boost's t
  // evaluation loses accuracy; use the normal there.
  if (nu > 1e7) return boost::math::quantile(boost::math::normal_distribution<double>(), p);
  return boost::math::quantile(boost::math::students_t_distribution<double>(nu), p);
}

}  // namespace pb
