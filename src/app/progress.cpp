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

bool ProgressPrinter::wants_summary(uint64_t, double run_seconds) {
  return run_seconds - last_print_ >= interval();
}

void ProgressPrinter::after_pass(const PassInfo& info) {
  if (info.pass == printed_) return;
  if (info.developed) develop_seconds_ = info.develop_seconds;
  if (info.stop == StopReason::None && !(info.run_seconds - last_print_ >= 0.5 && info.developed))
    return;
  last_print_ = info.run_seconds;
  printed_ = info.pass;
  out_ << line(info) << std::endl;
}

std::string ProgressPrinter::line(const PassInfo& info) {
  const RenderOptions& o = info.renderer.options();
  const FilmSummary& s = info.summary;
  const uint64_t pass = info.pass;
  const double seconds = info.schedule.seconds;
  std::ostringstream line;
  line.precision(4);
  line << "pass " << pass << " | " << format_count(double(info.renderer.work().photons))
       << " photons";
  const double tested = tested_quantity(o, s);
  if (pass >= 2) {
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
  // Time left: the smallest of what the stop conditions imply. The target's comes from the
  // power-law decay of the tested quantity since an earlier test; once the quantity is at the
  // target it is the time to the next scheduled test, never the rest of the budget.
  const double per_pass = seconds / double(pass);
  double left = INFINITY;
  if (o.passes) left = std::min(left, double(*o.passes - pass) * per_pass);
  if (o.time_seconds) left = std::min(left, *o.time_seconds - info.run_seconds);
  if (o.target_error && std::isfinite(tested)) {
    const uint64_t next = std::max(info.schedule.next_check, pass);
    const double to_check = double(next - pass) * per_pass;
    const uint64_t early = info.schedule.early_pass;
    const double early_value = info.schedule.early_value;
    if (tested <= *o.target_error) {
      left = std::min(left, to_check);
    } else if (const double needed =
                   passes_to_target(pass, tested, early, early_value, *o.target_error);
               std::isfinite(needed)) {
      left = std::min(left, std::max((needed - double(pass)) * per_pass, to_check));
    }
  }
  if (std::isfinite(left)) line << " | ~" << std::max(0.0, left) << " s left";
  return line.str();
}

bool PassLogger::wants_summary(uint64_t, double run_seconds) {
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
    const CompareResult c = compare_images(pack_channels(film), *reference_, "render", "reference");
    line.add("mae", c.mean_abs_error).add("rmse", c.rmse).add("coverage", c.coverage);
  }
  out_ << line.str() << "\n" << std::flush;
  log_seconds_ += seconds_since(t0);
}

}  // namespace pb
