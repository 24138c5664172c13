// `photonbound compare`: how a render's actual error relates to its own error bounds, against a
// reference image (ESTIMATOR.md section 7: both reported as means over pixels and channels).
#pragma once

#include "io/image_io.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pb {

struct CompareResult {
  int width = 0, height = 0;
  double mean_abs_error = 0.0;  // over all pixels and RGB channels
  double rmse = 0.0;
  // Over pixel-channels with a finite, positive bound (not exact, not unknown):
  uint64_t bounded = 0;
  double coverage = 0.0;  // fraction with |L - L_ref| <= ErrorBound
  double mean_bound = 0.0;
  double mean_bounded_error = 0.0;
  double bound_over_error = 0.0;  // mean_bound / mean_bounded_error
  uint64_t exact = 0;             // pixel-channels with bound 0 (background, exact emission)
  uint64_t unknown = 0;           // pixel-channels with an infinite bound
  double bias_dominated =
      0.0;  // fraction of bounded pixels whose |bias| exceeds the noise half-width
};

// Throws ImageError when the sizes differ or a needed channel is missing.
CompareResult compare_images(const ExrImage& render, const ExrImage& reference,
                             const std::string& render_name, const std::string& reference_name);

// preview's word on a picture that shows nothing (docs/usage.md "preview"): given each pixel's
// largest radiance channel and the exposure, a one-line warning when at least 10% of the pixels
// clip to white (above 1), or when 99% of them are darker than 1% grey (0.003 linear, sRGB 11/255),
// with the --exposure that puts the 90th percentile at 0.5; nothing when the picture shows
// something.
std::optional<std::string> exposure_warning(std::vector<float> levels, double exposure,
                                            const std::string& image);

std::string to_json(const CompareResult& r);
std::string to_text(const CompareResult& r);

}  // namespace pb
