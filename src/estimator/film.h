// Per-pixel radiance and error bounds from the per-point statistics (ESTIMATOR.md sections 5-7).
#pragma once

#include "estimator/channels.h"
#include "estimator/error_model.h"
#include "estimator/estimator.h"
#include "util/math.h"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <span>
#include <string>
#include <vector>

namespace pb {

// Planar float images, RGB channels interleaved per pixel (3 floats), scalars one per pixel.
struct FilmImage {
  int width = 0, height = 0;
  std::vector<float> radiance;      // L_pix
  std::vector<float> bound;         // Eb_pix at the chosen confidence; +inf where unknown
  std::vector<float> bias;          // B_pix, signed
  std::vector<float> noise;         // noise half-width t sqrt(Var_pix)
  std::vector<float> variance;      // Var_pix: variance of the mean
  std::vector<float> photons;       // photons gathered by the pixel's points
  std::vector<float> radius;        // current radius of the pixel's first point (0 if none)
  std::vector<float> target_ratio;  // bound over the target in the metric (over 1 without one)

  // The plane of an EXR channel group (channels.def): 3 floats per pixel for RGB groups.
  const std::vector<float>& plane(Channel id) const;
};

struct FilmSummary {
  double mean_bound = INFINITY;  // over known pixels and RGB channels, in the chosen metric
  double mean_noise = 0.0;       // mean noise half-width (absolute)
  double mean_abs_bias = 0.0;    // mean |B| (absolute)
  double mean_bias_metric =
      0.0;  // mean |B| in the chosen metric: the part of the bound the noise cannot shrink
  double below_target = 0.0;    // fraction of pixels whose every channel's bound meets the target
  uint64_t unknown_pixels = 0;  // pixels with a state whose bound is unknown (section 7)
  uint64_t pixels = 0;          // the image's pixels
  double relative_floor = 0.0;  // denominator floor of the relative metric
  // The image's mean absolute error over pixels and channels (what `compare` reports), in the
  // chosen metric, as the error model predicts it, and its upper confidence limit at the
  // settings' confidence (ESTIMATOR.md section 7); +inf while a pixel is unknown.
  double predicted_error = INFINITY;
  double predicted_error_upper = INFINITY;
  // The pixels whose errors move with a pixel's, in effect, measured from the noise replicas:
  // the variance of the mean error is K times the independent pixels' (section 7).
  double correlated_pixels = 1.0;
  // The settings' quantile (stop_fraction) of the pixels' bounds (largest channel, in the
  // metric): at most the target exactly when that share of the pixels is within it.
  double pixel_quantile_bound = INFINITY;
  // The model checks (ESTIMATOR.md sections 11b, 11c): the share of state-channels whose
  // regression slope on R^2 and Laplacian slope disagree, the share of states whose two kernel
  // scales disagree, and whether either share refutes the second-order bias model (every pixel
  // with a random state is then unknown).
  double slope_disagreement = 0.0;
  double scale_disagreement = 0.0;
  bool model_refuted = false;
};

struct FilmSettings {
  double photons_per_pass = 1.0;
  double confidence = 0.9;
  ErrorMetric metric = ErrorMetric::Absolute;
  double target = 0.0;         // 0 = no target
  double stop_fraction = 0.9;  // the share of pixels pixel_quantile_bound is taken at
  BiasModel bias_model = BiasModel::TwoScale;
};

// Each PPM point's W_k f (render/camera_pass.h, VisiblePoint::f) read in place from the
// points' array by its stride, so that this layer need not know the point's layout.
struct StridedColours {
  const unsigned char* first = nullptr;
  size_t stride = 0, count = 0;
  bool empty() const { return count == 0; }
  vec3 operator[](size_t k) const {
    vec3 v;
    std::memcpy(&v, first + k * stride, sizeof v);
    return v;
  }
};

// Which states make up each pixel (ESTIMATOR.md sections 5 and 10): PPM's visible points,
// grouped by pixel, plus the emission its camera rays see exactly; or SPPM's one state per
// pixel (pixel_begin and emission empty) with the passes in which the pixel had a visible point.
struct PixelLayout {
  int width = 0, height = 0;
  std::span<const uint32_t> pixel_begin;     // empty: state p is pixel p
  std::span<const dvec3> emission;           // empty: no light outside the states
  std::span<const uint32_t> visible_passes;  // SPPM: per pixel
  // For states with few photons (ESTIMATOR.md section 12): w(0) Phi_max / M_e, which with the
  // state's f and 1 / (c pi R^2) is the most one photon adds to a pass sample; the states'
  // BRDF (PPM: each point's f; SPPM: the largest a visible point can have) and kernel mass c.
  double photon_cap = 0.0;
  StridedColours point_f;           // PPM
  vec3 max_f{0.0f};                 // SPPM
  std::span<const float> glossy_f;  // SPPM: per pixel, glossy points' largest f / c (empty: none)
  std::vector<float> mass;          // per state; empty: 1
  double footprint = 0.0;  // median pixel footprint at the points (the errors' correlation)
  // SPPM, --adaptive paths: per pixel, 1 where it has had more than one camera path in a pass
  // (section 15); the bias priors' floor acts in their windows (section 6b). Empty without
  // paths (PPM, or SPPM without --adaptive paths).
  std::vector<uint8_t> paths_taken;
};
// The memory one development leaves to the next: its per-pixel results (250 bytes a pixel,
// 500 MB at 1920x1080), which a development of fresh memory faults in page by page (a fifth of
// its time there). A stop test develops every few passes, so the block is kept between them;
// release() frees it (before an EXR is packed, which would otherwise hold both). Two developments
// at once (a checkpoint's beside a stop test's): one takes the block, the other allocates.
class DevelopMemory {
 public:
  DevelopMemory() = default;
  ~DevelopMemory() { release(); }
  DevelopMemory(const DevelopMemory&) = delete;
  DevelopMemory& operator=(const DevelopMemory&) = delete;
  // At least `bytes`: the kept block when it is large enough (then no longer kept), else a new
  // one (operator new's alignment).
  std::byte* take(size_t bytes);
  // Keeps `block` (of `bytes`, from take()) in place of a smaller one, frees the other.
  void give(std::byte* block, size_t bytes);
  void release();

 private:
  std::mutex mutex_;
  std::byte* block_ = nullptr;
  size_t bytes_ = 0;
};

// Combines the states of every pixel. With passes < 2 no bound exists: every pixel with
// a state that is random is unknown. `memory`: where the results' block is taken from and left
// (none: allocated and freed here).
FilmSummary develop(const PixelLayout& layout, const std::vector<PointState>& states,
                    uint64_t passes, const FilmSettings& settings, FilmImage* image,
                    DevelopMemory* memory = nullptr);

// The relative metric divides by max(L, floor) with floor = kRelativeFloor x mean radiance of
// the image, so that dark pixels do not dominate the mean.
inline constexpr double kRelativeFloor = 0.01;

}  // namespace pb
