#include "render/photon_guide.h"

#include <algorithm>
#include <stdexcept>

namespace pb {

namespace {

// The largest float below 1: a warped number stays in [0, 1) as an Rng's does.
constexpr float kBelowOne = 0x1.fffffep-1f;

float in_bin(uint32_t bin, float u, uint32_t bins) {
  return std::min((float(bin) + u) / float(bins), kBelowOne);
}

uint32_t bin_of(float u, uint32_t bins) { return std::min(uint32_t(u * float(bins)), bins - 1); }

}  // namespace

EmissionGuide::EmissionGuide(size_t emitters) {
  pick_bins_ = uint32_t(std::clamp<size_t>(emitters, 1, 16));
  dir_bins_ = pick_bins_ == 1 ? 64 : pick_bins_ <= 4 ? 32 : 16;
  mean_.assign(cells(), 0.0);
  rebuild();
}

void EmissionGuide::rebuild() {
  const size_t n = cells();
  cdf_.assign(n + 1, 0.0);
  density_.assign(n, 1.0f);
  double total = 0.0;
  for (double v : mean_) total += v;
  const bool learnt = learnt_ > 0 && total > 0.0;
  for (size_t c = 0; c < n; ++c) {
    // q_c = (1 - m) h_c + m / cells (section 14): the mixture with power-proportional emission.
    const double q = learnt ? (1.0 - kUniformShare) * mean_[c] / total + kUniformShare / double(n)
                            : 1.0 / double(n);
    cdf_[c + 1] = cdf_[c] + q;
    density_[c] = float(q * double(n));
  }
  // The last entry is 1 up to rounding; the search below treats it as the end.
  cdf_[n] = std::max(cdf_[n], 1.0);
  start_.assign(n, 0);
  size_t c = 0;
  for (size_t k = 0; k < n; ++k) {
    const double at = double(k) / double(n);
    while (c + 1 < n && cdf_[c + 1] <= at) ++c;
    start_[k] = uint32_t(c);
  }
}

uint32_t EmissionGuide::warp(float u_cell, PrimarySample& u, const Lights& lights,
                             float& density) const {
  if (!guiding()) {
    density = 1.0f;
    const int pair = lights.direction_pair(u.u[0]);
    return (bin_of(u.u[0], pick_bins_) * dir_bins_ + bin_of(u.u[pair], dir_bins_)) * dir_bins_ +
           bin_of(u.u[pair + 1], dir_bins_);
  }
  // The cell c with cdf_[c] <= u < cdf_[c + 1], scanned from its cutpoint.
  const size_t n = cells();
  const double x = double(u_cell);
  uint32_t cell = start_[std::min(size_t(x * double(n)), n - 1)];
  while (cell + 1 < n && cdf_[cell + 1] <= x) ++cell;
  const uint32_t j = cell % dir_bins_, i = (cell / dir_bins_) % dir_bins_;
  const uint32_t a = cell / (dir_bins_ * dir_bins_);
  u.u[0] = in_bin(a, u.u[0], pick_bins_);
  const int pair = lights.direction_pair(u.u[0]);
  u.u[pair] = in_bin(i, u.u[pair], dir_bins_);
  u.u[pair + 1] = in_bin(j, u.u[pair + 1], dir_bins_);
  density = density_[cell];
  return cell;
}

void EmissionGuide::learn(std::span<const double> pass_sums) {
  if (pass_sums.size() != mean_.size()) throw std::invalid_argument("guide: wrong cell count");
  double total = 0.0;
  for (double v : pass_sums) total += v;
  if (!(total > 0.0) || !std::isfinite(total)) return;
  ++learnt_;
  const double blend = std::max(1.0 / double(learnt_), kMinBlend);
  for (size_t c = 0; c < mean_.size(); ++c)
    mean_[c] = (1.0 - blend) * mean_[c] + blend * pass_sums[c] / total;
  rebuild();
}

double EmissionGuide::max_weight() const {
  float lo = 1.0f;
  for (float d : density_) lo = std::min(lo, d);
  return 1.0 / double(lo);
}

void EmissionGuide::restore(std::vector<double> histogram, uint64_t learnt) {
  if (histogram.size() != mean_.size())
    throw std::invalid_argument("the state's photon guide has " + std::to_string(histogram.size()) +
                                " cells, this render's " + std::to_string(mean_.size()));
  mean_ = std::move(histogram);
  learnt_ = learnt;
  rebuild();
}

GuideTally::Chunk::Chunk(GuideTally& tally, size_t index)
    : scratch_([&]() -> std::vector<double>& {
        thread_local std::vector<double> s;
        if (s.size() < tally.cells_) s.resize(tally.cells_, 0.0);
        return s;
      }()),
      touched_([]() -> std::vector<uint32_t>& {
        thread_local std::vector<uint32_t> t;
        return t;
      }()),
      list_(tally.lists_.at(index)) {
  touched_.clear();
  list_.clear();
}

GuideTally::Chunk::~Chunk() {
  for (uint32_t c : touched_) {
    if (scratch_[c] == 0.0) continue;  // already moved (a cell touched twice)
    list_.emplace_back(c, scratch_[c]);
    scratch_[c] = 0.0;
  }
  touched_.clear();
}

void GuideTally::begin_pass(size_t cells, size_t chunks) {
  cells_ = cells;
  sums_.assign(cells, 0.0);
  if (lists_.size() < chunks) lists_.resize(chunks);
  for (auto& l : lists_) l.clear();
}

void GuideTally::reduce_block(size_t chunks) {
  for (size_t k = 0; k < chunks && k < lists_.size(); ++k) {
    for (const auto& [cell, v] : lists_[k]) sums_[cell] += v;
    lists_[k].clear();
  }
}

}  // namespace pb
