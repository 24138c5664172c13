#include "app/progress.h"

#include "app/compare.h"
#include "util/json.h"
#include "util/timer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace pb {

namespace {

std::string format_count(double v) {
  char buf[32];
  if (v >= 1e9)
    std::snprintf(buf, sizeof buf, "%.2fG", v / 1e9);
  else if (v >= 1e6)
    std::snprintf(buf, sizeof buf, "%.2fM", v / 1e6);
  else if (v >= 1e3)
    std::snprintf(buf, sizeof buf, "%.1fk", v / 1e3);
  else
    std::snprintf(buf, sizeof buf, "%.0f", v);
  return buf;
}

}  // namespace

// Every 0.5 s, or every 20 developments' time when a development takes longer (a large image):
// the line costs at most 5% of the run.
double ProgressPrinter::interval() const { return std::max(0.5, 20.0 * develop_seconds_); }

bool ProgressPrinter::wants_summary(uint64_t pass, double run_seconds, uint64_t next_test) {
  // Pass 1's line has no figures (a variance needs two passes).
  if (pass < 2) return false;
  const double per_pass = run_seconds / double(pass);
  // Before any development its cost is not known: with a target, taken as a pass's (about a
  // development's at 512x512, more than one at 1920x1080), so that the first test, 16 passes
  // in by default, brings the first figures; without one, the first line with figures is pass
  // 2's, as far as it costs.
  const double every =
      developed_ ? interval() : (next_test > 0 ? std::max(0.5, 20.0 * per_pass) : 0.5);
  // Its line must be due too (at most every 0.5 s), or the development is wasted.
  if (run_seconds - last_figures_ < every || run_seconds - last_print_ < 0.5) return false;
  // A stop test within the interval develops the image anyway.
  return !(next_test > 0 && double(next_test - std::min(next_test, pass)) * per_pass < every);
}

void ProgressPrinter::after_pass(const PassInfo& info) {
  if (info.pass == printed_) return;
  if (info.developed) {
    develop_seconds_ = info.develop_seconds;
    developed_ = true;
  }
  const double since = info.run_seconds - last_print_;
  const bool figures = info.developed && since >= 0.5;
  const bool quiet = !developed_ && (printed_ == 0 || since >= kQuietSeconds);
  if (info.stop == StopReason::None && !figures && !quiet) return;
  last_print_ = info.run_seconds;
  if (info.developed) last_figures_ = info.run_seconds;
  printed_ = info.pass;
  out_ << line(info, earlier_) << std::endl;
  if (info.developed) {
    const double tested = tested_quantity(info.renderer.options(), info.summary);
    if (std::isfinite(tested)) earlier_ = {info.pass, tested};
  }
}

double seconds_left(const RenderOptions& o, const DriverState& schedule, uint64_t pass,
                    double seconds, double run_seconds, double tested, const TestedAt& earlier,
                    bool* bounded_only) {
  const double per_pass = seconds / double(std::max<uint64_t>(pass, 1));
  double left = INFINITY;
  if (o.passes) left = std::min(left, double(*o.passes - std::min(pass, *o.passes)) * per_pass);
  const double by_passes = left;
  if (o.time_seconds) left = std::min(left, *o.time_seconds - run_seconds);
  // The target's estimate (+inf: none).
  double by_target = INFINITY;
  if (o.target_error && std::isfinite(tested)) {
    const double target = *o.target_error;
    const uint64_t next = std::max(schedule.next_check, pass);
    const double to_check = double(next - pass) * per_pass;
    if (tested <= target) {
      by_target = to_check;
    } else {
      double needed =
          passes_to_target(pass, tested, schedule.early_pass, schedule.early_value, target);
      if (std::isnan(needed))
        needed = passes_to_target(pass, tested, earlier.pass, earlier.value, target);
      // No earlier figure at all: the noise's fall, which the schedule also takes as the
      // slowest when it postpones a test (at 1920x1080 the first line came at the first test,
      // and the time left it showed was the rest of --time: "~890 s" for a render that ended
      // 9 s later).
      const bool first = (schedule.early_pass == 0 || schedule.early_pass >= pass) &&
                         (earlier.pass == 0 || earlier.pass >= pass);
      if (std::isnan(needed) && first) needed = passes_at_fall(pass, tested, kSlowestFall, target);
      if (std::isfinite(needed)) by_target = std::max((needed - double(pass)) * per_pass, to_check);
    }
  }
  if (bounded_only) *bounded_only = o.target_error && !std::isfinite(by_target) && left < by_passes;
  return std::min(left, by_target);
}

std::string ProgressPrinter::line(const PassInfo& info, const TestedAt& earlier) {
  const RenderOptions& o = info.renderer.options();
  const FilmSummary& s = info.summary;
  const uint64_t pass = info.pass;
  const double seconds = info.schedule.seconds;
  std::ostringstream line;
  line.precision(4);
  line << "pass " << pass << " | " << format_count(double(info.renderer.work().photons))
       << " photons";
  // The summary is this pass's only where it was developed (an earlier one's otherwise).
  const double tested = info.developed ? tested_quantity(o, s) : NAN;
  if (pass >= 2 && info.developed) {
    if (o.target_error) {
      // The quantity the stop rule tests, next to the target (docs/error-bounds.md "Stopping").
      line << " | " << tested_name(o) << " " << (o.stop_rule == StopRule::MeanError ? "<= " : "")
           << tested << " (target " << *o.target_error << ")";
    } else {
      line << " | bound " << s.mean_bound;
    }
    line << " | " << s.unknown_pixels << " unknown";
    if (s.model_refuted)
      line << " (bias model refuted: " << 100.0 * s.slope_disagreement << "% of slopes, "
           << 100.0 * s.scale_disagreement << "% of scales disagree)";
  }
  line << " | " << seconds << " s";
  bool bounded_only = false;
  const double left = seconds_left(o, info.schedule, pass, seconds, info.run_seconds, tested,
                                   earlier, &bounded_only);
  if (std::isfinite(left))
    line << " | " << (bounded_only ? "<= " : "~") << std::max(0.0, left) << " s left";
  return line.str();
}

bool PassLogger::wants_summary(uint64_t, double run_seconds, uint64_t) {
  want_ = log_seconds_ <= max_overhead_ * run_seconds;
  return want_;
}

void PassLogger::after_pass(const PassInfo& info) {
  if (info.pass == logged_ || (!want_ && info.stop == StopReason::None)) return;
  logged_ = info.pass;
  // The development this pass's line needed is the log's cost (the stop test may have needed it
  // too; counting it here errs on the side of logging less): without it --log developed every
  // pass, 1.5-1.7x a pass's time on the default scene (issue 40).
  if (want_) log_seconds_ += info.develop_seconds;
  const auto t0 = Clock::now();
  const FilmSummary& s = info.summary;
  JsonObject line;
  // JSON has no infinity: an unknown mean bound is written as -1 (docs/usage.md "Logging").
  line.add("pass", info.pass)
      .add("seconds", info.schedule.seconds)
      .add("photons", info.renderer.work().photons)
      .add("mean_bound", std::isfinite(s.mean_bound) ? s.mean_bound : -1.0)
      .add("mean_noise", s.mean_noise)
      .add("mean_abs_bias", s.mean_abs_bias)
      .add("below_target", s.below_target)
      .add("predicted_error", std::isfinite(s.predicted_error) ? s.predicted_error : -1.0)
      .add("predicted_error_upper",
           std::isfinite(s.predicted_error_upper) ? s.predicted_error_upper : -1.0)
      .add("unknown_pixels", s.unknown_pixels);
  if (reference_) {
    FilmImage film;
    info.renderer.develop(&film);
    const CompareResult c =
        compare_images(packed(film_view(film)), *reference_, "render", "reference");
    line.add("mae", c.mean_abs_error).add("rmse", c.rmse).add("coverage", c.coverage);
  }
  out_ << line.str() << "\n" << std::flush;
  log_seconds_ += seconds_since(t0);
}

}  // namespace pb
