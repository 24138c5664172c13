// The render itself: state, step() and snapshot/restore, nothing else. The method (method.h:
// PPM keeps the visible points of one camera pass, SPPM traces fresh camera paths every pass
// and keeps one state per pixel) runs the camera's side of a pass; the renderer owns what both
// share: the states and radii, the photons (a photon index range per pass) and their grid.
// When to stop, what to print and when to checkpoint belong to the driver (app/driver.h).
#pragma once

#include "estimator/estimator.h"
#include "estimator/film.h"
#include "io/image_io.h"
#include "options/options.h"
#include "render/camera_choice.h"
#include "render/camera_pass.h"
#include "render/exchange.h"
#include "render/hash_grid.h"
#include "render/method.h"
#include "render/photon_pass.h"
#include "world/boundary.h"
#include "world/world.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace pb {

// Wall-clock seconds spent in each phase, accumulated over all passes (for the benchmark).
struct PhaseTimings {
  double camera = 0.0;  // PPM's camera pass (once); SPPM's footprint sample
  double trace = 0.0;   // photon tracing
  double grid = 0.0;    // hash grid builds
  double gather = 0.0;  // gathers, next-event samples and estimator updates
};

// What the driver adds to an image's metadata.
struct RunInfo {
  double seconds = 0.0;  // wall clock of all runs
  std::string stop_reason;
};

// The EXR layout of channels.def over the film's planes (no metadata); valid while `film` is.
ExrView film_view(const FilmImage& film);

// The default initial radius: kFootprintsPerRadius pixel footprints (median over the points),
// or 1% of the scene without points; never below the radius floor.
double default_initial_radius(const CameraPassResult& pass, const World& world);
// The radius floor: R never falls below this fraction of the scene size (ESTIMATOR.md section
// 8): far below it float positions cannot resolve the distance test anyway.
double radius_floor(const World& world);

class Renderer {
 public:
  Renderer(Scene scene, const RenderOptions& options);
  ~Renderer();

  // Runs one more pass (pass number passes() + 1). With `copy`, also copies every point's
  // state into it as the pass leaves it (resized to the point count first). With `cutoff`, the
  // pass polls it between batches of photons, before the grid build and while the first fold
  // block gathers; once reached, the pass is discarded whole and step() returns false: states,
  // side state and counters are those of the last whole pass, and `copy` is not that pass's.
  // Past the first fold the pass runs to its end.
  bool step(std::vector<PointState>* copy = nullptr, const Cutoff* cutoff = nullptr);
  uint64_t passes() const { return work_.passes; }
  const WorkCounters& work() const { return work_; }

  // A render split over processes (exchange.h): from now on this process traces its share of
  // every pass's photons and computes the states it owns. Every rank calls step() for every
  // pass: rank 0 through the driver, the others through follow(). A cutoff then never cuts a
  // pass (the ranks could not agree where): passes end whole, and the driver stops between
  // them. Throws std::invalid_argument for what does not run distributed yet (--adaptive
  // photons and paths need every state on every rank).
  void distribute(Exchange* exchange);
  // Rank 0: brings every state and the method's side state to this process from the ranks
  // that computed them, once per pass (a no-op in one process and after the first call).
  // Called before anything reads the states: develop, snapshot, image.
  void collect();
  // The other ranks: runs passes and collects as rank 0 commands, until it ends the render.
  void follow();
  // Rank 0: tells the others the render is over (at the end, or never if an error ends it).
  void release_followers();
  const Exchange* exchange() const { return exchange_; }

  // The state and the way back. restore() throws StateError when the state does not fit this
  // scene and camera. snapshot(states) is the state with `states` in place of the current ones
  // (a checkpoint's copy, made inside a pass).
  RenderState snapshot() const { return snapshot(states_); }
  RenderState snapshot(std::vector<PointState> states) const;
  void restore(const RenderState& saved);

  // True when no radius can shrink any more (alpha = 1, or every radius at its floor).
  bool radii_fixed() const;

  // Which states make up each pixel (of the current states).
  PixelLayout layout() const;
  // Radiance and bounds of the current states, or of a snapshot's; the film when wanted.
  FilmSummary develop(FilmImage* image = nullptr) const;
  FilmSummary develop(const RenderState& state, FilmImage* image) const;
  // The EXR (channels.def) with every option and the run in its metadata.
  ExrImage image(const RunInfo& run) const;
  ExrImage image(const RunInfo& run, const RenderState& state) const;
  // The EXR of the current states from their development (`film` and `summary`, made by
  // develop(&film) since the last pass): as a view of the film's planes, which write_exr
  // writes with no copy of the image (valid while `film` is), or packed.
  ExrView image_view(const RunInfo& run, const FilmImage& film, const FilmSummary& summary) const {
    return view(run, film, summary, work_, initial_radius_, states_.size());
  }
  ExrImage image(const RunInfo& run, const FilmImage& film, const FilmSummary& summary) const {
    return packed(image_view(run, film, summary));
  }

  const RenderOptions& options() const { return options_; }
  // PPM: the visible points. SPPM: the image size and the median footprint only.
  const CameraPassResult& camera_pass() const { return method_->camera_pass(); }
  const std::vector<PointState>& states() const { return states_; }
  FilmSettings film_settings() const;
  const PhaseTimings& timings() const { return timings_; }
  const World& world() const { return world_; }
  const PinholeCamera& camera() const { return camera_; }
  double initial_radius() const { return initial_radius_; }
  const BoundaryIndex& boundary() const { return boundary_; }
  // The bench's probe-cost comparison (issue 14) alone switches the boundary moments off: every
  // disc then counts as whole, which is biased along edges (ESTIMATOR.md section 11).
  void use_boundary_moments(bool on) { boundary_on_ = on; }

 private:
  // Which of `states` make up each pixel, with a snapshot's side state or the current one.
  PixelLayout layout(const std::vector<PointState>& states, const RenderState* saved,
                     double max_photon_power) const;
  FilmSummary develop(const std::vector<PointState>& states, const RenderState* saved,
                      uint64_t passes, double max_photon_power, FilmImage* image) const;
  ExrView view(const RunInfo& run, const FilmImage& film, const FilmSummary& summary,
               const WorkCounters& work, double initial_radius, size_t states) const;

  const RenderOptions options_;
  World world_;
  PinholeCamera camera_;
  std::unique_ptr<PhotonMethod> method_;
  std::vector<PointState> states_;
  EstimatorParams params_;
  PhotonTracer tracer_;
  // --adaptive photons: the emission the next pass's photons are drawn from, and what the pass
  // gathers to learn it (ESTIMATOR.md section 14).
  std::optional<EmissionGuide> guide_;
  GuideTally tally_;
  HashGrid grid_;
  BoundaryIndex boundary_;  // where surfaces end, for discs up to the initial radius
  bool boundary_on_ = true;
  std::vector<PhotonHit> hits_;
  std::vector<vec3> hit_positions_;
  std::vector<float> radii_;       // search_radius(r2) per point, for the grid build
  double max_photon_power_ = 0.0;  // emitted or stored, the largest channel
  WorkCounters work_;
  double initial_radius_ = 0.0;
  PhaseTimings timings_;
  Exchange* exchange_ = nullptr;  // distributed: the other ranks; null in one process
  uint64_t collected_ = 0;        // the pass whose states rank 0 last collected
  // The last development's per-pixel block, for the next stop test's (film.h); an EXR's
  // packing frees it.
  mutable DevelopMemory develop_memory_;
};

}  // namespace pb
