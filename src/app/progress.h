// Driver observers that report: the progress line on a terminal and the per-pass JSON log.
#pragma once

#include "app/driver.h"
#include "io/image_io.h"

#include <ostream>

namespace pb {

// A pass and the tested quantity its development found (pass 0: none).
struct TestedAt {
  uint64_t pass = 0;
  double value = 0.0;
};

// The progress line's time left: the smallest of what the stop conditions imply, after `pass`
// whose development found `tested` (not finite: none), `seconds` into the render (of which
// `run_seconds` in this run). The target's share comes from the tested quantity's power law:
// through the schedule's earlier test, or else `earlier` (the schedule takes the test it
// extrapolates from anew each time the passes double, at that very pass); with neither, as the
// noise falls, passes^-1/2 (the first test). Once the quantity is at the target it is the time to
// the next scheduled test, never the rest of the budget. +inf: no estimate. `bounded_only`, when
// given, is set where a target gave no estimate and the figure is only what --time leaves (the
// line then says "<= X s left", not "~X s left": at pass 1 the budget is no estimate of a render
// that stops on its target).
double seconds_left(const RenderOptions& options, const DriverState& schedule, uint64_t pass,
                    double seconds, double run_seconds, double tested, const TestedAt& earlier,
                    bool* bounded_only = nullptr);

// A progress line at most every 0.5 s (less often when developing the image takes over 25 ms:
// at most 5% of the run) and after the last pass: pass, photons, mean bound,
// share of pixels below the target, unknown pixels, elapsed time and time left. A pass is told
// again when the next one was cut short (Driver::run): not printed twice, and pass 0 never.
// The figures come from a development; the printer asks for one of its own only where no stop
// test brings one within its interval (README's first command at 1920x1080 developed at pass 1,
// whose line shows no figure, and at pass 15, a pass before the first test: 0.6 s of 13 s).
// Until the first development the lines, every kQuietSeconds, have no figures.
class ProgressPrinter : public PassObserver {
 public:
  explicit ProgressPrinter(std::ostream& out) : out_(out) {}
  bool wants_summary(uint64_t pass, double run_seconds, uint64_t next_test) override;
  void after_pass(const PassInfo& info) override;
  // `earlier`: an earlier line's pass and tested quantity (pass 0: none), for the time left.
  // Without a development of this pass (info.developed) the line has no figures.
  static std::string line(const PassInfo& info, const TestedAt& earlier = {});
  // The lines before the first development, which have only the pass, photons and times.
  static constexpr double kQuietSeconds = 2.0;

 private:
  double interval() const;
  std::ostream& out_;
  double last_print_ = -1.0;
  double last_figures_ = -1.0;    // when the last line with figures was printed
  double develop_seconds_ = 0.0;  // the last development's time
  bool developed_ = false;        // a development was seen
  uint64_t printed_ = 0;          // the last pass printed
  TestedAt earlier_;              // the last line's tested quantity
};

// --log: one JSON object per logged pass (docs/usage.md "Logging"). Passes are logged while
// the time spent logging stays within `max_overhead` of the run's time, so the log never slows
// the pass loop by more than that; the last pass is always logged (once, and pass 0 never: see
// ProgressPrinter). With a reference image each line also carries the actual error and coverage.
class PassLogger : public PassObserver {
 public:
  PassLogger(std::ostream& out, const ExrImage* reference, double max_overhead = 0.03)
      : out_(out), reference_(reference), max_overhead_(max_overhead) {}
  bool wants_summary(uint64_t pass, double run_seconds, uint64_t next_test) override;
  void after_pass(const PassInfo& info) override;

 private:
  std::ostream& out_;
  const ExrImage* reference_;
  double max_overhead_;
  double log_seconds_ = 0.0;
  bool want_ = false;
  uint64_t logged_ = 0;  // the last pass logged
};

}  // namespace pb
