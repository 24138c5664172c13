#include "estimator/film.h"

#include "estimator/error_model.h"
#include "estimator/film_pixels.h"
#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>

namespace pb {

namespace {

// What the bounds add up to over the image (ESTIMATOR.md section 7): sums over a chunk of
// pixels, which develop() adds in chunk order, and the per-pixel values.
struct TallySums {
  double bound_sum = 0.0, noise_sum = 0.0, bias_sum = 0.0, bias_metric_sum = 0.0;
  double error = 0.0, error_var = 0.0;  // MeanErrorSums' (below)
  uint64_t known = 0, below = 0, unknown = 0;
  void add(const TallySums& o) {
    bound_sum += o.bound_sum;
    noise_sum += o.noise_sum;
    bias_sum += o.bias_sum;
    bias_metric_sum += o.bias_metric_sum;
    error += o.error;
    error_var += o.error_var;
    known += o.known;
    below += o.below;
    unknown += o.unknown;
  }
};
struct Tally {
  TallySums sums;
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
dvec3 channel_bounds(const PixelResult& r, const BoundRule& rule, const dvec3& denominator,
                     size_t p, TallySums& sums, Tally& tally) {
  dvec3 bound(0.0);
  double pixel_error_sd = 0.0;
  for (int c = 0; c < 3; ++c) {
    if (r.exact) continue;
    const double vb = r.bias_variance[c];
    const double w = bias_shrinkage(r.prior[c], vb);
    // Section 6c: with the fourth-order part, already shrunk by its own prior.
    const double bias = w * r.bias[c] + r.fourth[c];
    const double bias_var = w * vb + squared(double(r.fourth_sd[c]));
    bound[c] = rule.quantile(bias, std::sqrt(r.variance[c] + bias_var)) + r.sparse[c];
    // The same model, for the image's mean error: |w B + noise| with the noise's variance
    // (the t's), plus the sparse-photon term as it stands (an upper limit).
    const ChannelError e = channel_error(bias, r.variance[c] * rule.t_var + bias_var, r.sparse[c],
                                         denominator[c], r.replica[c], r.variance[c]);
    sums.error += e.mean;
    pixel_error_sd += e.sd;
    if (e.replicated) {
      tally.model.replica_linear[p] += e.linear;
      tally.model.replica_rest[p] += e.rest;
    }
  }
  // A pixel's three channels come from the same photons and paths: their errors are taken as
  // fully correlated (exactly so in a grey scene), so their sd add.
  sums.error_var += pixel_error_sd * pixel_error_sd;
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

// ESTIMATOR.md sections 5-7: every pixel's bound (+inf where unknown) into the tally and image;
// the sums into its chunk's `sums`.
void bound_pixel(const PixelResult& r, const BoundRule& rule, bool refuted, uint64_t passes,
                 size_t p, TallySums& sums, Tally& tally, FilmImage* image) {
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
    bound = channel_bounds(r, rule, denominator, p, sums, tally);
    const dvec3 bias = r.bias + dvec3(r.fourth);
    const dvec3 metric = bound / denominator, bias_metric = glm::abs(bias) / denominator;
    sums.bound_sum += metric.x + metric.y + metric.z;
    sums.bias_metric_sum += bias_metric.x + bias_metric.y + bias_metric.z;
    sums.noise_sum += noise.x + noise.y + noise.z;
    sums.bias_sum += std::fabs(bias.x) + std::fabs(bias.y) + std::fabs(bias.z);
    ++sums.known;
    if (s.target > 0.0 && max_component(metric) <= s.target) ++sums.below;
    tally.pixel_bounds[p] = float(max_component(metric));
    if (image)
      for (int c = 0; c < 3; ++c)
        image->target_ratio[3 * p + c] = float(s.target > 0.0 ? metric[c] / s.target : metric[c]);
  } else {
    ++sums.unknown;
    tally.pixel_bounds[p] = INFINITY;
    if (image)
      for (int c = 0; c < 3; ++c) image->target_ratio[3 * p + c] = INFINITY;
  }
  if (image) write_pixel(*image, p, r, bound, noise, known_pixel);
}

// The image's means over its known pixels and the settings' quantile of the pixels' bounds.
void summarise(Tally& tally, const FilmSettings& s, FilmSummary& sum) {
  const size_t pixels = tally.pixel_bounds.size();
  const TallySums& t = tally.sums;
  sum.pixels = pixels;
  sum.unknown_pixels = t.unknown;
  if (t.known > 0) {
    const double known = double(t.known);
    sum.mean_bound = t.bound_sum / (3.0 * known);
    sum.mean_noise = t.noise_sum / (3.0 * known);
    sum.mean_abs_bias = t.bias_sum / (3.0 * known);
    sum.mean_bias_metric = t.bias_metric_sum / (3.0 * known);
  }
  sum.below_target = double(t.below) / double(std::max<size_t>(pixels, 1));
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
  // The planes side by side: in a first development each is fresh pages (166 MB in all at
  // 1920x1080), and faulting them in is most of this (the driver hands later stop tests the
  // earlier planes, which assign() fills in place).
  const std::pair<std::vector<float>*, size_t> planes[] = {
      {&image.radiance, 3 * pixels}, {&image.bound, 3 * pixels},
      {&image.bias, 3 * pixels},     {&image.noise, 3 * pixels},
      {&image.variance, 3 * pixels}, {&image.target_ratio, 3 * pixels},
      {&image.photons, pixels},      {&image.radius, pixels}};
  parallel_for(std::size(planes), 1, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) planes[k].first->assign(planes[k].second, 0.0f);
  });
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

std::byte* DevelopMemory::take(size_t bytes) {
  {
    const std::lock_guard lock(mutex_);
    if (block_ && bytes_ >= bytes) return std::exchange(block_, nullptr);
  }
  return static_cast<std::byte*>(::operator new(bytes));
}

void DevelopMemory::give(std::byte* block, size_t bytes) {
  std::byte* drop = block;
  {
    const std::lock_guard lock(mutex_);
    if (!block_ || bytes_ < bytes) {
      drop = std::exchange(block_, block);
      bytes_ = bytes;
    }
  }
  ::operator delete(drop);
}

void DevelopMemory::release() {
  std::byte* drop = nullptr;
  {
    const std::lock_guard lock(mutex_);
    drop = std::exchange(block_, nullptr);
  }
  ::operator delete(drop);
}

// ESTIMATOR.md sections 5-7: combine, check the model, take the prior, bound and predict.
FilmSummary develop(const PixelLayout& layout, const std::vector<PointState>& states,
                    uint64_t passes, const FilmSettings& s, FilmImage* image,
                    DevelopMemory* memory) {
  PixelResults results = combine_pixels(layout, states, passes, s, memory);
  const size_t pixels = results.size();
  FilmSummary sum;
  sum.relative_floor = relative_floor(results.all());
  if (image) prepare_image(*image, layout.width, layout.height);
  check_model(results.all(), sum);
  const std::span<const uint8_t> floor = layout.paths_taken;
  if (s.bias_model == BiasModel::TwoScale)
    shrink_fourth(results.all(), layout.width, layout.height, floor);
  prior_of(results.all(), layout.width, layout.height, floor);
  const BoundRule rule(passes, s, sum.relative_floor);
  Tally tally(pixels);
  // Over fixed chunks of pixels on every thread, their sums added in chunk order: the summary
  // does not depend on the threads (the loop was a third of a 512x512 development on one).
  constexpr size_t kChunk = 4096;
  std::vector<TallySums> chunk_sums((pixels + kChunk - 1) / kChunk);
  parallel_chunks(pixels, kChunk, [&](size_t k, size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      bound_pixel(results[p], rule, sum.model_refuted, passes, p, chunk_sums[k], tally, image);
  });
  for (const TallySums& c : chunk_sums) tally.sums.add(c);
  tally.model.error = tally.sums.error;
  tally.model.error_var = tally.sums.error_var;
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
