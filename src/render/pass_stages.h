// The stages of one pass, each a function of plain inputs and outputs, in the order the
// renderer runs them (the bench times the same functions):
//   0. SPPM only: camera paths trace_visible_points (camera_paths.h) -> visible points, emission
//   1. trace photons          PhotonTracer::run (photon_pass.h)      -> hits
//   2. build the grid         build_photon_grid                      -> grid over the hits
//   3. gather                 gather_pass: photons within each radius -> pass sums (phi, lap, M)
//   4. next-event samples     next_event_pass                        -> pass sums (D)
//   5. fold                   fold_pass: sums into the estimator     -> states, radii
// The pass sums of a block of points exist as an array (PassGather, estimator.h) between 4 and
// 5: a distributed render reduces exactly that array across machines before folding it.
#pragma once

#include "world/boundary.h"
#include "estimator/estimator.h"
#include "render/eye_pass.h"
#include "render/hash_grid.h"
#include "render/next_event.h"
#include "render/photon_pass.h"
#include "util/rng.h"
#include "world/world.h"

#include <cmath>
#include <span>
#include <vector>

namespace pb {

// The float radius a point with squared radius r2 queries the grid with. The grid is built for
// these same values (Renderer keeps one per point), so both must come from here.
inline float search_radius(double r2) { return float(std::sqrt(r2)); }

// Stage 2: the grid over the hits' positions for queries of the given radii. `positions` is
// scratch, reused across passes.
void build_photon_grid(const std::vector<PhotonHit>& hits, std::span<const float> radii,
                       std::vector<vec3>& positions, HashGrid& grid);

// Adds every photon within search_radius(r2) of the point that arrived on the point's side
// (ESTIMATOR.md sections 2-3). Without the Laplacian (the bench's "error estimation off"
// variant) phi_lap_r2 is left alone. Lambertian points: the photon powers are summed and f
// multiplied once.
template <bool kLaplacian = true>
void gather_photons(const MeasurementPoint& point, double r2, const HashGrid& grid,
                    const std::vector<PhotonHit>& hits, PassGather& out);
// The same for a point on a non-Lambertian surface: each photon's power times f(wo, wi_photon),
// the path weight point.f once.
template <bool kLaplacian = true>
void gather_photons(const MeasurementPoint& point, const GlossyPoint& glossy, double r2,
                    const HashGrid& grid, const std::vector<PhotonHit>& hits, PassGather& out);

// The glossy side table of a span of points: entries sorted by GlossyPoint::point, which counts
// from the span's first point at `base` (entries outside the span are skipped).
struct GlossyTable {
  std::span<const GlossyPoint> entries;
  size_t base = 0;
};

// Stage 3: adds the photons of the pass at points[k] into out[k] (phi, phi_lap_r2, count).
// states[k].r2 is the radius of the pass. A point with f = 0 (SPPM: no visible point this
// pass) gathers nothing and so does not shrink its radius. Points in `glossy` evaluate their
// Bsdf per photon. With `boundary`, also the kernel's moments over the reachable part of each
// point's disc (ESTIMATOR.md section 11); without, every disc counts as whole. `clearance`
// (PPM; empty otherwise) holds per point BoundaryIndex::clearance: the radius up to which its
// disc is whole without asking.
void gather_pass(std::span<const MeasurementPoint> points, std::span<const PointState> states,
                 const HashGrid& grid, const std::vector<PhotonHit>& hits,
                 const BoundaryIndex* boundary, GlossyTable glossy, std::span<PassGather> out,
                 std::span<const float> clearance = {});

// Stage 4: adds one next-event sample at points[k] to out[k].direct, drawn from
// Rng(seed, pass, first + k, Stream::DirectLight): point (or pixel) first + k's own stream.
void next_event_pass(const World& world, std::span<const MeasurementPoint> points,
                     GlossyTable glossy, uint64_t seed, uint64_t pass, size_t first,
                     std::span<PassGather> out);

// Stage 5: folds sums[k] into states[k] (accumulate_pass), writes the radius the next grid is
// built for into radii[k], and with `copy` streams each new state into copy[k] (a checkpoint's
// snapshot, written while the state is in cache).
void fold_pass(std::span<PointState> states, std::span<const PassGather> sums,
               const EstimatorParams& params, uint64_t pass, std::span<float> radii,
               PointState* copy);

// Stages 3-5 over all points, block by block in parallel, as Renderer::step runs them: for each
// block of sums.size() points, gather and next-event samples into `sums`, then fold. `copy`
// (sized to the points) receives the new states.
struct PassInputs {
  const World& world;
  const HashGrid& grid;
  const std::vector<PhotonHit>& hits;
  const EstimatorParams& params;
  const BoundaryIndex* boundary = nullptr;
  uint64_t seed = 0, pass = 0;
  bool next_event = true;
  std::span<const GlossyPoint> glossy{};  // PPM: EyePassResult::glossy (indices into the points)
  std::span<const float> clearance{};     // PPM: per point, BoundaryIndex::clearance
};
void gather_and_fold(const PassInputs& in, std::span<const MeasurementPoint> points,
                     std::span<PointState> states, std::span<float> radii,
                     std::span<PassGather> sums, PointState* copy);

// SPPM (ESTIMATOR.md section 10): the same with the camera stage first, per block of pixels:
// trace_visible_points into `points` and `glossy` (block-sized scratch) and the sums' emission,
// gather, next-event samples, count each pixel's passes with a visible point in `visible`, keep
// the smallest kernel mass of its visible points in `min_mass` and the largest f a glossy visible
// point of it may have (throughput x Bsdf::max_f) in `glossy_f` (section 12), then fold.
struct CameraPathInputs;
void sppm_gather_and_fold(const PassInputs& in, const CameraPathInputs& camera,
                          std::span<PointState> states, std::span<float> radii,
                          std::span<uint32_t> visible, std::span<float> min_mass,
                          std::span<float> glossy_f, std::span<MeasurementPoint> points,
                          std::span<GlossyPoint> glossy, std::span<PassGather> sums,
                          PointState* copy);

}  // namespace pb
