#include "estimator/film.h"

#include "estimator/error_model.h"
#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pb {

namespace {

double sq(double x) { return x * x; }

struct PixelResult {
  dvec3 radiance{0.0}, bias{0.0}, variance{0.0};
  dvec3 bias_variance{0.0};  // of the bias estimate (ESTIMATOR.md section 6b)
  // The two scales' fourth-order bias and its variance (section 6c; 0 with --bias-model
  // laplacian), shrunk by a prior of their own: float, since develop() holds every pixel's.
  // Its sd rather than its variance: a float's range holds a bias of 1e30 and its square not.
  vec3 fourth{0.0f}, fourth_sd{0.0f};
  dvec3 sparse{0.0};   // bound of the photon part of states with few photons (section 12)
  dvec3 replica{0.0};  // a replica of the noise (sum_k W_k of the states', section 7)
  double photons = 0.0;
  uint32_t slope_tested = 0, slope_disagree = 0;  // state-channels of the model check (11b)
  uint32_t scale_tested = 0, scale_disagree = 0;  // states of the two-scale check (11c)
  float radius = 0.0f;
  bool exact = false;  // PPM: no point, so nothing random (background, exact emission)
  // SPPM: no visible point in any pass, so no photon part: the bias model does not enter its
  // bound (the emission and background its jittered paths saw), and a refuted model leaves it.
  bool photon_free = false;
  bool known = true;
};

// Counts a state's channels into the model check (ESTIMATOR.md section 11b) and the state into
// the two-scale check (section 11c).
void count_slopes(PixelResult& r, const PointEstimate& e) {
  for (int c = 0; c < 3; ++c) {
    if (e.slope_z[c] == 0.0) continue;
    ++r.slope_tested;
    r.slope_disagree += std::fabs(e.slope_z[c]) > kSlopeZ;
  }
  if (e.scale_z != 0.0) {
    ++r.scale_tested;
    r.scale_disagree += std::fabs(e.scale_z) > kSlopeZ;
  }
}

// L_pix = Le_seen + sum_k W_k L_k; B_pix = sum_k W_k B_k; Var_pix = sum_k W_k^2 S_k^2 / i
// (ESTIMATOR.md section 5). W_k is already inside each point's estimate (VisiblePoint::f).
// SPPM (section 10): one state per pixel, whose samples carry the emission seen along the path.
// The bound of a state's photon part while it has fewer than kMinPhotonsForBound photons.
// `f_over_c`: the largest f / c a photon's pass sample can carry (f the BRDF, c the kernel mass).
dvec3 sparse_term(const PixelLayout& layout, const PointState& s, const dvec3& f_over_c,
                  uint64_t passes_with_point, double confidence) {
  if (s.photons >= kMinPhotonsForBound || !(layout.photon_cap > 0.0)) return dvec3(0.0);
  dvec3 out;
  for (int ch = 0; ch < 3; ++ch)
    out[ch] = sparse_photon_bound(s.photons, passes_with_point,
                                  layout.photon_cap * f_over_c[ch] / (kPiD * s.r2), confidence);
  return out;
}

double kernel_mass(const PixelLayout& layout, size_t k) {
  return layout.mass.empty() ? 1.0 : std::max(double(layout.mass[k]), kMinKernelMass);
}

// Section 6c: a state's fourth-order bias into the pixel's, unless --bias-model laplacian.
void add_fourth(PixelResult& r, const PointEstimate& e, BiasModel model) {
  if (model != BiasModel::TwoScale) return;
  r.fourth += vec3(e.fourth);
  for (int c = 0; c < 3; ++c)
    r.fourth_sd[c] = float(std::sqrt(sq(double(r.fourth_sd[c])) + e.fourth_variance[c]));
}

PixelResult combine(const PixelLayout& layout, const std::vector<PointState>& states, size_t pixel,
                    uint64_t passes, const FilmSettings& settings) {
  const double photons_per_pass = settings.photons_per_pass, confidence = settings.confidence;
  PixelResult r;
  if (layout.pixel_begin.empty()) {
    const PointEstimate e = estimate(states[pixel], passes, photons_per_pass);
    add_fourth(r, e, settings.bias_model);
    r.radiance = e.radiance;
    r.bias = e.bias;
    r.variance = e.variance;
    r.bias_variance = e.bias_variance;
    r.replica = e.replica;
    count_slopes(r, e);
    r.photons = double(states[pixel].photons);
    r.radius = float(std::sqrt(states[pixel].r2));
    // A pixel that never had a visible point has no photon part to wait for: its samples are
    // the emission along its paths, known from two passes on.
    const uint64_t visible = layout.visible_passes.empty() ? passes : layout.visible_passes[pixel];
    // Lambertian points: the scene's largest Lambertian f over the pixel's smallest c; glossy
    // points: the largest f / c any of them had.
    dvec3 f_over_c = dvec3(layout.max_f) / kernel_mass(layout, pixel);
    if (!layout.glossy_f.empty()) f_over_c = glm::max(f_over_c, dvec3(layout.glossy_f[pixel]));
    // The pixel's estimate averages its samples over every pass, and a pass without a visible
    // point has no photon part: the photon part's mean is at most k_v lambda_u / i times a
    // photon's cap, with lambda_u the bound per visible pass (n photons in k_v such passes), so
    // chi^2 / (2 i) times the cap, over all i passes (ESTIMATOR.md section 12).
    r.sparse = visible == 0 ? dvec3(0.0)
                            : sparse_term(layout, states[pixel], f_over_c, passes, confidence);
    // Without the photon cap a state with few photons has no bound (unknown); a pixel that never
    // had a visible point has no photon part to wait for.
    r.photon_free = visible == 0;
    r.known = passes >= 2 && (e.known || layout.photon_cap > 0.0 || visible == 0) &&
              (layout.mass.empty() || visible == 0 || layout.mass[pixel] >= kValidKernelMass);
    return r;
  }
  if (!layout.emission.empty()) r.radiance = layout.emission[pixel];
  r.exact = true;
  for (uint32_t k = layout.pixel_begin[pixel]; k < layout.pixel_begin[pixel + 1]; ++k) {
    const PointEstimate e = estimate(states[k], passes, photons_per_pass);
    add_fourth(r, e, settings.bias_model);
    r.radiance += e.radiance;
    r.bias += e.bias;
    r.variance += e.variance;
    r.bias_variance += e.bias_variance;
    r.replica += e.replica;
    count_slopes(r, e);
    r.photons += double(states[k].photons);
    if (r.exact) r.radius = float(std::sqrt(states[k].r2));
    r.exact = false;
    if (!layout.point_f.empty())
      r.sparse += sparse_term(layout, states[k], dvec3(layout.point_f[k]) / kernel_mass(layout, k),
                              passes, confidence);
    r.known = r.known && passes >= 2 && (e.known || layout.photon_cap > 0.0) &&
              (layout.mass.empty() || layout.mass[k] >= kValidKernelMass);
  }
  return r;
}

// ESTIMATOR.md sections 5 and 10: every pixel's sums of its states.
std::vector<PixelResult> combine_pixels(const PixelLayout& layout,
                                        const std::vector<PointState>& states, uint64_t passes,
                                        const FilmSettings& s) {
  const size_t pixels = size_t(layout.width) * size_t(layout.height);
  std::vector<PixelResult> results(pixels);
  parallel_for(pixels, 1024, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) results[p] = combine(layout, states, p, passes, s);
  });
  return results;
}

// ESTIMATOR.md section 7: the relative metric's floor, from the image's mean radiance.
double relative_floor(const std::vector<PixelResult>& results) {
  double mean_radiance = 0.0;
  for (const PixelResult& r : results)
    mean_radiance += (r.radiance.x + r.radiance.y + r.radiance.z);
  mean_radiance /= 3.0 * double(std::max<size_t>(results.size(), 1));
  return kRelativeFloor * mean_radiance;
}

// ESTIMATOR.md sections 11b and 11c: where the samples' drift with R^2 and the Laplacian
// disagree in more than kRefutedShare of the state-channels, or the two scales in more than
// that share of the states, no bound of this image can be trusted.
void check_model(const std::vector<PixelResult>& results, FilmSummary& sum) {
  uint64_t slope_tested = 0, slope_disagree = 0, scale_tested = 0, scale_disagree = 0;
  for (const PixelResult& r : results) {
    slope_tested += r.slope_tested;
    slope_disagree += r.slope_disagree;
    scale_tested += r.scale_tested;
    scale_disagree += r.scale_disagree;
  }
  sum.slope_disagreement = slope_tested ? double(slope_disagree) / double(slope_tested) : 0.0;
  sum.scale_disagreement = scale_tested ? double(scale_disagree) / double(scale_tested) : 0.0;
  sum.model_refuted =
      sum.slope_disagreement > kRefutedShare || sum.scale_disagreement > kRefutedShare;
}

// ESTIMATOR.md section 6b: the bias prior over the known pixels with a random state.
std::vector<dvec3> prior_of(const std::vector<PixelResult>& results, int width, int height) {
  return bias_prior(
      [&](size_t p) {
        const PixelResult& r = results[p];
        return BiasEstimate{r.bias, r.bias_variance, r.known && !r.exact};
      },
      width, height);
}

// ESTIMATOR.md section 6c: the fourth-order part shrunk by a prior of its own (over the same
// window), in place: each pixel keeps w4 B4 and sqrt(w4 V4). Where it is noise (a smooth radiance,
// tau4 ~ 0) it then neither moves the bias nor dilutes the Laplacian's. Done before the
// second-order prior, so that develop() never holds two priors at once.
void shrink_fourth(std::vector<PixelResult>& results, int width, int height) {
  const std::vector<dvec3> tau4 = bias_prior(
      [&](size_t p) {
        const PixelResult& r = results[p];
        const dvec3 sd(r.fourth_sd);
        return BiasEstimate{dvec3(r.fourth), sd * sd, r.known && !r.exact};
      },
      width, height, kFourthNoiseFactor);
  for (size_t p = 0; p < results.size(); ++p)
    for (int c = 0; c < 3; ++c) {
      PixelResult& r = results[p];
      const double w4 =
          r.fourth[c] == 0.0f ? 0.0 : bias_shrinkage(tau4[p][c], sq(double(r.fourth_sd[c])));
      r.fourth[c] = float(r.fourth[c] * w4);
      r.fourth_sd[c] = float(r.fourth_sd[c] * std::sqrt(w4));
    }
}

// What the bounds add up to over the image (ESTIMATOR.md section 7).
struct Tally {
  double bound_sum = 0.0, noise_sum = 0.0, bias_sum = 0.0, bias_metric_sum = 0.0;
  uint64_t known = 0, below = 0;
  std::vector<float> pixel_bounds;  // largest channel, in the metric
  // The error model's sums. The noise replicas, standardised and weighted by what of a pixel's
  // |error| moves linearly with its noise and what otherwise: their cross products between
  // neighbours bound the covariances of the neighbours' |error|.
  MeanErrorSums model;
  explicit Tally(size_t pixels) : pixel_bounds(pixels, 0.0f) {
    model.replica_linear.assign(pixels, 0.0);
    model.replica_rest.assign(pixels, 0.0);
  }
};

// How a pixel's bounds are taken: the quantile at i - 1 degrees of freedom (no bound exists
// before two passes, nu = i - 1 >= 1), the noise half-width's t, Var(T_nu) and the metric.
struct BoundRule {
  BoundQuantile quantile;
  double t, nu, t_var;
  const FilmSettings& s;
  double relative_floor;
  BoundRule(uint64_t passes, const FilmSettings& settings, double floor)
      : quantile(double(std::max<uint64_t>(passes, 2) - 1), settings.confidence),
        t(quantile.two_sided_t()),
        nu(double(std::max<uint64_t>(passes, 2) - 1)),
        t_var(nu > 2.0 ? nu / (nu - 2.0) : 3.0),  // Var(T_nu); 3 stands in below nu = 3
        s(settings),
        relative_floor(floor) {}
};

// ESTIMATOR.md sections 6b and 7: a known pixel's bound per channel, its share of the
// mean-error model added to the tally. The bias is known only through its noisy estimate B:
// given the prior of the neighbourhood, the error's bias part is B shrunk by
// w = tau^2 / (tau^2 + Var B), with the posterior's variance w Var B added to the noise.
dvec3 channel_bounds(const PixelResult& r, const dvec3& tau2, const BoundRule& rule,
                     const dvec3& denominator, size_t p, Tally& tally) {
  dvec3 bound(0.0);
  double pixel_error_sd = 0.0;
  for (int c = 0; c < 3; ++c) {
    if (r.exact) continue;
    const double vb = r.bias_variance[c];
    const double w = bias_shrinkage(tau2[c], vb);
    // Section 6c: with the fourth-order part, already shrunk by its own prior.
    const double bias = w * r.bias[c] + r.fourth[c];
    const double bias_var = w * vb + sq(double(r.fourth_sd[c]));
    bound[c] = rule.quantile(bias, std::sqrt(r.variance[c] + bias_var)) + r.sparse[c];
    // The same model, for the image's mean error: |w B + noise| with the noise's variance
    // (the t's), plus the sparse-photon term as it stands (an upper limit).
    const ChannelError e = channel_error(bias, r.variance[c] * rule.t_var + bias_var, r.sparse[c],
                                         denominator[c], r.replica[c], r.variance[c]);
    tally.model.error += e.mean;
    pixel_error_sd += e.sd;
    if (e.replicated) {
      tally.model.replica_linear[p] += e.linear;
      tally.model.replica_rest[p] += e.rest;
    }
  }
  // A pixel's three channels come from the same photons and paths: their errors are taken as
  // fully correlated (exactly so in a grey scene), so their sd add.
  tally.model.error_var += pixel_error_sd * pixel_error_sd;
  return bound;
}

void write_pixel(FilmImage& image, size_t p, const PixelResult& r, const dvec3& bound,
                 const dvec3& noise, bool known) {
  for (int c = 0; c < 3; ++c) {
    image.radiance[3 * p + c] = float(r.radiance[c]);
    image.bound[3 * p + c] = float(bound[c]);
    image.bias[3 * p + c] = float(r.bias[c] + r.fourth[c]);
    image.noise[3 * p + c] = known ? float(noise[c]) : INFINITY;
    image.variance[3 * p + c] = float(r.variance[c]);
  }
  image.photons[p] = float(r.photons);
  image.radius[p] = r.radius;
}

// ESTIMATOR.md sections 5-7: every pixel's bound (+inf where unknown) into the tally and image.
void bound_pixel(const PixelResult& r, const dvec3& tau2, const BoundRule& rule, bool refuted,
                 uint64_t passes, size_t p, Tally& tally, FilmSummary& sum, FilmImage* image) {
  const FilmSettings& s = rule.s;
  const bool known_pixel = r.exact || (passes >= 2 && r.known && (!refuted || r.photon_free));
  dvec3 noise(0.0), bound(std::numeric_limits<double>::infinity());
  if (known_pixel) {
    // PPM pixels without points see only background or exact emission: bound 0.
    noise = r.exact ? dvec3(0.0) : rule.t * glm::sqrt(r.variance);
    const dvec3 denominator =
        s.metric == ErrorMetric::Relative
            ? glm::max(r.radiance, dvec3(std::max(rule.relative_floor, 1e-300)))
            : dvec3(1.0);
    bound = channel_bounds(r, tau2, rule, denominator, p, tally);
    const dvec3 bias = r.bias + dvec3(r.fourth);
    const dvec3 metric = bound / denominator, bias_metric = glm::abs(bias) / denominator;
    tally.bound_sum += metric.x + metric.y + metric.z;
    tally.bias_metric_sum += bias_metric.x + bias_metric.y + bias_metric.z;
    tally.noise_sum += noise.x + noise.y + noise.z;
    tally.bias_sum += std::fabs(bias.x) + std::fabs(bias.y) + std::fabs(bias.z);
    ++tally.known;
    if (s.target > 0.0 && max_component(metric) <= s.target) ++tally.below;
    tally.pixel_bounds[p] = float(max_component(metric));
    if (image)
      for (int c = 0; c < 3; ++c)
        image->target_ratio[3 * p + c] = float(s.target > 0.0 ? metric[c] / s.target : metric[c]);
  } else {
    ++sum.unknown_pixels;
    tally.pixel_bounds[p] = INFINITY;
    if (image)
      for (int c = 0; c < 3; ++c) image->target_ratio[3 * p + c] = INFINITY;
  }
  if (image) write_pixel(*image, p, r, bound, noise, known_pixel);
}

// The image's means over its known pixels and the settings' quantile of the pixels' bounds.
void summarise(Tally& tally, const FilmSettings& s, FilmSummary& sum) {
  const size_t pixels = tally.pixel_bounds.size();
  sum.pixels = pixels;
  if (tally.known > 0) {
    const double known = double(tally.known);
    sum.mean_bound = tally.bound_sum / (3.0 * known);
    sum.mean_noise = tally.noise_sum / (3.0 * known);
    sum.mean_abs_bias = tally.bias_sum / (3.0 * known);
    sum.mean_bias_metric = tally.bias_metric_sum / (3.0 * known);
  }
  sum.below_target = double(tally.below) / double(std::max<size_t>(pixels, 1));
  if (pixels > 0) {
    std::vector<float>& b = tally.pixel_bounds;
    const size_t q = std::min(pixels - 1, size_t(std::ceil(s.stop_fraction * double(pixels))) - 1);
    std::nth_element(b.begin(), b.begin() + q, b.end());
    sum.pixel_quantile_bound = b[q];
  }
}

void prepare_image(FilmImage& image, int width, int height) {
  const size_t pixels = size_t(width) * size_t(height);
  image.width = width;
  image.height = height;
  for (auto* v : {&image.radiance, &image.bound, &image.bias, &image.noise, &image.variance,
                  &image.target_ratio})
    v->assign(3 * pixels, 0.0f);
  image.photons.assign(pixels, 0.0f);
  image.radius.assign(pixels, 0.0f);
}

double mean_r2(const std::vector<PointState>& states) {
  double mean = 0.0;
  for (const PointState& st : states) mean += st.r2;
  return mean / double(std::max<size_t>(states.size(), 1));
}

}  // namespace

const std::vector<float>& FilmImage::plane(Channel id) const {
  switch (id) {
    case Channel::Radiance:
      return radiance;
    case Channel::ErrorBound:
      return bound;
    case Channel::Bias:
      return bias;
    case Channel::Noise:
      return noise;
    case Channel::Variance:
      return variance;
    case Channel::Photons:
      return photons;
    case Channel::Radius:
      return radius;
    case Channel::TargetRatio:
      return target_ratio;
  }
  return radiance;
}

// ESTIMATOR.md sections 5-7: combine, check the model, take the prior, bound and predict.
FilmSummary develop(const PixelLayout& layout, const std::vector<PointState>& states,
                    uint64_t passes, const FilmSettings& s, FilmImage* image) {
  std::vector<PixelResult> results = combine_pixels(layout, states, passes, s);
  const size_t pixels = results.size();
  FilmSummary sum;
  sum.relative_floor = relative_floor(results);
  if (image) prepare_image(*image, layout.width, layout.height);
  check_model(results, sum);
  if (s.bias_model == BiasModel::TwoScale) shrink_fourth(results, layout.width, layout.height);
  const std::vector<dvec3> tau2 = prior_of(results, layout.width, layout.height);
  const BoundRule rule(passes, s, sum.relative_floor);
  Tally tally(pixels);
  for (size_t p = 0; p < pixels; ++p)
    bound_pixel(results[p], tau2[p], rule, sum.model_refuted, passes, p, tally, sum, image);
  summarise(tally, s, sum);
  if (sum.unknown_pixels == 0 && pixels > 0) {
    const ErrorPrediction e =
        predict_mean_error(tally.model, layout.width, layout.height, mean_r2(states),
                           layout.footprint, rule.nu, s.confidence);
    sum.correlated_pixels = e.correlated_pixels;
    sum.predicted_error = e.mean;
    sum.predicted_error_upper = e.upper;
  }
  return sum;
}

}  // namespace pb
