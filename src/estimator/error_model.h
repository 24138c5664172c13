// The error model behind the mean-error stop rule (ESTIMATOR.md section 7): a pixel-channel's
// error is its bias (posterior mean mu, section 6b) plus a noise of standard deviation sigma
// (the bias's posterior variance inside). Its expected absolute value and the variance of that
// absolute value, for a normal error: the folded normal distribution's moments.
#pragma once

namespace pb {

// What --target-error measures (docs/usage.md "Stop rules"): the absolute error, or the error relative
// to max(L, kRelativeFloor x the image's mean radiance) (film.h).
enum class ErrorMetric { Absolute, Relative };

// E|mu + sigma Z| = sigma sqrt(2/pi) exp(-mu^2 / (2 sigma^2)) + mu erf(mu / (sigma sqrt 2)).
double expected_abs_error(double mu, double sigma);
// Var|mu + sigma Z| = mu^2 + sigma^2 - (E|mu + sigma Z|)^2.
double abs_error_variance(double mu, double sigma);

// Pixels whose errors are fully correlated, in effect, because their discs share photons:
// sum over pixels j of the correlation of two kernel estimates a pixel apart, for discs of
// radius R and pixels of footprint f: (integral kappa)^2 / integral kappa^2 (R / f)^2 =
// 1.4449 (R / f)^2 (the quintic kernel; at least 1). The photon-sharing model the mean-error
// rule measures against (`bounds_study correlation`); the rule itself measures K from the
// noise replicas (film.cpp, ESTIMATOR.md section 7), since next-event and jitter noise are
// each pixel's own.
double correlated_pixels(double radius, double footprint);

// The one-sided normal quantile z_p (p in (0, 1)).
double normal_quantile(double p);

}  // namespace pb
