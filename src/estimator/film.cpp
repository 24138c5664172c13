#include "estimator/film.h"

#include "estimator/error_model.h"
#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pb {

namespace {

struct PixelResult {
  dvec3 radiance{0.0}, bias{0.0}, variance{0.0};
  dvec3 bias_variance{0.0};  // of the bias estimate (ESTIMATOR.md section 6b)
  dvec3 sparse{0.0};         // bound of the photon part of states with few photons (section 12)
  dvec3 replica{0.0};        // a replica of the noise (sum_k W_k of the states', section 7)
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
// (ESTIMATOR.md section 5). W_k is already inside each point's estimate (MeasurementPoint::f).
// SPPM (section 10): one state per pixel, whose samples carry the emission seen along the path.
// The bound of a state's photon part while it has fewer than kMinPhotonsForBound photons.
dvec3 sparse_term(const PixelLayout& layout, const PointState& s, size_t k, const vec3& f,
                  uint64_t passes_with_point, double confidence) {
  if (s.photons >= kMinPhotonsForBound || !(layout.photon_cap > 0.0)) return dvec3(0.0);
  const double c = layout.mass.empty() ? 1.0 : std::max(double(layout.mass[k]), kMinKernelMass);
  const double area = c * kPiD * s.r2;
  dvec3 out;
  for (int ch = 0; ch < 3; ++ch)
    out[ch] = sparse_photon_bound(s.photons, passes_with_point, layout.photon_cap * f[ch] / area,
                                  confidence);
  return out;
}

PixelResult combine(const PixelLayout& layout, const std::vector<PointState>& states, size_t pixel,
                    uint64_t passes, double photons_per_pass, double confidence) {
  PixelResult r;
  if (layout.pixel_begin.empty()) {
    const PointEstimate e = estimate(states[pixel], passes, photons_per_pass);
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
    const vec3 f = layout.glossy_f.empty() ? layout.max_f
                                           : glm::max(layout.max_f, vec3(layout.glossy_f[pixel]));
    // The pixel's estimate averages its samples over every pass, and a pass without a visible
    // point has no photon part: the photon part's mean is at most k_v lambda_u / i times a
    // photon's cap, with lambda_u the bound per visible pass (n photons in k_v such passes), so
    // chi^2 / (2 i) times the cap, over all i passes (ESTIMATOR.md section 12).
    r.sparse = visible == 0 ? dvec3(0.0)
                            : sparse_term(layout, states[pixel], pixel, f, passes, confidence);
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
      r.sparse += sparse_term(layout, states[k], k, layout.point_f[k], passes, confidence);
    r.known = r.known && passes >= 2 && (e.known || layout.photon_cap > 0.0) &&
              (layout.mass.empty() || layout.mass[k] >= kValidKernelMass);
  }
  return r;
}

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

// Empirical-Bayes prior of the bias (ESTIMATOR.md section 6b): per pixel and channel, the
// variance tau^2 of the true bias around it, estimated over the (2W+1)^2 window of known
// pixels as mean(B^2) - mean(Var B) (the estimates' own noise taken out), never below 0.
constexpr int kPriorWindow = 4;

std::vector<dvec3> bias_prior(const std::vector<PixelResult>& results, int width, int height) {
  auto use = [&](size_t p) { return results[p].known && !results[p].exact; };
  const SummedArea<dvec3> b2(width, height, [&](size_t p) {
    return use(p) ? results[p].bias * results[p].bias : dvec3(0.0);
  });
  const SummedArea<dvec3> v(
      width, height, [&](size_t p) { return use(p) ? results[p].bias_variance : dvec3(0.0); });
  const SummedArea<double> n(width, height, [&](size_t p) { return use(p) ? 1.0 : 0.0; });
  std::vector<dvec3> tau2(size_t(width) * size_t(height), dvec3(0.0));
  parallel_for(size_t(height), 16, [&](size_t y0, size_t y1) {
    for (size_t y = y0; y < y1; ++y)
      for (size_t x = 0; x < size_t(width); ++x) {
        const size_t xa = x >= kPriorWindow ? x - kPriorWindow : 0;
        const size_t ya = y >= kPriorWindow ? y - kPriorWindow : 0;
        const size_t xb = std::min(x + kPriorWindow + 1, size_t(width));
        const size_t yb = std::min(y + kPriorWindow + 1, size_t(height));
        const double count = n.box(xa, ya, xb, yb);
        if (count > 0.0)
          tau2[y * size_t(width) + x] =
              glm::max(dvec3(0.0), (b2.box(xa, ya, xb, yb) - v.box(xa, ya, xb, yb)) / count);
      }
  });
  return tau2;
}

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

FilmSummary develop(const PixelLayout& eye, const std::vector<PointState>& states, uint64_t passes,
                    const FilmSettings& s, FilmImage* image) {
  const size_t pixels = size_t(eye.width) * size_t(eye.height);
  std::vector<PixelResult> results(pixels);
  parallel_for(pixels, 1024, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      results[p] = combine(eye, states, p, passes, s.photons_per_pass, s.confidence);
  });

  // No bound exists before two passes (nu = i - 1 >= 1).
  const BoundQuantile quantile(double(std::max<uint64_t>(passes, 2) - 1), s.confidence);
  const double t = quantile.two_sided_t();
  FilmSummary sum;
  double mean_radiance = 0.0;
  for (const PixelResult& r : results)
    mean_radiance += (r.radiance.x + r.radiance.y + r.radiance.z);
  mean_radiance /= 3.0 * double(std::max<size_t>(pixels, 1));
  sum.relative_floor = kRelativeFloor * mean_radiance;

  if (image) {
    image->width = eye.width;
    image->height = eye.height;
    for (auto* v : {&image->radiance, &image->bound, &image->bias, &image->noise, &image->variance,
                    &image->target_ratio})
      v->assign(3 * pixels, 0.0f);
    image->photons.assign(pixels, 0.0f);
    image->radius.assign(pixels, 0.0f);
  }

  // The model checks (sections 11b, 11c): where the samples' drift with R^2 and the Laplacian
  // disagree in more than kRefutedShare of the state-channels, or the two scales in more than
  // that share of the states, no bound of this image can be trusted.
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

  const std::vector<dvec3> tau2 = bias_prior(results, eye.width, eye.height);
  double bound_sum = 0.0, noise_sum = 0.0, bias_sum = 0.0, bias_metric_sum = 0.0;
  double error_sum = 0.0, error_var_sum = 0.0;  // of the error model (section 7)
  const double nu = double(std::max<uint64_t>(passes, 2) - 1);
  const double t_var = nu > 2.0 ? nu / (nu - 2.0) : 3.0;  // Var(T_nu); 3 stands in below nu = 3
  uint64_t known = 0, below = 0;
  std::vector<float> pixel_bounds(pixels, 0.0f);  // largest channel, in the metric
  // The noise replicas, standardised and weighted by what of a pixel's |error| moves linearly
  // with its noise and what otherwise (section 7): their cross products between neighbours
  // bound the covariances of the neighbours' |error|.
  std::vector<double> replica_linear(pixels, 0.0), replica_rest(pixels, 0.0);
  for (size_t p = 0; p < pixels; ++p) {
    const PixelResult& r = results[p];
    const bool known_pixel =
        r.exact || (passes >= 2 && r.known && (!sum.model_refuted || r.photon_free));
    dvec3 noise(0.0), bound(std::numeric_limits<double>::infinity());
    if (known_pixel) {
      // PPM pixels without points see only background or exact emission: bound 0.
      const dvec3 sd = glm::sqrt(r.variance);
      noise = r.exact ? dvec3(0.0) : t * sd;
      // The bias is known only through its noisy estimate B: given the prior of the
      // neighbourhood, the error's bias part is B shrunk by w = tau^2 / (tau^2 + Var B), with
      // the posterior's variance w Var B added to the noise (section 6b).
      double pixel_error_sd = 0.0;
      const dvec3 denominator =
          s.metric == ErrorMetric::Relative
              ? glm::max(r.radiance, dvec3(std::max(sum.relative_floor, 1e-300)))
              : dvec3(1.0);
      for (int c = 0; c < 3; ++c) {
        if (r.exact) {
          bound[c] = 0.0;
          continue;
        }
        const double vb = r.bias_variance[c], prior = tau2[p][c];
        const double w = vb > 0.0 ? prior / (prior + vb) : 1.0;
        bound[c] = quantile(w * r.bias[c], std::sqrt(r.variance[c] + w * vb)) + r.sparse[c];
        // The same model, for the image's mean error: |w B + noise| with the noise's variance
        // (the t's), plus the sparse-photon term as it stands (an upper limit).
        const double mu = w * r.bias[c] / denominator[c];
        const double sigma = std::sqrt(r.variance[c] * t_var + w * vb) / denominator[c];
        error_sum += expected_abs_error(mu, sigma) + r.sparse[c] / denominator[c];
        const double v = abs_error_variance(mu, sigma);
        pixel_error_sd += std::sqrt(v);
        if (sigma > 0.0 && r.variance[c] > 0.0) {
          // |mu + sigma Z| = m + g sigma He_1(Z) + sum_{k >= 2} c_k sigma He_k(Z) (Hermite),
          // g = erf(mu / sigma sqrt 2): two pixels' |e| whose noises correlate by rho have the
          // covariance sigma sigma' (g g' rho + sum_k k! c_k c_k' rho^k), and for 0 <= rho <= 1
          // the sum is at most rho sqrt(r r') (Cauchy-Schwarz), r = v - g^2 sigma^2 the part of
          // the variance beyond the linear term. The replica's z measures rho: the covariance is
          // bounded by the cross products of g sigma z and sqrt(r) z, exactly so for identical
          // errors (rho = 1), and by rho in place of rho^2 for the noise-dominated (the price of
          // a bound whose every term a replica can measure without its distribution's shape).
          const double g = std::erf(mu / (sigma * std::sqrt(2.0)));
          const double z = r.replica[c] / std::sqrt(r.variance[c]);  // standardised replica
          replica_linear[p] += g * sigma * z;
          replica_rest[p] += std::sqrt(std::max(0.0, v - g * g * sigma * sigma)) * z;
        }
      }
      // A pixel's three channels come from the same photons and paths: their errors are taken
      // as fully correlated (exactly so in a grey scene), so their sd add.
      error_var_sum += pixel_error_sd * pixel_error_sd;
      const dvec3 metric = bound / denominator, bias_metric = glm::abs(r.bias) / denominator;
      bound_sum += metric.x + metric.y + metric.z;
      bias_metric_sum += bias_metric.x + bias_metric.y + bias_metric.z;
      noise_sum += noise.x + noise.y + noise.z;
      bias_sum += std::fabs(r.bias.x) + std::fabs(r.bias.y) + std::fabs(r.bias.z);
      ++known;
      if (s.target > 0.0 && max_component(metric) <= s.target) ++below;
      pixel_bounds[p] = float(max_component(metric));
      if (image)
        for (int c = 0; c < 3; ++c)
          image->target_ratio[3 * p + c] = float(s.target > 0.0 ? metric[c] / s.target : metric[c]);
    } else {
      ++sum.unknown_pixels;
      pixel_bounds[p] = INFINITY;
      if (image)
        for (int c = 0; c < 3; ++c) image->target_ratio[3 * p + c] = INFINITY;
    }
    if (image) {
      for (int c = 0; c < 3; ++c) {
        image->radiance[3 * p + c] = float(r.radiance[c]);
        image->bound[3 * p + c] = float(bound[c]);
        image->bias[3 * p + c] = float(r.bias[c]);
        image->noise[3 * p + c] = known_pixel ? float(noise[c]) : INFINITY;
        image->variance[3 * p + c] = float(r.variance[c]);
      }
      image->photons[p] = float(r.photons);
      image->radius[p] = r.radius;
    }
  }
  if (known > 0) {
    sum.mean_bound = bound_sum / (3.0 * double(known));
    sum.mean_noise = noise_sum / (3.0 * double(known));
    sum.mean_abs_bias = bias_sum / (3.0 * double(known));
    sum.mean_bias_metric = bias_metric_sum / (3.0 * double(known));
  }
  sum.below_target = double(below) / double(std::max<size_t>(pixels, 1));
  if (pixels > 0) {
    const size_t q = std::min(pixels - 1, size_t(std::ceil(s.stop_fraction * double(pixels))) - 1);
    std::nth_element(pixel_bounds.begin(), pixel_bounds.begin() + q, pixel_bounds.end());
    sum.pixel_quantile_bound = pixel_bounds[q];
  }
  if (sum.unknown_pixels == 0 && pixels > 0) {
    // The mean over every pixel-channel, as `compare` takes it (exact pixels add no error).
    // Its variance (section 7): the pixels' own, plus the covariances of neighbours' |e|,
    // bounded by the replicas' cross products over the window their discs can share (2R, plus
    // the jitter); plus the model's: each sigma^2 comes from i - 1 passes, and their mean over
    // the n / K independent groups has relative error 1 / sqrt(2 (i - 1) n / K), which moves
    // the predicted mean by half that.
    const double n = 3.0 * double(pixels);
    double mean_r2 = 0.0;
    for (const PointState& st : states) mean_r2 += st.r2;
    mean_r2 /= double(std::max<size_t>(states.size(), 1));
    const double reach_pixels =
        eye.footprint > 0.0 ? 2.0 * std::sqrt(mean_r2) / eye.footprint + 1.0 : 1.0;
    const int reach =
        int(std::ceil(std::min(reach_pixels, double(std::max(eye.width, eye.height)))));
    const double cross = windowed_cross_sum(replica_linear, eye.width, eye.height, reach) +
                         windowed_cross_sum(replica_rest, eye.width, eye.height, reach);
    const double k = error_var_sum > 0.0 ? 1.0 + cross / error_var_sum : 1.0;
    const double m = error_sum / n;
    const double model = 0.5 * m / std::sqrt(2.0 * nu * std::max(1.0, n / k));
    const double var = k * error_var_sum / (n * n) + model * model;
    sum.correlated_pixels = k;
    sum.predicted_error = m;
    sum.predicted_error_upper = m + normal_quantile(s.confidence) * std::sqrt(var);
  }
  return sum;
}

}  // namespace pb
