// The film's first phase (ESTIMATOR.md sections 5, 6b, 6c, 10, 11b, 11c, 12): every pixel's
// sums of its states, the model checks' counts, and the fourth-order bias shrunk by its prior.
// Internal to film.cpp, which bounds and summarises them.
#pragma once

#include "estimator/film.h"

#include <cstddef>
#include <memory>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace pb {

inline double squared(double x) { return x * x; }

struct PixelResult {
  dvec3 radiance{0.0}, bias{0.0}, variance{0.0};
  dvec3 bias_variance{0.0};  // of the bias estimate (ESTIMATOR.md section 6b)
  // The two scales' fourth-order bias and its variance (section 6c; 0 with --bias-model
  // laplacian), shrunk by a prior of their own: float, since develop() holds every pixel's.
  // Its sd rather than its variance: a float's range holds a bias of 1e30 and its square not.
  vec3 fourth{0.0f}, fourth_sd{0.0f};
  dvec3 sparse{0.0};   // bound of the photon part of states with few photons (section 12)
  dvec3 replica{0.0};  // a replica of the noise (sum_k W_k of the states', section 7)
  // The bias prior tau^2 of the pixel's window (section 6b): the fourth-order part's while
  // shrink_fourth takes it, then the Laplacian's (prior_of), so that a development holds one.
  dvec3 prior{0.0};
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

// ESTIMATOR.md section 12: what bounds one photon's share of an SPPM pixel's pass sample. Its
// Lambertian points: the scene's largest Lambertian f over the smallest kernel mass they had;
// its glossy points: the largest f / c they had (0: none).
struct SppmPhotonCap {
  double photon_cap = 0.0;  // PixelLayout::photon_cap
  vec3 max_f{0.0f};
  float mass = 1.0f;
  float glossy_f = 0.0f;
};
// The sparse-photon term of an SPPM pixel's bound per channel after `passes` passes: 0 with
// kMinPhotonsForBound photons or more, or without a visible point in any pass.
dvec3 sppm_sparse_term(const PointState& s, const SppmPhotonCap& cap, uint64_t visible_passes,
                       uint64_t passes, double confidence);

// Every pixel's PixelResult, each constructed by the thread that computes it (combine_pixels),
// in a block from the development's memory (film.h), given back when done. Fresh pages would
// be faulted in (500 MB at 1920x1080): a std::vector's value-initialisation did so on one
// thread before the threads wrote them again (0.27 s of a 1.1 s development there), and even
// faulted in by the threads themselves they are a fifth of a development.
class PixelResults {
 public:
  PixelResults(size_t n, DevelopMemory* memory)
      : memory_(memory),
        bytes_(n * sizeof(PixelResult)),
        data_(reinterpret_cast<PixelResult*>(
            memory ? memory->take(bytes_) : static_cast<std::byte*>(::operator new(bytes_)))),
        size_(n) {}
  PixelResults(PixelResults&& o) noexcept
      : memory_(o.memory_),
        bytes_(o.bytes_),
        data_(std::exchange(o.data_, nullptr)),
        size_(o.size_) {}
  PixelResults& operator=(PixelResults&&) = delete;
  ~PixelResults() {
    std::byte* block = reinterpret_cast<std::byte*>(data_);
    if (!block) return;
    if (memory_)
      memory_->give(block, bytes_);
    else
      ::operator delete(block);
  }
  size_t size() const { return size_; }
  PixelResult& operator[](size_t i) { return data_[i]; }
  const PixelResult& operator[](size_t i) const { return data_[i]; }
  std::span<PixelResult> all() { return {data_, size_}; }
  std::span<const PixelResult> all() const { return {data_, size_}; }

 private:
  // An aggregate with a trivial destructor: raw storage holds it (each constructed in place),
  // and nothing needs destroying but the storage.
  static_assert(std::is_aggregate_v<PixelResult> && std::is_trivially_destructible_v<PixelResult>);
  static_assert(alignof(PixelResult) <= __STDCPP_DEFAULT_NEW_ALIGNMENT__);
  DevelopMemory* memory_;
  size_t bytes_;
  PixelResult* data_;
  size_t size_;
};

// ESTIMATOR.md sections 5 and 10: every pixel's sums of its states.
// The results' block comes from `memory` (may be null).
PixelResults combine_pixels(const PixelLayout& layout, const std::vector<PointState>& states,
                            uint64_t passes, const FilmSettings& s, DevelopMemory* memory);
// ESTIMATOR.md section 7: the relative metric's floor, from the image's mean radiance.
double relative_floor(std::span<const PixelResult> results);
// ESTIMATOR.md sections 11b and 11c: the shares of disagreeing states, and whether they refute.
void check_model(std::span<const PixelResult> results, FilmSummary& sum);
// ESTIMATOR.md section 6b: the bias prior over the known pixels with a random state, into
// each pixel's `prior`. `floor`: the pixels whose windows take the floor of their own estimate
// (empty: none).
void prior_of(std::span<PixelResult> results, int width, int height,
              std::span<const uint8_t> floor);
// ESTIMATOR.md section 6c: each pixel's fourth-order part shrunk in place by its own prior
// (which it leaves in `prior`, for prior_of to replace).
void shrink_fourth(std::span<PixelResult> results, int width, int height,
                   std::span<const uint8_t> floor);

}  // namespace pb
