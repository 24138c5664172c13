// The stages of one pass, each a function of plain inputs and outputs; the methods (ppm.h,
// sppm.h) run them in this order over blocks of points:
//   0. SPPM only: camera paths trace_visible_points (camera_paths.h) -> visible points, owner
//   values, the regions of the discs that are not whole (RegionTable, world/boundary.h)
//   1. trace photons          PhotonTracer::run (photon_pass.h)       -> hits of a photon range
//   2. build the grid         build_photon_grid                       -> grid over the hits
//   3. gather                 gather_pass: photons within each disc's  -> PassSums (phi, lap, M)
//                             region (the owner values' moments)
//   4. owner values           disc_pass (PPM, before 3), next_event_pass -> OwnerValues (D, disc)
//   5. fold                   fold_pass: sums and values into states   -> states, radii
// Stage 3 runs on any set of photon hits, and its PassSums (estimator.h) add over disjoint sets.
// A pass split across processes (exchange.h) shares stage 1 by photon range and stages 0 and
// 3-5 by chunks of states (Share), each rank gathering from every rank's hits.
#pragma once

#include "estimator/estimator.h"
#include "render/camera_pass.h"
#include "render/exchange.h"
#include "render/hash_grid.h"
#include "render/next_event.h"
#include "render/photon_guide.h"
#include "render/photon_pass.h"
#include "util/parallel.h"
#include "util/rng.h"
#include "world/boundary.h"
#include "world/world.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace pb {

// The float radius a point with squared radius r2 queries the grid with. The grid is built for
// these same values (Renderer keeps one per point), so both must come from here.
inline float search_radius(double r2) { return float(std::sqrt(r2)); }

// Which chunks of kStageChunk states (counted from state 0) this process computes in a
// distributed render (render/exchange.h): chunk c belongs to rank c mod ranks, so that every
// rank gets a share of every region of the image (a block of sky costs a tenth of a block of
// glass). One process owns every chunk.
struct Share {
  int rank = 0, ranks = 1;
  bool owns(size_t first_state) const;
};

// Stage 2: the grid over the hits' positions for queries of the given radii. `positions` is
// scratch, reused across passes.
void build_photon_grid(const std::vector<PhotonHit>& hits, std::span<const float> radii,
                       std::vector<vec3>& positions, HashGrid& grid);

// Adds every photon within search_radius(r2) of the point that arrived on the point's side
// (ESTIMATOR.md sections 2-3). Without the Laplacian (the bench's "error estimation off"
// variant) phi_lap_r2 is left alone. Lambertian points: the photon powers are summed and f
// multiplied once.
// With `learn`, each photon's error-weighted contribution goes to its guide cell
// (photon_guide.h): its share of the point's pass sample times learn->weight.
struct GuideLearning {
  GuideTally::Chunk* chunk = nullptr;
  double weight = 0.0;  // the point's relative error times mean(f) / R^2
};
// With `region`, only the photons inside it (the part of the disc the point's surface reaches,
// ESTIMATOR.md section 11); null: the whole disc.
template <bool kLaplacian = true>
void gather_photons(const VisiblePoint& point, double r2, const HashGrid& grid,
                    const std::vector<PhotonHit>& hits, PassSums& out,
                    const GuideLearning* learn = nullptr, const RegionView* region = nullptr);
// The same for a point on a non-Lambertian surface: each photon's power times f(wo, wi_photon),
// the path weight point.f once.
template <bool kLaplacian = true>
void gather_photons(const VisiblePoint& point, const PointBsdf& glossy, double r2,
                    const HashGrid& grid, const std::vector<PhotonHit>& hits, PassSums& out,
                    const GuideLearning* learn = nullptr, const RegionView* region = nullptr);

// The gather of one point, on its Bsdf where it has one (glossy non-null) and as a Lambertian
// point otherwise: the two overloads above, chosen, within `region` (null: the whole disc).
void gather_point(const VisiblePoint& point, const PointBsdf* glossy, double r2,
                  const HashGrid& grid, const std::vector<PhotonHit>& hits,
                  const RegionView* region, PassSums& out, const GuideLearning* learn = nullptr);

// The glossy side table of a span of points: entries sorted by PointBsdf::point, which counts
// from the span's first point at `base` (entries outside the span are skipped).
struct PointBsdfTable {
  std::span<const PointBsdf> entries;
  size_t base = 0;
};

// Stage 3: out[k] = the sums of the photons `hits` brings to points[k] (phi, phi_lap_r2,
// phi_half, count) at the pass's radius states[k].r2, within the regions `regions` holds for the
// points whose discs are not whole (null: every disc whole). A point with f = 0 (SPPM: no
// visible point this pass) gathers nothing and so does not shrink its radius. Points in `glossy`
// evaluate their Bsdf per photon. With `tally` (--adaptive photons), every gathered photon's
// error-weighted contribution goes to its guide cell, the point's relative error from its state
// after `passes_done` passes (ESTIMATOR.md section 14).
struct GuideInputs {
  GuideTally* tally = nullptr;
  uint64_t passes_done = 0;
  double photons_per_pass = 1.0;
};
void gather_pass(std::span<const VisiblePoint> points, std::span<const PointState> states,
                 const HashGrid& grid, const std::vector<PhotonHit>& hits, PointBsdfTable glossy,
                 const RegionTable* regions, std::span<PassSums> out,
                 GuideTally::Chunk* tally = nullptr, const GuideInputs& guide = {});

// Stage 4, PPM: out[k].disc = the kernel's moments over the reachable part of points[k]'s disc
// at the pass's radius (ESTIMATOR.md section 11); without `boundary` every disc counts as whole.
// `clearance` holds per point BoundaryIndex::clearance: the radius up to which its disc is whole
// without asking. `regions` receives (cleared first) the regions of the discs that are not
// whole, for the gather (stage 3 runs after it).
void disc_pass(std::span<const VisiblePoint> points, std::span<const PointState> states,
               const BoundaryIndex* boundary, std::span<const float> clearance,
               std::span<OwnerValues> out, RegionTable& regions);

// One point's next-event sample (stage 4), Rng keyed by (seed, pass, item, DirectLight); 0 for a
// point on a GGX lobe's diffuse base, whose camera path took its sample.
dvec3 next_event_at(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                    uint64_t seed, uint64_t pass, uint64_t item);
// Stage 4: adds one next-event sample (ESTIMATOR.md section 4) to out[k].direct for every
// point with f > 0, Rng keyed by (seed, pass, first + k, DirectLight). A point on a GGX lobe's
// diffuse base (is_base_part, render/lobe_split.h) is skipped: its camera path took its sample.
// The shadow rays of neighbouring points are traced as packets (Accel::occluded_packet); each
// point's sum is next_event_at's, bit for bit.
void next_event_pass(const World& world, std::span<const VisiblePoint> points,
                     PointBsdfTable glossy, uint64_t seed, uint64_t pass, size_t first,
                     std::span<OwnerValues> out);

// Stage 5: folds sums[k] and owner[k] into states[k] (accumulate_pass), writes the radius the
// next grid is built for into radii[k], and with `copy` streams each new state into copy[k]
// (a checkpoint's snapshot, written while the state is in cache).
void fold_pass(std::span<PointState> states, std::span<const PassSums> sums,
               std::span<const OwnerValues> owner, const EstimatorParams& params, uint64_t pass,
               std::span<float> radii, PointState* copy);

// Stage 5 over a fold block: the block [first, first + sums.size()) of the states, from the
// block's sums and owner values (indexed from 0), in parallel by chunks; `copy` (sized to all
// states) or null.
// Only the chunks `share` owns are folded.
void fold_block(size_t first, std::span<PointState> states, std::span<const PassSums> sums,
                std::span<const OwnerValues> owner, const EstimatorParams& params, uint64_t pass,
                std::span<float> radii, PointState* copy, Share share = {});

// Points per fold block: the pass sums of a block are gathered (stages 3-4) into one array,
// then folded (stage 5). 16384 points keep the block's sums and owner values (2.4 MB) and states
// (3.4 MB) in the last-level cache between the two, and the block's PassSums exist whole for a
// distributed reduction.
inline constexpr size_t kFoldBlock = 16384;

// What every stage of a pass reads: the world, the pass's photons and grid, the estimator's
// parameters and the random stream's key; and what may cut the pass short (polled by the first
// fold block's chunks, before anything of the pass is folded; null: never).
struct PassInputs {
  const World& world;
  const HashGrid& grid;
  const std::vector<PhotonHit>& hits;
  const EstimatorParams& params;
  const BoundaryIndex* boundary = nullptr;
  uint64_t seed = 0, pass = 0;
  bool next_event = true;
  const Cutoff* cutoff = nullptr;
  GuideInputs guide{};  // tally set: this pass learns the photon guide
  // Photon-pass rays per emitted photon over the passes before this one (--adaptive paths
  // prices a camera path against them, path_allocation.h).
  double rays_per_photon = 2.0;
  // The chunks of states this process computes (the others are other ranks').
  Share share{};
  // What bounds one photon's share of a sample (film.h's PixelLayout::photon_cap): --adaptive
  // paths weighs the sparse-photon bound, which paths cannot lower.
  double photon_cap = 0.0;
  // A distributed render's exchange (null in one process): --adaptive paths shares the
  // pixels' variances, each computed by the rank that owns the pixel, before allocating.
  Exchange* exchange = nullptr;
  // Whether a chunk of the fold block starting at `first` should give up: only the first block
  // can (the later ones come after a fold).
  bool cut(size_t first) const { return first == 0 && cutoff && cutoff->reached(); }
};

// Points per parallel task inside a fold block. The methods cut a block into chunks of this
// many points, the same every pass: a chunk's glossy entries sit at the front of its share of
// the scratch, so every stage of a chunk must see the same chunk.
inline constexpr size_t kStageChunk = 256;

// Runs body(first, count) for the chunks [first, first + count) of [0, n) of kStageChunk
// points, in parallel.
template <class Body>
void for_each_chunk(size_t n, Body&& body) {
  const size_t chunks = (n + kStageChunk - 1) / kStageChunk;
  parallel_for(chunks, 1, [&](size_t b, size_t e) {
    for (size_t c = b; c < e; ++c) {
      const size_t first = c * kStageChunk;
      body(first, std::min(kStageChunk, n - first));
    }
  });
}

}  // namespace pb
