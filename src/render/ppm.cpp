#include "render/ppm.h"

#include "util/parallel.h"

#include <algorithm>
#include <atomic>
#include <optional>
#include <string>

namespace pb {

PpmMethod::PpmMethod(const World& world, const PinholeCamera& camera, int max_depth)
    : pass_(run_camera_pass(world, camera, max_depth)) {
  state_count_ = pass_.points.size();
  if (!pass_.glossy.empty()) {
    capped_points_ = pass_.points;
    for (const PointBsdf& g : pass_.glossy) capped_points_[g.point].f *= g.bsdf.max_f(g.wo);
  }
  sums_.resize(std::min(kFoldBlock, state_count_));
  owner_.resize(sums_.size());
  regions_.resize((sums_.size() + kStageChunk - 1) / kStageChunk);
}

void PpmMethod::prepare(const BoundaryIndex& boundary, double initial_radius) {
  boundary_ = &boundary;
  clearance_.resize(pass_.points.size());
  const float r0 = search_radius(initial_radius * initial_radius);
  parallel_for(pass_.points.size(), 4096, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const VisiblePoint& p = pass_.points[k];
      clearance_[k] = boundary.clearance(p.triangle, p.position, r0);
    }
  });
}

bool ppm_pass(const PassInputs& in, std::span<const VisiblePoint> points,
              std::span<const PointBsdf> glossy, std::span<const float> clearance,
              std::span<PointState> states, std::span<float> radii, std::span<PassSums> sums,
              std::span<OwnerValues> owner, PointState* copy, std::span<RegionTable> regions) {
  const size_t n = states.size(), block = sums.size();
  for (size_t first = 0; first < n; first += block) {
    const size_t count = std::min(block, n - first);
    std::atomic<bool> cut{false};
    for_each_chunk(count, [&](size_t b, size_t m) {
      if (cut.load(std::memory_order_relaxed) || in.cut(first)) {
        cut.store(true, std::memory_order_relaxed);
        return;
      }
      const size_t at = first + b;
      if (!in.share.owns(at)) return;  // another rank's
      const std::span<const VisiblePoint> pts = points.subspan(at, m);
      const std::span<const PointState> st = std::span<const PointState>(states).subspan(at, m);
      const PointBsdfTable table{glossy, at};
      std::optional<GuideTally::Chunk> learn;
      if (in.guide.tally) learn.emplace(*in.guide.tally, b / kStageChunk);
      // The discs first: the gather counts the photons of each disc's region (section 11).
      const std::span<OwnerValues> own = owner.subspan(b, m);
      std::fill(own.begin(), own.end(), OwnerValues{});
      RegionTable& chunk_regions = regions[b / kStageChunk];
      disc_pass(pts, st, in.boundary, clearance.empty() ? clearance : clearance.subspan(at, m), own,
                chunk_regions);
      gather_pass(pts, st, in.grid, in.hits, table, &chunk_regions, sums.subspan(b, m),
                  learn ? &*learn : nullptr, in.guide);
      if (in.next_event) next_event_pass(in.world, pts, table, in.seed, in.pass, at, own);
    });
    if (cut.load()) return false;  // the first block: nothing folded yet
    if (in.guide.tally) in.guide.tally->reduce_block((count + kStageChunk - 1) / kStageChunk);
    fold_block(first, states, std::span<const PassSums>(sums).first(count),
               std::span<const OwnerValues>(owner).first(count), in.params, in.pass, radii, copy,
               in.share);
  }
  return true;
}

bool PpmMethod::step(const PassInputs& in, std::span<PointState> states, std::span<float> radii,
                     PointState* copy) {
  return ppm_pass(in, pass_.points, pass_.glossy, clearance_, states, radii, sums_, owner_, copy,
                  regions_);
}

void PpmMethod::restore(const RenderState& s) {
  // PPM keeps no per-pixel side state: a state with one is SPPM's.
  if (!s.visible.empty())
    throw StateError("the state holds " + std::to_string(s.visible.size()) +
                     " SPPM pixel counters but this render has 0");
  if (!s.min_mass.empty())
    throw StateError("the state holds " + std::to_string(s.min_mass.size()) +
                     " SPPM kernel masses but this render has 0");
  if (!s.glossy_f.empty())
    throw StateError("the state holds " + std::to_string(s.glossy_f.size()) +
                     " SPPM glossy caps but this render has 0");
}

PixelLayout PpmMethod::layout(const std::vector<PointState>& states, const RenderState*) const {
  PixelLayout l = layout_of(pass_);
  if (!capped_points_.empty()) l.point_f = colours_of(capped_points_);
  // Each point's disc's kernel mass at the current radius (the sparse-photon bound and the
  // validity of the bias model need it; points within their clearance are whole).
  l.mass.assign(states.size(), 1.0f);
  parallel_for(states.size(), 1024, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const VisiblePoint& p = pass_.points[k];
      const float r = search_radius(states[k].r2);
      if (!clearance_.empty() && r <= clearance_[k]) continue;  // the whole disc: mass 1
      l.mass[k] = float(boundary_->moments(p.triangle, p.position, p.normal, r).mass);
    }
  });
  return l;
}

}  // namespace pb
