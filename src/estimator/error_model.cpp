#include "estimator/error_model.h"

#include "estimator/kernel.h"
#include "util/parallel.h"

#include <boost/math/distributions/normal.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pb {

namespace {

// A summed-area table over the image: the sum of a per-pixel value over any box in O(1).
template <class T>
class SummedArea {
 public:
  template <class ValueAt>
  SummedArea(int width, int height, ValueAt value_at)
      : w1_(size_t(width) + 1), t_((size_t(height) + 1) * w1_, T(0.0)) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const size_t at = size_t(y + 1) * w1_ + size_t(x + 1), up = size_t(y) * w1_ + size_t(x + 1);
        t_[at] = value_at(size_t(y) * size_t(width) + size_t(x)) + t_[at - 1] + t_[up] - t_[up - 1];
      }
  }
  // Over pixels [xa, xb) x [ya, yb).
  T box(size_t xa, size_t ya, size_t xb, size_t yb) const {
    return t_[yb * w1_ + xb] - t_[ya * w1_ + xb] - t_[yb * w1_ + xa] + t_[ya * w1_ + xa];
  }

 private:
  size_t w1_;
  std::vector<T> t_;
};

// Sum over pixel pairs p, q within `reach` pixels of each other (both orders) of u_p u_q, by a
// summed-area table: the window estimate of Var(sum_p u_p) for a field u whose correlation does
// not reach further (as in a Newey-West estimate of a correlated sum). Returns the pairs q != p
// only, never below 0: a negative sum is the estimate's own noise.
double windowed_cross_sum(const std::vector<double>& u, int width, int height, int reach) {
  const SummedArea<double> sat(width, height, [&](size_t p) { return u[p]; });
  double cross = 0.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double v = u[size_t(y) * size_t(width) + size_t(x)];
      if (v == 0.0) continue;
      const double box =
          sat.box(size_t(std::max(0, x - reach)), size_t(std::max(0, y - reach)),
                  size_t(std::min(width, x + reach + 1)), size_t(std::min(height, y + reach + 1)));
      cross += v * (box - v);
    }
  return std::max(0.0, cross);
}

// The pixels within which the discs' errors correlate (ESTIMATOR.md section 7): 2 R over the
// footprint, plus one for the jitter, at most the image's size.
int replica_reach(double mean_r2, double footprint, int width, int height) {
  const double reach_pixels = footprint > 0.0 ? 2.0 * std::sqrt(mean_r2) / footprint + 1.0 : 1.0;
  return int(std::ceil(std::min(reach_pixels, double(std::max(width, height)))));
}

}  // namespace

double expected_abs_error(double mu, double sigma) {
  const double a = std::fabs(mu);
  if (!(sigma > 0.0)) return a;
  const double x = a / sigma;
  return sigma * std::sqrt(2.0 / std::numbers::pi) * std::exp(-0.5 * x * x) +
         a * std::erf(x / std::numbers::sqrt2);
}

double correlated_pixels(double radius, double footprint) {
  // 1 / integral over the unit disc of kappa^2 = pi / E[w^2] (kernel.h's quintic).
  constexpr double kInverseSquaredMass = std::numbers::pi / kernel::kWeightSecondMoment;
  if (!(footprint > 0.0)) return 1.0;
  const double q = radius / footprint;
  return std::max(1.0, kInverseSquaredMass * q * q);
}

double normal_quantile(double p) {
  return boost::math::quantile(boost::math::normal_distribution<double>(), p);
}

namespace {

// What a pixel adds to its windows' sums (section 6b): B^2 and Var B where it has an estimate,
// whether it does, and whether paths were taken there.
struct WindowTerms {
  dvec3 b2{0.0}, v{0.0};
  double n = 0.0, taken = 0.0;
  void add(const WindowTerms& o) {
    b2 += o.b2;
    v += o.v;
    n += o.n;
    taken += o.taken;
  }
};

}  // namespace

// ESTIMATOR.md section 6b: the prior of the bias, by the window's sums, each a direct sum of its
// (2 kPriorWindow + 1)^2 terms taken as sums along rows, then down columns. Rows of 32 pixels'
// windows at a time on each thread, in a buffer of their rows' sums (the 8 rows above and below
// summed again by the blocks beside: every sum is the same whichever block takes it). Summed-area
// tables did this before: each a recurrence over the whole image on one thread, eight tables of a
// 64-byte value per pixel (fresh pages in every development: 0.3-0.4 s of a 0.9 s development at
// 1920x1080), and a window's sum the difference of sums over the image, whose rounding is the
// image's, not the window's: a window of small biases beside a large one lost its digits.
void bias_prior(const std::function<BiasEstimate(size_t)>& pixel, int width, int height,
                double noise_factor, std::span<const uint8_t> floor,
                const std::function<void(size_t, const dvec3&)>& out) {
  // The windows that hold a pixel with paths (section 6b: the floor is theirs).
  const bool floored = !floor.empty();
  const size_t w = size_t(std::max(width, 0)), h = size_t(std::max(height, 0));
  constexpr size_t r = kPriorWindow, kRows = 32;
  parallel_chunks(h, kRows, [&](size_t, size_t y0, size_t y1) {
    const size_t ya = y0 >= r ? y0 - r : 0, yb = std::min(h, y1 + r);
    // Per thread, kept from block to block (and development to development): a block's buffer
    // is 5 MB at 1920 pixels a row.
    thread_local std::vector<WindowTerms> terms, rows;
    terms.resize(w);
    rows.resize((yb - ya) * w);
    for (size_t y = ya; y < yb; ++y) {
      for (size_t x = 0; x < w; ++x) {
        const size_t p = y * w + x;
        const BiasEstimate e = pixel(p);
        WindowTerms& t = terms[x];
        t = WindowTerms{};
        if (e.use) t = WindowTerms{e.bias * e.bias, e.variance, 1.0, 0.0};
        t.taken = floored && p < floor.size() && floor[p] ? 1.0 : 0.0;
      }
      WindowTerms* row = &rows[(y - ya) * w];
      for (size_t x = 0; x < w; ++x) {
        WindowTerms sum;
        for (size_t k = x >= r ? x - r : 0, end = std::min(w, x + r + 1); k < end; ++k)
          sum.add(terms[k]);
        row[x] = sum;
      }
    }
    for (size_t y = y0; y < y1; ++y) {
      const size_t wa = y >= r ? y - r : 0, wb = std::min(h, y + r + 1);
      for (size_t x = 0; x < w; ++x) {
        WindowTerms sum;
        for (size_t k = wa; k < wb; ++k) sum.add(rows[(k - ya) * w + x]);
        const size_t p = y * w + x;
        dvec3 tau2(0.0);
        if (sum.n > 0.0) tau2 = glm::max(dvec3(0.0), (sum.b2 - noise_factor * sum.v) / sum.n);
        // The floor (section 6b): a lone bias that stands out of its own noise keeps at least
        // its own size, however small its window's others are.
        if (floored && sum.taken > 0.0)
          if (const BiasEstimate e = pixel(p); e.use)
            tau2 = glm::max(tau2, e.bias * e.bias - kPriorOwnFactor * noise_factor * e.variance);
        out(p, tau2);
      }
    }
  });
}

// ESTIMATOR.md section 6b: the posterior's shrinkage of the bias estimate.
double bias_shrinkage(double prior, double bias_variance) {
  return bias_variance > 0.0 ? prior / (prior + bias_variance) : 1.0;
}

// ESTIMATOR.md section 7: one pixel-channel's |error| and its replica weights.
ChannelError channel_error(double shrunk_bias, double error_variance, double sparse,
                           double denominator, double replica, double variance) {
  const double mu = shrunk_bias / denominator;
  const double sigma = std::sqrt(error_variance) / denominator;
  ChannelError e;
  // Var|mu + sigma Z| = mu^2 + sigma^2 - (E|mu + sigma Z|)^2, on the one E|.| (each an exp
  // and an erf: the development's bound loop spent most of its time in them).
  const double m = expected_abs_error(mu, sigma);
  e.mean = m + sparse / denominator;
  const double v = std::max(0.0, mu * mu + sigma * sigma - m * m);
  e.sd = std::sqrt(v);
  if (sigma > 0.0 && variance > 0.0) {
    // |mu + sigma Z| = m + g sigma He_1(Z) + sum_{k >= 2} c_k sigma He_k(Z) (Hermite),
    // g = erf(mu / sigma sqrt 2): two pixels' |e| whose noises correlate by rho have the
    // covariance sigma sigma' (g g' rho + sum_k k! c_k c_k' rho^k), and for 0 <= rho <= 1
    // the sum is at most rho sqrt(r r') (Cauchy-Schwarz), r = v - g^2 sigma^2 the part of
    // the variance beyond the linear term. The replica's z measures rho: the covariance is
    // bounded by the cross products of g sigma z and sqrt(r) z, exactly so for identical
    // errors (rho = 1), and by rho in place of rho^2 for the noise-dominated (the price of
    // a bound whose every term a replica can measure without its distribution's shape).
    const double g = std::erf(mu / (sigma * std::sqrt(2.0)));
    const double z = replica / std::sqrt(variance);  // standardised replica
    e.replicated = true;
    e.linear = g * sigma * z;
    e.rest = std::sqrt(std::max(0.0, v - g * g * sigma * sigma)) * z;
  }
  return e;
}

// ESTIMATOR.md section 7: the predicted mean error and its upper confidence limit.
ErrorPrediction predict_mean_error(const MeanErrorSums& sums, int width, int height, double mean_r2,
                                   double footprint, double nu, double confidence) {
  // The mean over every pixel-channel, as `compare` takes it (exact pixels add no error). Its
  // variance: the pixels' own, plus the covariances of neighbours' |e|, bounded by the
  // replicas' cross products over the window their discs can share (2R, plus the jitter); plus
  // the model's: each sigma^2 comes from i - 1 passes, and their mean over the n / K
  // independent groups has relative error 1 / sqrt(2 (i - 1) n / K), which moves the predicted
  // mean by half that.
  const double n = 3.0 * double(size_t(width) * size_t(height));
  const int reach = replica_reach(mean_r2, footprint, width, height);
  double linear = 0.0, rest = 0.0;
  parallel_invoke([&] { linear = windowed_cross_sum(sums.replica_linear, width, height, reach); },
                  [&] { rest = windowed_cross_sum(sums.replica_rest, width, height, reach); });
  const double cross = linear + rest;
  const double k = sums.error_var > 0.0 ? 1.0 + cross / sums.error_var : 1.0;
  const double m = sums.error / n;
  const double model = 0.5 * m / std::sqrt(2.0 * nu * std::max(1.0, n / k));
  const double var = k * sums.error_var / (n * n) + model * model;
  ErrorPrediction out;
  out.correlated_pixels = k;
  out.mean = m;
  out.upper = m + normal_quantile(confidence) * std::sqrt(var);
  return out;
}

}  // namespace pb
