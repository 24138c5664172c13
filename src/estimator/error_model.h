// The error model behind the mean-error stop rule (ESTIMATOR.md section 7): a pixel-channel's
// error is its bias (posterior mean mu, section 6b) plus a noise of standard deviation sigma
// (the bias's posterior variance inside). Its expected absolute value and the variance of that
// absolute value, for a normal error: the folded normal distribution's moments.
#pragma once

#include <cstdint>
#include <functional>
#include <span>

#include "util/math.h"

#include <vector>

namespace pb {

// What --target-error measures (docs/usage.md "Stop rules"): the absolute error, or the error
// relative to max(L, kRelativeFloor x the image's mean radiance) (film.h).
enum class ErrorMetric { Absolute, Relative };

// Which bias the bounds take (--bias-model, ESTIMATOR.md section 6c): the Laplacian's a R^2 plus
// the fourth-order part the two kernel scales measure, or the Laplacian's alone (HJJ10).
enum class BiasModel { TwoScale, Laplacian };

// E|mu + sigma Z| = sigma sqrt(2/pi) exp(-mu^2 / (2 sigma^2)) + mu erf(mu / (sigma sqrt 2)).
double expected_abs_error(double mu, double sigma);

// Pixels whose errors are fully correlated, in effect, because their discs share photons:
// sum over pixels j of the correlation of two kernel estimates a pixel apart, for discs of
// radius R and pixels of footprint f: (integral kappa)^2 / integral kappa^2 (R / f)^2 =
// 1.4449 (R / f)^2 (the quintic kernel; at least 1). The photon-sharing model the mean-error
// rule measures against (`bounds_study correlation`); the rule itself measures K from the
// noise replicas (predict_mean_error, ESTIMATOR.md section 7), since next-event and jitter noise
// are each pixel's own.
double correlated_pixels(double radius, double footprint);

// The one-sided normal quantile z_p (p in (0, 1)).
double normal_quantile(double p);

// One pixel's bias estimate B and its variance, as the prior sees it (ESTIMATOR.md section 6b);
// `use` is false for pixels without one (unknown or exact).
struct BiasEstimate {
  dvec3 bias{0.0}, variance{0.0};
  bool use = false;
};
// The empirical-Bayes prior of the bias (section 6b): per pixel and channel, the variance tau^2
// of the true bias around 0, estimated over the (2 kPriorWindow + 1)^2 window of the pixels in
// use as mean(B^2) - mean(Var B) (the estimates' own noise taken out), never below 0.
inline constexpr int kPriorWindow = 4;
// The floor under a window's tau^2 from the pixel's own estimate: tau^2 >= B^2 - k' k Var B
// with k' = kPriorOwnFactor (and the prior's noise factor k). A contact shadow is a few biased
// pixels in a window of 81 whose others are near 0, and the window alone shrinks their bias
// toward 0; with the noise beside it lowered by `--adaptive paths` that bias is most of the
// error, and the mean-error stop was 7-8% low (14 of 20 within at 90% on the Cornell box). A
// pixel's own B counts only beyond about sqrt(5) of its sds (a chi-square of 1 beyond 5: 2.5%
// of pure noise), so that where the bias is noise the window still decides. Measured in
// section 15's table: k' = 5 calibrates `radius,paths` (16-20 of 20 within at 90%) for 1-6% more
// passes where the window alone was already calibrated. Only with `--adaptive paths`, in the
// windows of pixels that have had a second path (PixelLayout::paths_taken): where
// no path lowered the noise the window alone keeps the stop calibrated, and the floor there
// cost the plane 6% more passes.
inline constexpr double kPriorOwnFactor = 5.0;
// `pixel(p)` gives pixel p's estimate (read in place: a copy of the image's estimates would
// raise a render's peak memory by 56 bytes per pixel).
// `noise_factor` k: tau^2 = max(0, mean(B^2) - k mean(Var B)); k > 1 asks the window's
// estimates to stand out of their noise before any of it counts as bias (section 6c).
// `floor`: per pixel, 1 where paths were taken; a pixel with one in its window takes the floor
// tau^2 >= B^2 - kPriorOwnFactor k Var B of its own estimate (empty: no pixel does).
// Each pixel's tau^2 is handed to out(p, tau2), once, from any thread.
void bias_prior(const std::function<BiasEstimate(size_t)>& pixel, int width, int height,
                double noise_factor, std::span<const uint8_t> floor,
                const std::function<void(size_t, const dvec3&)>& out);
// The noise factor of the fourth-order bias's prior (section 6c). Where the radiance is smooth
// B4 is noise, and with k = 1 tau4^2 is still positive in about half of the windows:
// mean(B4^2) / mean(V4) over a window's 81 pixels has an sd of sqrt(2 K / 81) under the null,
// 0.22-0.31 for the K = 2-4 pixels that share photons. A window's B4 counts as bias only beyond
// about 2 of those sds. On the analytic plane k = 1 widened every bound by 7% and kept 52-53%
// of the pixels within the 50% bound.
inline constexpr double kFourthNoiseFactor = 1.5;
// The shrinkage w = tau^2 / (tau^2 + Var B) of a bias estimate B under the prior tau^2 (section
// 6b): the error's bias part is w B, and the posterior's variance w Var B; 1 when B is exact.
double bias_shrinkage(double prior, double bias_variance);

// One pixel-channel in the model of the image's mean error (section 7): its error is the shrunk
// bias w B plus a normal noise of variance `error_variance` (the noise's, the t's variance
// times Var_pix, plus the bias posterior's w Var B), over the metric's `denominator`, plus the
// sparse-photon term as it stands (an upper limit). `replica` is the pixel-channel's noise
// replica and `variance` the Var_pix that standardises it.
struct ChannelError {
  double mean = 0.0;        // E|e| plus the sparse term, in the metric
  double sd = 0.0;          // sd of |e|
  bool replicated = false;  // the replica weights apply (sigma > 0 and Var_pix > 0)
  double linear = 0.0;      // the standardised replica weighted by g sigma
  double rest = 0.0;        // and by sqrt(Var|e| - g^2 sigma^2)
};
ChannelError channel_error(double shrunk_bias, double error_variance, double sparse,
                           double denominator, double replica, double variance);

// What the prediction of an image's mean error takes (section 7): sums over its pixel-channels.
struct MeanErrorSums {
  double error = 0.0;      // of E|e|
  double error_var = 0.0;  // of the pixels' Var|e| (each pixel's channels' sd added)
  std::vector<double> replica_linear, replica_rest;  // per pixel: ChannelError's, summed
};
// The predicted mean absolute error over the width x height x 3 pixel-channels and its upper
// confidence limit, with K, the pixels whose errors move together in effect, measured from the
// replicas' cross products between pixels within the reach of the discs (2 R, from the states'
// mean R^2, plus the jitter), and nu = i - 1 the degrees of freedom of each sigma^2.
struct ErrorPrediction {
  double correlated_pixels = 1.0;  // K
  double mean = 0.0;
  double upper = 0.0;
};
ErrorPrediction predict_mean_error(const MeanErrorSums& sums, int width, int height, double mean_r2,
                                   double footprint, double nu, double confidence);

}  // namespace pb
