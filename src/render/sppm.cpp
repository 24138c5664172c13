#include "render/sppm.h"

#include "estimator/film_pixels.h"
#include "estimator/path_mean.h"

#include <algorithm>
#include <atomic>
#include <optional>
#include <string>

namespace pb {

namespace {

// f / c of a glossy visible point of kernel mass `mass`: one photon adds at most
// w(0) f Phi_max / (c pi R^2 M_e) to the pass sample (ESTIMATOR.md section 12).
float glossy_ratio(const VisiblePoint& point, const PointBsdf& g, double mass) {
  return float(max_component(point.f * g.bsdf.max_f(g.wo)) / std::max(mass, kMinKernelMass));
}

}  // namespace

SppmMethod::SppmMethod(const World& world, const PinholeCamera& camera, CameraPathSettings settings)
    : camera_(camera), settings_(settings) {
  // SPPM keeps no points: the default radius comes from the footprints of a sample of
  // pixel-centre paths (every 4th pixel each way).
  pass_.width = camera.width();
  pass_.height = camera.height();
  pass_.median_footprint = median_footprint(world, camera, settings.max_depth, 4);
  state_count_ = size_t(pass_.width) * size_t(pass_.height);
  visible_.assign(state_count_, 0);
  min_mass_.assign(state_count_, 1.0f);
  glossy_f_.assign(state_count_, 0.0f);
  // The largest BRDF of any Lambertian surface a visible point can lie on (the sparse-photon
  // bound); glossy points bound theirs with Bsdf::max_f (glossy_f_).
  const vec3 up(0.0f, 0.0f, 1.0f);
  for (const Material& m : world.scene().materials)
    if (Bsdf(m, up, up, world.mirror_roughness()).is_lambertian())
      max_f_ = glm::max(max_f_, lambertian(m.base_color));
  const size_t block = std::min(kFoldBlock, state_count_);
  points_.resize(block);
  glossy_.resize(block);
  sums_.resize(block);
  owner_.resize(block);
  glossy_count_.resize((block + kStageChunk - 1) / kStageChunk);
  regions_.resize(glossy_count_.size());
  if (settings.adaptive_paths) {
    paths_.assign(state_count_, 1);
    history_.assign(state_count_, PathHistory{});
    extra_.resize(block);
  }
}

bool SppmMethod::step(const PassInputs& in, std::span<PointState> states, std::span<float> radii,
                      PointState* copy) {
  const CameraPathInputs camera{in.world, camera_, settings_.max_depth, settings_.follow_roughness,
                                in.seed,  in.pass, in.next_event,       in.boundary};
  const size_t n = states.size(), block = sums_.size();
  // The paths of this pass, from the states of the passes before it (section 15).
  if (settings_.adaptive_paths) {
    PathCosts costs;
    costs.rays_per_photon = in.rays_per_photon;
    const uint64_t done = in.pass - 1;
    std::vector<PathVariance>& v = path_scratch_.variance;
    v.resize(n);
    if (done >= kPathsMinPasses) {
      // Each pixel's variances by the rank that owns its state (the others' are stale there),
      // then every rank has them all and allocates alike.
      for_each_chunk(n, [&](size_t at, size_t m) {
        if (!in.share.owns(at)) return;
        for (size_t p = at; p < at + m; ++p) {
          v[p] = path_variance(states[p], done, in.params.photons_per_pass, history_[p], costs);
          const SppmPhotonCap cap{in.photon_cap, max_f_, min_mass_[p], glossy_f_[p]};
          v[p].settled += float(sparse_at_horizon(
              states[p], sppm_sparse_term(states[p], cap, visible_[p], done, kPathsConfidence)));
        }
      });
      if (in.exchange) in.exchange->share_owned(v.data(), sizeof(PathVariance), n, true);
    }
    choose_paths(v, done, in.params.photons_per_pass, costs, paths_, path_scratch_);
  }
  for (size_t first = 0; first < n; first += block) {
    const size_t count = std::min(block, n - first);
    // Stages 0, 3 and 4 chunk by chunk, so that a chunk's visible points are still in cache.
    std::atomic<bool> cut{false};
    for_each_chunk(count, [&](size_t b, size_t m) {
      if (cut.load(std::memory_order_relaxed) || in.cut(first)) {
        cut.store(true, std::memory_order_relaxed);
        return;
      }
      const size_t at = first + b;
      if (!in.share.owns(at)) return;  // another rank's pixels
      const std::span<VisiblePoint> pts = std::span(points_).subspan(b, m);
      const std::span<OwnerValues> own = std::span(owner_).subspan(b, m);
      const std::span<PointBsdf> scratch = std::span(glossy_).subspan(b, m);
      const std::span<const PointState> st = std::span<const PointState>(states).subspan(at, m);
      RegionTable& regions = regions_[b / kStageChunk];
      const size_t n_glossy = trace_visible_points(
          camera, at, std::span<const float>(radii).subspan(at, m), pts, scratch, own, regions);
      const PointBsdfTable table{scratch.first(n_glossy), 0};  // indices into pts
      std::optional<GuideTally::Chunk> learn;
      if (in.guide.tally) learn.emplace(*in.guide.tally, b / kStageChunk);
      gather_pass(pts, st, in.grid, in.hits, table, &regions, std::span(sums_).subspan(b, m),
                  learn ? &*learn : nullptr, in.guide);
      if (in.next_event) next_event_pass(in.world, pts, table, in.seed, in.pass, at, own);
      if (settings_.adaptive_paths) extra_paths(in, camera, at, b, m, st, radii);
      glossy_count_[b / kStageChunk] = uint32_t(n_glossy);
    });
    if (cut.load()) return false;  // the first block: nothing recorded or folded yet
    if (in.guide.tally) in.guide.tally->reduce_block((count + kStageChunk - 1) / kStageChunk);
    // The pixels' side state, once the pass is known to go on (a chunk writes its own pixels).
    for_each_chunk(count, [&](size_t b, size_t m) {
      if (!in.share.owns(first + b)) return;
      if (settings_.adaptive_paths)
        for (size_t k = b; k < b + m; ++k) {
          const size_t pixel = first + k;
          const ExtraPaths& e = extra_[k];
          PathHistory& h = history_[pixel];
          h.inv_paths += 1.0f / float(paths_[pixel]);
          if (!e.combined) continue;
          h.spread += e.spread;
          h.dof += float(paths_[pixel] - 1);
          min_mass_[pixel] = std::min(min_mass_[pixel], e.mass);
          glossy_f_[pixel] = std::max(glossy_f_[pixel], e.ratio);
        }
      const std::span<const ExtraPaths> extra =
          settings_.adaptive_paths ? std::span<const ExtraPaths>(extra_).subspan(b, m)
                                   : std::span<const ExtraPaths>();
      record_visible(first + b, std::span(points_).subspan(b, m), std::span(owner_).subspan(b, m),
                     std::span(glossy_).subspan(b, glossy_count_[b / kStageChunk]),
                     std::span<const PointState>(states).subspan(first + b, m), extra);
    });
    fold_block(first, states, std::span<const PassSums>(sums_).first(count),
               std::span<const OwnerValues>(owner_).first(count), in.params, in.pass, radii, copy,
               in.share);
  }
  return true;
}

void SppmMethod::record_visible(size_t first, std::span<const VisiblePoint> points,
                                std::span<const OwnerValues> owner,
                                std::span<const PointBsdf> glossy,
                                std::span<const PointState> states,
                                std::span<const ExtraPaths> extra) {
  // The first path's kernel mass: a pixel of several paths folds a synthetic disc (PathMean).
  const auto mass = [&](size_t k) {
    return !extra.empty() && extra[k].combined ? double(extra[k].primary_mass) : owner[k].disc.mass;
  };
  for (size_t k = 0; k < points.size(); ++k) {
    if (!(max_component(points[k].f) > 0.0f)) continue;
    const size_t pixel = first + k;
    if (visible_[pixel] != UINT32_MAX) ++visible_[pixel];  // saturating: far beyond use
    min_mass_[pixel] = std::min(min_mass_[pixel], float(mass(k)));
  }
  for (const PointBsdf& g : glossy) {  // only while the cap can still matter
    if (states[g.point].photons >= kMinPhotonsForBound) continue;
    // f / c of this pass's point: one photon adds at most w(0) f Phi_max / (c pi R^2 M_e) to
    // this pass's sample, so the largest ratio over the passes bounds every pass, where the
    // largest f and the smallest c, often of different points (a grazing view; a disc over a
    // crease), bound them up to 10-100 times looser (ESTIMATOR.md section 12).
    float& cap = glossy_f_[first + g.point];
    cap = std::max(cap, glossy_ratio(points[g.point], g, mass(g.point)));
  }
}

void SppmMethod::extra_paths(const PassInputs& in, const CameraPathInputs& camera, size_t at,
                             size_t b, size_t m, std::span<const PointState> states,
                             std::span<const float> radii) {
  DiscRegion region;  // of each extra path's disc when it is not whole
  for (size_t k = 0; k < m; ++k) {
    const size_t pixel = at + k;
    ExtraPaths& e = extra_[b + k];
    e = ExtraPaths{};
    const uint32_t paths = paths_[pixel];
    if (paths <= 1) continue;
    const double r2 = states[k].r2;
    e.combined = true;
    e.primary_mass = float(owner_[b + k].disc.mass);
    PathMean mean;
    const double m_e = in.params.photons_per_pass;
    mean.add(sums_[b + k], owner_[b + k], r2, m_e);
    for (uint32_t t = 1; t < paths; ++t) {
      VisiblePoint p;
      OwnerValues o;
      PassSums g;
      const std::optional<PointBsdf> bsdf =
          trace_visible_point(camera, pixel, t, radii[pixel], p, o, region);
      if (max_component(p.f) > 0.0f) {
        // Stages 3 and 4 for this one point, as gather_pass and next_event_pass do them.
        const PointBsdf* glossy = bsdf ? &*bsdf : nullptr;
        const RegionView view = region.view();
        gather_point(p, glossy, r2, in.grid, in.hits, o.disc.full ? nullptr : &view, g);
        if (in.next_event)
          o.direct += next_event_at(in.world, p, glossy, in.seed, in.pass, path_item(pixel, t));
        e.mass = std::min(e.mass, float(o.disc.mass));
        if (glossy && states[k].photons < kMinPhotonsForBound)
          e.ratio = std::max(e.ratio, glossy_ratio(p, *glossy, o.disc.mass));
      }
      mean.add(g, o, r2, m_e);
    }
    e.spread = float(mean.spread());
    mean.finish(r2, sums_[b + k], owner_[b + k]);
  }
}

void SppmMethod::save(RenderState& s) const {
  s.path_history.clear();
  for (const PathHistory& h : history_)
    s.path_history.insert(s.path_history.end(), {h.inv_paths, h.spread, h.dof});
  s.visible = visible_;
  s.min_mass = min_mass_;
  s.glossy_f = glossy_f_;
}

void SppmMethod::restore(const RenderState& saved) {
  if (saved.visible.size() != visible_.size())
    throw StateError("the state holds " + std::to_string(saved.visible.size()) +
                     " SPPM pixel counters but this render has " + std::to_string(visible_.size()));
  if (saved.min_mass.size() != min_mass_.size())
    throw StateError("the state holds " + std::to_string(saved.min_mass.size()) +
                     " SPPM kernel masses but this render has " + std::to_string(min_mass_.size()));
  if (saved.glossy_f.size() != glossy_f_.size())
    throw StateError("the state holds " + std::to_string(saved.glossy_f.size()) +
                     " SPPM glossy caps but this render has " + std::to_string(glossy_f_.size()));
  if (saved.path_history.size() != history_.size() * 3)
    throw StateError("the state holds " + std::to_string(saved.path_history.size() / 3) +
                     " camera-path histories but this render has " +
                     std::to_string(history_.size()) + " (--adaptive paths)");
  for (size_t p = 0; p < history_.size(); ++p) {
    const float* h = saved.path_history.data() + 3 * p;
    history_[p] = PathHistory{h[0], h[1], h[2]};
  }
  visible_ = saved.visible;
  min_mass_ = saved.min_mass;
  glossy_f_ = saved.glossy_f;
}

PixelLayout SppmMethod::layout(const std::vector<PointState>&, const RenderState* saved) const {
  PixelLayout l;
  l.width = pass_.width;
  l.height = pass_.height;
  l.visible_passes = saved ? saved->visible : visible_;
  l.max_f = max_f_;
  l.glossy_f = saved ? saved->glossy_f : glossy_f_;
  l.mass = saved ? saved->min_mass : min_mass_;
  // --adaptive paths: which pixels have had a second path (their history's dof, sum of
  // K_j - 1, above 0); the bias priors' floor acts only in their windows.
  const size_t n = saved ? saved->path_history.size() / 3 : history_.size();
  l.paths_taken.resize(n);
  for (size_t p = 0; p < n; ++p)
    l.paths_taken[p] = (saved ? saved->path_history[3 * p + 2] : history_[p].dof) > 0.0f;
  return l;
}

}  // namespace pb
