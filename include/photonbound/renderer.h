// The pass loop: eye pass once, then photon pass, grid build, gather and estimator update per
// pass, until a stop condition (passes, time, target error, interruption) is met.
#pragma once

#include "photonbound/checkpoint.h"
#include "photonbound/estimator.h"
#include "photonbound/eye_pass.h"
#include "photonbound/film.h"
#include "photonbound/hash_grid.h"
#include "photonbound/image_io.h"
#include "photonbound/options.h"
#include "photonbound/photon_pass.h"
#include "photonbound/world.h"

#include <atomic>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace pb {

struct RenderReport {
  uint64_t passes = 0;
  uint64_t photons = 0;  // emitted, all passes
  uint64_t rays = 0;     // photon-pass rays, all passes
  double seconds = 0.0;  // wall clock of the pass loop
  std::string stop_reason;
  double initial_radius = 0.0;
  FilmSummary summary;
};

// Picks the camera (by node or camera name when given) and the image size.
PinholeCamera choose_camera(const Scene& scene, const RenderOptions& options);

// Wall-clock seconds spent in each phase, accumulated over all passes (for the benchmark).
struct PhaseTimings {
  double eye = 0.0;     // eye pass (once)
  double trace = 0.0;   // photon tracing
  double grid = 0.0;    // hash grid builds
  double gather = 0.0;  // gathers, next-event samples and estimator updates
  // Checkpoints: time the pass loop itself spent on them (waiting for a previous write,
  // starting the next), and wall time of the background writes. The snapshot copy made inside
  // the update loop is part of `gather`.
  double checkpoint_stall = 0.0;
  double checkpoint_write = 0.0;
  uint64_t checkpoints = 0;
};

// The EXR channel layout of README "Output" (no metadata).
ExrImage pack_channels(const FilmImage& film);

// Optional per-pass log (--log): one JSON object per logged pass. Passes are logged while the
// time spent logging stays within `max_overhead` of the run's time, so the log never slows the
// pass loop by more than that; the last pass is always logged.
struct PassLog {
  std::ostream* out = nullptr;
  const ExrImage* reference = nullptr;  // adds the actual error and coverage when given
  double max_overhead = 0.03;
};

// Checkpoints every `every` seconds of the run (0 = never). `write` runs on a background
// thread while the passes go on: it gets the report and a snapshot of the render as it stood
// after one pass (states copied inside that pass's update loop, while they are in cache), and
// must not touch the Renderer's mutable state (image(report, states) is safe). One checkpoint
// is in flight at most: while one is being written, the next waits for a later pass. run()
// waits for the last one before it returns, and rethrows what a write threw.
struct CheckpointPolicy {
  double every = 0.0;
  std::function<void(const RenderReport&, SavedRender&)> write;
};

class Renderer {
 public:
  Renderer(const Scene& scene, const RenderOptions& options);

  // Runs to a stop condition. `stop` is polled after every pass (Ctrl-C); progress lines go to
  // `progress` when it is not null.
  RenderReport run(const std::atomic<bool>* stop, std::ostream* progress,
                   const CheckpointPolicy& checkpoint = {}, const PassLog& log = {});

  // Runs one more pass (pass number passes() + 1). With `copy`, also copies every point's
  // state into it as the pass leaves it (resized to the point count first).
  void step(std::vector<PointState>* copy = nullptr);
  uint64_t passes() const { return loop_.passes; }

  // Everything a state file holds (scene hash aside), and the way back. restore() throws
  // StateError when the state does not fit this scene and camera.
  SavedRender snapshot() const;
  void restore(const SavedRender& saved);

  // Radiance, bound channels and metadata, ready for write_exr: of the current states, or of
  // `states` (a checkpoint's snapshot; reads only what does not change after construction).
  ExrImage image(const RenderReport& report) const { return image(report, states_); }
  ExrImage image(const RenderReport& report, const std::vector<PointState>& states) const;

  const EyePassResult& eye() const { return eye_; }
  const std::vector<PointState>& states() const { return states_; }
  FilmSettings film_settings() const;
  const PhaseTimings& timings() const { return timings_; }
  const World& world() const { return world_; }

 private:
  double default_radius() const;
  SavedRender snapshot_with(std::vector<PointState> states) const;  // these states, the rest now
  std::string progress_line(const RenderReport& report, double run_seconds) const;
  void write_log_line(const RenderReport& report, const PassLog& log) const;
  bool radii_fixed() const;

  const RenderOptions options_;
  World world_;
  PinholeCamera camera_;
  EyePassResult eye_;
  std::vector<PointState> states_;
  EstimatorParams params_;
  PhotonTracer tracer_;
  HashGrid grid_;
  std::vector<PhotonHit> hits_;
  std::vector<vec3> hit_positions_;
  std::vector<float> radii_;                   // sqrt(r2) per point, for the grid build
  std::vector<PointState> checkpoint_states_;  // snapshot buffer, reused (checkpoints only)
  LoopState loop_;  // passes, photons, rays, seconds and check schedule so far
  double initial_radius_ = 0.0;
  PhaseTimings timings_;
};

}  // namespace pb
