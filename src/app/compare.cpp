#include "app/compare.h"

#include "estimator/channels.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace pb {

namespace {

int require(const ExrImage& img, const std::string& channel, const std::string& name) {
  const int c = img.channel_index(channel);
  if (c < 0) throw ImageError(name + ": has no channel " + channel);
  return c;
}

}  // namespace

CompareResult compare_images(const ExrImage& a, const ExrImage& ref, const std::string& a_name,
                             const std::string& ref_name) {
  if (a.width != ref.width || a.height != ref.height)
    throw ImageError(a_name + " is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                     " but " + ref_name + " is " + std::to_string(ref.width) + "x" +
                     std::to_string(ref.height) + ": images of different sizes cannot be compared");
  int l[3], lr[3], eb[3], bias[3], noise[3];
  for (int c = 0; c < 3; ++c) {
    l[c] = require(a, channel_name(Channel::Radiance, c), a_name);
    lr[c] = require(ref, channel_name(Channel::Radiance, c), ref_name);
    eb[c] = require(a, channel_name(Channel::ErrorBound, c), a_name);
    bias[c] = require(a, channel_name(Channel::Bias, c), a_name);
    noise[c] = require(a, channel_name(Channel::Noise, c), a_name);
  }
  CompareResult r;
  r.width = a.width;
  r.height = a.height;
  const size_t pixels = size_t(a.width) * size_t(a.height);
  const size_t na = a.channels.size(), nr = ref.channels.size();
  double abs_sum = 0.0, sq_sum = 0.0, bound_sum = 0.0, bounded_err = 0.0;
  uint64_t covered = 0, bounded_pixels = 0, bias_pixels = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const float* pa = &a.pixels[p * na];
    const float* pr = &ref.pixels[p * nr];
    double b_sum = 0.0, n_sum = 0.0;
    bool pixel_bounded = false;
    for (int c = 0; c < 3; ++c) {
      const double err = std::fabs(double(pa[l[c]]) - double(pr[lr[c]]));
      abs_sum += err;
      sq_sum += err * err;
      const double bound = pa[eb[c]];
      if (bound == 0.0) {
        ++r.exact;
      } else if (!std::isfinite(bound)) {
        ++r.unknown;
      } else {
        ++r.bounded;
        covered += err <= bound;
        bound_sum += bound;
        bounded_err += err;
        pixel_bounded = true;
        b_sum += std::fabs(double(pa[bias[c]]));
        n_sum += double(pa[noise[c]]);
      }
    }
    if (pixel_bounded) {
      ++bounded_pixels;
      bias_pixels += b_sum > n_sum;
    }
  }
  const double n = 3.0 * double(pixels);
  r.mean_abs_error = pixels ? abs_sum / n : 0.0;
  r.rmse = pixels ? std::sqrt(sq_sum / n) : 0.0;
  if (r.bounded) {
    r.coverage = double(covered) / double(r.bounded);
    r.mean_bound = bound_sum / double(r.bounded);
    r.mean_bounded_error = bounded_err / double(r.bounded);
    r.bound_over_error =
        r.mean_bounded_error > 0.0 ? r.mean_bound / r.mean_bounded_error : INFINITY;
    r.bias_dominated = double(bias_pixels) / double(bounded_pixels);
  }
  return r;
}

std::string to_json(const CompareResult& r) {
  std::ostringstream s;
  s.precision(10);
  // JSON has no NaN or infinity: a non-finite number is null (docs/usage.md "compare and
  // preview").
  auto num = [](double v) {
    if (!std::isfinite(v)) return std::string("null");
    std::ostringstream t;
    t.precision(10);
    t << v;
    return t.str();
  };
  s << "{\"width\": " << r.width << ", \"height\": " << r.height
    << ", \"mean_abs_error\": " << num(r.mean_abs_error) << ", \"rmse\": " << num(r.rmse)
    << ", \"coverage\": " << num(r.coverage) << ", \"mean_bound\": " << num(r.mean_bound)
    << ", \"mean_bounded_error\": " << num(r.mean_bounded_error)
    << ", \"bound_over_error\": " << num(r.bound_over_error)
    << ", \"bias_dominated\": " << num(r.bias_dominated) << ", \"bounded\": " << r.bounded
    << ", \"exact\": " << r.exact << ", \"unknown\": " << r.unknown << "}\n";
  return s.str();
}

std::string to_text(const CompareResult& r) {
  std::ostringstream s;
  s.precision(6);
  s << "size                    " << r.width << "x" << r.height << "\n"
    << "mean absolute error     " << r.mean_abs_error << "\n"
    << "RMSE                    " << r.rmse << "\n"
    << "coverage                " << r.coverage << "  (|L - L_ref| <= ErrorBound, over "
    << r.bounded << " bounded pixel-channels)\n"
    << "mean bound / mean error " << r.bound_over_error << "  (" << r.mean_bound << " / "
    << r.mean_bounded_error << ")\n"
    << "bias-dominated pixels   " << r.bias_dominated << "\n"
    << "exact / unknown         " << r.exact << " / " << r.unknown << " pixel-channels\n";
  return s.str();
}

std::optional<std::string> exposure_warning(std::vector<float> levels, double exposure,
                                            const std::string& image) {
  std::erase_if(levels, [](float v) { return !std::isfinite(v); });
  if (levels.empty()) return std::nullopt;
  const double scale = std::exp2(exposure);
  auto quantile = [&](double q) {
    const size_t k = std::min(levels.size() - 1, size_t(q * double(levels.size())));
    std::nth_element(levels.begin(), levels.begin() + std::ptrdiff_t(k), levels.end());
    return double(levels[k]);
  };
  const size_t white = size_t(std::count_if(levels.begin(), levels.end(),
                                            [&](float v) { return double(v) * scale > 1.0; }));
  const double share = double(white) / double(levels.size());
  const double p99 = quantile(0.99), p90 = quantile(0.90);
  char what[160];
  if (share >= 0.1) {
    std::snprintf(what, sizeof what, "%.0f%% of the pixels are white", 100.0 * share);
  } else if (p99 * scale < 0.003) {
    std::snprintf(what, sizeof what, "99%% of the pixels are black (below %.3g)", 0.003 / scale);
  } else {
    return std::nullopt;
  }
  std::ostringstream line;
  line << "photonbound: warning: preview of " << image << ": " << what << " at --exposure "
       << exposure;
  if (p90 > 0.0) {
    // Half-stops: the 90th percentile at 0.5 (sRGB 188/255).
    const double advice = std::round(2.0 * std::log2(0.5 / p90)) / 2.0;
    line << "; --exposure " << advice << " shows them";
  } else {
    line << "; 90% of the pixels are 0, which no exposure shows";
  }
  return line.str();
}

}  // namespace pb
