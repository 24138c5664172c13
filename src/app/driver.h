// The driver: owns the pass loop around a Renderer. It decides when to stop (StopReason, on the
// check schedule of ESTIMATOR.md section 7) and tells its observers about every pass; progress
// lines, the per-pass log and checkpoints are observers (progress.h, pass_log.h,
// checkpoint_writer.h), so the Renderer itself only steps.
#pragma once

#include "estimator/film.h"
#include "render/renderer.h"

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pb {

enum class StopReason : uint8_t {
  None,
  Passes,
  Time,
  TargetError,
  Unreachable,   // the radii cannot shrink and the bias is above the target
  ModelRefuted,  // the second-order bias model fails at this radius (ESTIMATOR.md 11b)
  Interrupted
};

// As printed and stored in the EXR metadata ("passes", "time", "target-error", ...).
std::string stop_text(StopReason reason);

// The driver's own state, saved with the render so that a resumed render tests its target on
// the same schedule.
struct DriverState {
  double seconds = 0.0;     // wall clock of all runs so far
  uint64_t next_check = 0;  // pass of the next stop test; 0 = not scheduled yet
  uint64_t early_pass = 0;  // an earlier test and its tested quantity, for the time left
  double early_value = 0.0;
};

// What observers are told after each pass.
struct PassInfo {
  const Renderer& renderer;
  const DriverState& schedule;
  uint64_t pass = 0;
  double run_seconds = 0.0;  // this run
  bool developed = false;    // summary is of this pass (else of an earlier one, or empty)
  const FilmSummary& summary;
  StopReason stop = StopReason::None;  // None: more passes follow
  // What developing this pass's summary took (0 when it was not developed): observers that
  // ask for it count it in their overhead (--log's budget, the progress line's interval).
  double develop_seconds = 0.0;
};

class PassObserver {
 public:
  virtual ~PassObserver() = default;
  // Before each pass: a buffer that pass should copy every point state into (a checkpoint's
  // snapshot), or null.
  virtual std::vector<PointState>* snapshot_buffer(double /*run_seconds*/) { return nullptr; }
  // Whether this pass's summary is wanted (developing the image costs a fraction of a pass). The
  // last pass is always developed. `next_test`: the pass of the next stop test, which develops
  // the image anyway (0: none, no --target-error).
  virtual bool wants_summary(uint64_t /*pass*/, double /*run_seconds*/, uint64_t /*next_test*/) {
    return false;
  }
  virtual void after_pass(const PassInfo& /*info*/) {}
  // Once, after the last pass; may rethrow what a background job threw.
  virtual void finish() {}
};

struct RenderReport {
  WorkCounters work;
  double seconds = 0.0;  // wall clock of all runs
  StopReason stop = StopReason::None;
  FilmSummary summary;
  // The image of the final states, when they were developed after the stop was known (a stop by
  // the target is decided on a development without the image: then none).
  std::optional<FilmImage> film;
  RunInfo run() const { return {seconds, stop_text(stop)}; }
};

// What the stop rule of `options` compares with --target-error (docs/error-bounds.md "Stopping"):
// the upper confidence limit of the image's mean error (mean-error), the mean of the pixels' bounds
// (mean-bound), or the bound that the share Q of the pixels is within (pixels:Q).
double tested_quantity(const RenderOptions& options, const FilmSummary& summary);
// A short name of it for the progress line ("mean error", "mean bound", "90% of pixels").
std::string tested_name(const RenderOptions& options);

// The pass at which the tested quantity, `value` at `pass`, reaches `target`, by the power law
// through it and an earlier test's (`early_pass`, `early_value`); NaN where there is none (no
// earlier test, or the quantity did not fall). The progress line's time left and the stop test's
// schedule both extrapolate with it.
double passes_to_target(uint64_t pass, double value, uint64_t early_pass, double early_value,
                        double target);
// The slowest fall the extrapolations assume where they need one: the noise's, passes^-1/2.
inline constexpr double kSlowestFall = 0.5;
// The pass at which `value` at `pass`, falling as passes^-k, reaches `target`.
double passes_at_fall(uint64_t pass, double value, double k, double target);

// The pass of the next stop test after one at `pass` that found `value` above `target`
// (ESTIMATOR.md section 7): about 10% of the passes later; sooner, where the power law says the
// target is crossed before then, but never within 2.5% of the passes of this test; later, three
// quarters of the way to the crossing (the power law taken as falling at least as passes^-0.5),
// where that is further, but never beyond twice the passes; the regular test where the two tests
// show no fall.
uint64_t next_check_after(uint64_t pass, double value, uint64_t early_pass, double early_value,
                          double target);

// The figures of the closing line: the quantity the stop rule tests, then the mean bound; with
// pixels unknown, how many, and no mean at all when the known pixels are not a majority (their
// mean is not the image's: issue 37's background of bound 0).
std::string stop_figures(const RenderOptions& options, const FilmSummary& summary);

class Driver {
 public:
  explicit Driver(Renderer& renderer, DriverState state = {});

  // Runs passes until a stop condition of the renderer's options holds, or `interrupt` is set.
  // `interrupt` and the end of --time cut the pass in progress (Renderer::step): it is
  // discarded, and the render ends with the last whole pass.
  RenderReport run(const std::atomic<bool>* interrupt = nullptr,
                   std::span<PassObserver* const> observers = {});
  const DriverState& state() const { return state_; }

 private:
  Renderer& renderer_;
  DriverState state_;
};

}  // namespace pb
