// The render itself: state, step() and snapshot/restore, nothing else. PPM runs the eye pass
// once and keeps its measurement points; SPPM traces fresh camera paths every pass and keeps one
// state per pixel. Every pass runs the stages of pass_stages.h in turn (trace photons, build the
// grid, [SPPM: camera paths,] gather into pass sums, fold the sums into the estimator). When to
// stop, what to print and when to checkpoint belong to the driver (driver.h).
#pragma once

#include "world/boundary.h"
#include "estimator/estimator.h"
#include "render/eye_pass.h"
#include "estimator/film.h"
#include "render/hash_grid.h"
#include "io/image_io.h"
#include "options/options.h"
#include "render/photon_pass.h"
#include "render/view.h"
#include "world/world.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb {

// A saved render that does not fit this one (restore()); the state file's format is
// app/checkpoint.h's.
class StateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The work done so far, part of every state.
struct WorkCounters {
  uint64_t passes = 0;
  uint64_t photons = 0;  // emitted, all passes
  uint64_t rays = 0;     // photon-pass rays, all passes
};

// Everything a state file holds of the render itself.
struct RenderState {
  WorkCounters work;
  double initial_radius = 0.0;
  std::vector<PointState> states;  // PPM: one per measurement point; SPPM: one per pixel
  std::vector<uint32_t> visible;   // SPPM: passes with a visible point, per pixel
  std::vector<float> min_mass;     // SPPM: smallest kernel mass of a visible point, per pixel
  double max_photon_power = 0.0;   // largest channel of a photon's power seen (section 12)
  std::vector<float> glossy_f;     // SPPM: largest f a glossy visible point had, per pixel
};

// Wall-clock seconds spent in each phase, accumulated over all passes (for the benchmark).
struct PhaseTimings {
  double eye = 0.0;     // eye pass (once)
  double trace = 0.0;   // photon tracing
  double grid = 0.0;    // hash grid builds
  double gather = 0.0;  // gathers, next-event samples and estimator updates
};

// What the driver adds to an image's metadata.
struct RunInfo {
  double seconds = 0.0;  // wall clock of all runs
  std::string stop_reason;
};

// The EXR layout of channels.def (no metadata).
ExrImage pack_channels(const FilmImage& film);

// The default initial radius: kFootprintsPerRadius pixel footprints (median over the points),
// or 1% of the scene without points; never below the radius floor.
double default_initial_radius(const EyePassResult& eye, const World& world);
// The radius floor: R never falls below this fraction of the scene size (ESTIMATOR.md section
// 8): far below it float positions cannot resolve the distance test anyway.
double min_radius(const World& world);

class Renderer {
 public:
  Renderer(Scene scene, const RenderOptions& options);

  // Runs one more pass (pass number passes() + 1). With `copy`, also copies every point's
  // state into it as the pass leaves it (resized to the point count first).
  void step(std::vector<PointState>* copy = nullptr);
  uint64_t passes() const { return work_.passes; }
  const WorkCounters& work() const { return work_; }

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

  const RenderOptions& options() const { return options_; }
  // PPM: the measurement points. SPPM: the image size and the median footprint only.
  const EyePassResult& eye() const { return eye_; }
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
  // The current state or a snapshot's, without copying either.
  struct View {
    const WorkCounters& work;
    double initial_radius;
    const std::vector<PointState>& states;
    const std::vector<uint32_t>& visible;
    const std::vector<float>& min_mass;
    double max_photon_power;
    const std::vector<float>& glossy_f;
  };
  View view() const {
    return {work_, initial_radius_, states_, visible_, min_mass_, max_photon_power_, glossy_f_};
  }
  static View view(const RenderState& s) {
    return {s.work,     s.initial_radius,   s.states,  s.visible,
            s.min_mass, s.max_photon_power, s.glossy_f};
  }
  PixelLayout layout(const View& v) const;
  FilmSummary develop(const View& v, FilmImage* image) const;
  ExrImage image(const RunInfo& run, const View& v) const;

  const RenderOptions options_;
  World world_;
  PinholeCamera camera_;
  EyePassResult eye_;
  std::vector<PointState> states_;
  EstimatorParams params_;
  PhotonTracer tracer_;
  HashGrid grid_;
  BoundaryIndex boundary_;  // where surfaces end, for discs up to the initial radius
  bool boundary_on_ = true;
  std::vector<float> clearance_;  // PPM: per point, BoundaryIndex::clearance at the initial radius
  std::vector<PhotonHit> hits_;
  std::vector<vec3> hit_positions_;
  std::vector<float> radii_;       // search_radius(r2) per point, for the grid build
  std::vector<PassGather> sums_;   // one fold block's pass sums (pass_stages.h)
  std::vector<uint32_t> visible_;  // SPPM: passes with a visible point, per pixel
  std::vector<float> min_mass_;    // SPPM: smallest kernel mass seen, per pixel
  double max_photon_power_ = 0.0;  // emitted or stored, the largest channel
  vec3 max_f_{0.0f};               // largest BRDF a Lambertian point can have
  std::vector<float> glossy_f_;    // SPPM: largest glossy f seen, per pixel
  // PPM with glossy points: the points with f times Bsdf::max_f for the sparse-photon bound.
  std::vector<MeasurementPoint> capped_points_;
  std::vector<MeasurementPoint> visible_points_;  // SPPM: one fold block's, reused
  std::vector<GlossyPoint> visible_glossy_;       // SPPM: their Bsdfs where not Lambertian
  WorkCounters work_;
  double initial_radius_ = 0.0;
  PhaseTimings timings_;
};

}  // namespace pb
