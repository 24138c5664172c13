#include "estimator/film_pixels.h"

#include "estimator/error_model.h"
#include "util/parallel.h"

#include <cmath>

namespace pb {

namespace {

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
// `photon_cap`: PixelLayout::photon_cap.
dvec3 sparse_term(double photon_cap, const PointState& s, const dvec3& f_over_c,
                  uint64_t passes_with_point, double confidence) {
  if (s.photons >= kMinPhotonsForBound || !(photon_cap > 0.0)) return dvec3(0.0);
  dvec3 out;
  for (int ch = 0; ch < 3; ++ch)
    out[ch] = sparse_photon_bound(s.photons, passes_with_point,
                                  photon_cap * f_over_c[ch] / (kPiD * s.r2), confidence);
  return out;
}

}  // namespace

dvec3 sppm_sparse_term(const PointState& s, const SppmPhotonCap& cap, uint64_t visible_passes,
                       uint64_t passes, double confidence) {
  if (visible_passes == 0) return dvec3(0.0);
  // Lambertian points: the scene's largest Lambertian f over the pixel's smallest c; glossy
  // points: the largest f / c any of them had.
  const dvec3 f_over_c = glm::max(dvec3(cap.max_f) / std::max(double(cap.mass), kMinKernelMass),
                                  dvec3(double(cap.glossy_f)));
  // The pixel's estimate averages its samples over every pass, and a pass without a visible
  // point has no photon part: the photon part's mean is at most k_v lambda_u / i times a
  // photon's cap, with lambda_u the bound per visible pass (n photons in k_v such passes), so
  // chi^2 / (2 i) times the cap, over all i passes (ESTIMATOR.md section 12).
  return sparse_term(cap.photon_cap, s, f_over_c, passes, confidence);
}

namespace {

double kernel_mass(const PixelLayout& layout, size_t k) {
  return layout.mass.empty() ? 1.0 : std::max(double(layout.mass[k]), kMinKernelMass);
}

// Section 6c: a state's fourth-order bias into the pixel's, unless --bias-model laplacian.
void add_fourth(PixelResult& r, const PointEstimate& e, BiasModel model) {
  if (model != BiasModel::TwoScale) return;
  r.fourth += vec3(e.fourth);
  for (int c = 0; c < 3; ++c)
    r.fourth_sd[c] = float(std::sqrt(squared(double(r.fourth_sd[c])) + e.fourth_variance[c]));
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
    const SppmPhotonCap cap{layout.photon_cap, layout.max_f,
                            layout.mass.empty() ? 1.0f : layout.mass[pixel],
                            layout.glossy_f.empty() ? 0.0f : layout.glossy_f[pixel]};
    r.sparse = sppm_sparse_term(states[pixel], cap, visible, passes, confidence);
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
      r.sparse +=
          sparse_term(layout.photon_cap, states[k],
                      dvec3(layout.point_f[k]) / kernel_mass(layout, k), passes, confidence);
    r.known = r.known && passes >= 2 && (e.known || layout.photon_cap > 0.0) &&
              (layout.mass.empty() || layout.mass[k] >= kValidKernelMass);
  }
  return r;
}

}  // namespace

// ESTIMATOR.md sections 5 and 10: every pixel's sums of its states.
PixelResults combine_pixels(const PixelLayout& layout, const std::vector<PointState>& states,
                            uint64_t passes, const FilmSettings& s, DevelopMemory* memory) {
  const size_t pixels = size_t(layout.width) * size_t(layout.height);
  PixelResults results(pixels, memory);
  parallel_for(pixels, 1024, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      ::new (&results[p]) PixelResult(combine(layout, states, p, passes, s));
  });
  return results;
}

// ESTIMATOR.md section 7: the relative metric's floor, from the image's mean radiance.
double relative_floor(std::span<const PixelResult> results) {
  double mean_radiance = 0.0;
  for (const PixelResult& r : results)
    mean_radiance += (r.radiance.x + r.radiance.y + r.radiance.z);
  mean_radiance /= 3.0 * double(std::max<size_t>(results.size(), 1));
  return kRelativeFloor * mean_radiance;
}

// ESTIMATOR.md sections 11b and 11c: where the samples' drift with R^2 and the Laplacian
// disagree in more than kRefutedShare of the state-channels, or the two scales in more than
// that share of the states, no bound of this image can be trusted.
void check_model(std::span<const PixelResult> results, FilmSummary& sum) {
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

// ESTIMATOR.md section 6b: the bias prior over the known pixels with a random state. It reads
// the bias and writes the prior: other members of the same results.
void prior_of(std::span<PixelResult> results, int width, int height,
              std::span<const uint8_t> floor) {
  bias_prior(
      [&](size_t p) {
        const PixelResult& r = results[p];
        return BiasEstimate{r.bias, r.bias_variance, r.known && !r.exact};
      },
      width, height, 1.0, floor, [&](size_t p, const dvec3& tau2) { results[p].prior = tau2; });
}

// ESTIMATOR.md section 6c: the fourth-order part shrunk by a prior of its own (over the same
// window), in place: each pixel keeps w4 B4 and sqrt(w4 V4). Where it is noise (a smooth radiance,
// tau4 ~ 0) it then neither moves the bias nor dilutes the Laplacian's. Done before the
// second-order prior, whose place in each result it takes until then.
void shrink_fourth(std::span<PixelResult> results, int width, int height,
                   std::span<const uint8_t> floor) {
  bias_prior(
      [&](size_t p) {
        const PixelResult& r = results[p];
        const dvec3 sd(r.fourth_sd);
        return BiasEstimate{dvec3(r.fourth), sd * sd, r.known && !r.exact};
      },
      width, height, kFourthNoiseFactor, floor,
      [&](size_t p, const dvec3& tau4) { results[p].prior = tau4; });
  parallel_for(results.size(), 4096, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      for (int c = 0; c < 3; ++c) {
        PixelResult& r = results[p];
        const double w4 =
            r.fourth[c] == 0.0f ? 0.0 : bias_shrinkage(r.prior[c], squared(double(r.fourth_sd[c])));
        r.fourth[c] = float(r.fourth[c] * w4);
        r.fourth_sd[c] = float(r.fourth_sd[c] * std::sqrt(w4));
      }
  });
}

}  // namespace pb
