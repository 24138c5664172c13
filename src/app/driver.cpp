#include "app/driver.h"

#include "util/timer.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace pb {

std::string stop_text(StopReason reason) {
  switch (reason) {
    case StopReason::None:
      return "";
    case StopReason::Passes:
      return "passes";
    case StopReason::Time:
      return "time";
    case StopReason::TargetError:
      return "target-error";
    case StopReason::Unreachable:
      return "unreachable: the radius cannot shrink and the bias is above the target";
    case StopReason::ModelRefuted:
      return "unreachable: the bias model fails at this radius; start with a smaller --radius";
    case StopReason::Interrupted:
      return "interrupted";
  }
  return "";
}

double tested_quantity(const RenderOptions& o, const FilmSummary& s) {
  switch (o.stop_rule) {
    case StopRule::MeanError:
      return s.predicted_error_upper;
    case StopRule::MeanBound:
      return s.unknown_pixels ? INFINITY : s.mean_bound;
    case StopRule::Pixels:
      return s.pixel_quantile_bound;
  }
  return INFINITY;
}

std::string tested_name(const RenderOptions& o) {
  switch (o.stop_rule) {
    case StopRule::MeanError:
      return "mean error";
    case StopRule::MeanBound:
      return "mean bound";
    case StopRule::Pixels:
      return number_text(100.0 * o.stop_fraction) + "% of pixels";
  }
  return "";
}

namespace {

// The exponent k of the power law U ~ passes^-k through two tests; NaN where the quantity did not
// fall, either is not finite (a test with a pixel unknown), or there is no earlier test.
double falling_slope(uint64_t pass, double value, uint64_t early_pass, double early_value) {
  if (!(early_pass > 0 && pass > early_pass && std::isfinite(value) && value > 0.0 &&
        value < early_value && std::isfinite(early_value)))
    return NAN;
  return std::log(early_value / value) / std::log(double(pass) / double(early_pass));
}

}  // namespace

double passes_at_fall(uint64_t pass, double value, double k, double target) {
  return double(pass) * std::pow(value / target, 1.0 / k);
}

double passes_to_target(uint64_t pass, double value, uint64_t early_pass, double early_value,
                        double target) {
  const double k = falling_slope(pass, value, early_pass, early_value);
  return std::isnan(k) || !(target > 0.0) ? NAN : passes_at_fall(pass, value, k, target);
}

uint64_t next_check_after(uint64_t pass, double value, uint64_t early_pass, double early_value,
                          double target) {
  // The regular schedule: about 10% of the pass count apart (optional stopping: the criterion
  // is not retried after every pass). A test lands on average 5% of the passes after the
  // quantity crossed the target, and where two renders' predictions differ by 1.5% one may stop
  // a whole test, 10% of its time, after the other (ESTIMATOR.md section 15); and a test costs a
  // development, about a pass at 512x512. So the power law through this test and an earlier one
  // moves the next test: to the crossing where that comes before the next regular test (at
  // least 2.5% of the passes on: the tests near the target at most four times as dense), and
  // three quarters of the way to it where it comes later, with the exponent taken as at least
  // kSlowestFall and the test at most at twice the passes (a quantity that barely fell between
  // two close tests, as where --adaptive paths begins, may fall fast after them; one that
  // stopped falling is still tested, and the "unreachable" rule with it).
  const uint64_t regular = pass + std::max<uint64_t>(1, pass / 10);
  const uint64_t nearest = pass + std::max<uint64_t>(1, pass / 40);
  const double k = falling_slope(pass, value, early_pass, early_value);
  if (!(value > target && target > 0.0) || std::isnan(k)) return regular;
  const double needed = passes_at_fall(pass, value, k, target);
  if (needed < double(regular)) return std::clamp(uint64_t(std::ceil(needed)), nearest, regular);
  const double far = passes_at_fall(pass, value, std::max(k, kSlowestFall), target);
  const double later = std::min(double(pass) + 0.75 * (far - double(pass)), 2.0 * double(pass));
  return std::max(regular, uint64_t(std::ceil(later)));
}

// What the stop line reports: the quantity the stop rule tests, then the mean bound.
std::string stop_figures(const RenderOptions& o, const FilmSummary& s) {
  std::ostringstream out;
  const double tested = tested_quantity(o, s);  // what the progress line shows, too
  if (o.stop_rule != StopRule::MeanBound && std::isfinite(tested))
    out << tested_name(o) << " <= " << tested << " at " << number_text(100.0 * o.confidence)
        << "%, ";
  // The mean is over the known pixels: say how many it leaves out (+inf, not small). Over a
  // minority of them it is not the image's figure (issue 37: the known pixels may be the
  // background alone, of bound 0): then the line gives no mean at all.
  const uint64_t pixels = s.pixels;
  const uint64_t known = pixels - std::min(pixels, s.unknown_pixels);
  if (s.unknown_pixels > 0 && std::isfinite(s.mean_bound) && 2 * known <= pixels)
    out << "mean bound unknown: " << s.unknown_pixels << " of " << pixels
        << " pixels have no bound yet";
  else
    out << "mean bound " << s.mean_bound;
  if (s.unknown_pixels > 0 && std::isfinite(s.mean_bound) && 2 * known > pixels)
    out << " over the " << known << " known pixels of " << pixels << ", " << s.unknown_pixels
        << " unknown";
  return out.str();
}

Driver::Driver(Renderer& renderer, DriverState state) : renderer_(renderer), state_(state) {}

RenderReport Driver::run(const std::atomic<bool>* interrupt,
                         std::span<PassObserver* const> observers) {
  const RenderOptions& o = renderer_.options();
  const auto t0 = Clock::now();
  const double seconds_before = state_.seconds;
  if (state_.next_check == 0) state_.next_check = o.min_passes;
  RenderReport report;
  bool developed = false;
  double develop_seconds = 0.0;  // this pass's develop
  // `with_image`: the image is developed too, where the render may stop on this development
  // (the closing write then does not develop the same states again: a development of the
  // default scene costs about a pass). A development without it puts an earlier one's image
  // aside in `spare`, whose planes the next image fills again: fresh planes each time were
  // faulted in page by page (166 MB at 1920x1080, a tenth of a development there).
  std::optional<FilmImage> spare;
  auto develop = [&](bool with_image = false) {
    const auto start = Clock::now();
    renderer_.collect();  // a distributed render: every rank's states, here
    if (with_image && !report.film) {
      if (spare)
        report.film.swap(spare);
      else
        report.film.emplace();
    }
    if (!with_image && report.film) spare.swap(report.film);
    report.summary = renderer_.develop(with_image ? &*report.film : nullptr);
    developed = true;
    develop_seconds = seconds_since(start);
  };
  // A resumed render that already did its passes does not run another one.
  if (o.passes && renderer_.passes() >= *o.passes) report.stop = StopReason::Passes;
  // Ctrl-C and the end of --time cut the pass in progress (docs/usage.md "Stop rules").
  std::optional<Clock::time_point> deadline;
  if (o.time_seconds)
    deadline = t0 + std::chrono::duration_cast<Clock::duration>(
                        std::chrono::duration<double>(*o.time_seconds));
  const Cutoff cutoff = flag_or_deadline(interrupt, deadline);

  while (report.stop == StopReason::None) {
    const double before = seconds_since(t0);
    std::vector<PointState>* snapshot = nullptr;
    for (PassObserver* obs : observers)
      if (!snapshot) snapshot = obs->snapshot_buffer(before);
    const bool whole = renderer_.step(snapshot, &cutoff);
    const uint64_t pass = renderer_.passes();
    const double run_seconds = seconds_since(t0);
    state_.seconds = seconds_before + run_seconds;
    if (!whole) {
      // The render is the last whole pass's: its summary, told again with the stop (observers
      // do not repeat a pass they have written).
      report.stop = interrupt && interrupt->load() ? StopReason::Interrupted : StopReason::Time;
      develop(true);
      const PassInfo info{renderer_, state_,         pass,        run_seconds,
                          true,      report.summary, report.stop, develop_seconds};
      for (PassObserver* obs : observers) obs->after_pass(info);
      break;
    }

    const bool check = o.target_error && pass >= state_.next_check;
    bool want = check;
    const uint64_t next_test = o.target_error ? state_.next_check : 0;
    for (PassObserver* obs : observers)
      want = obs->wants_summary(pass, run_seconds, next_test) || want;
    developed = false;
    develop_seconds = 0.0;
    // A stop test develops the image with its summary: if the render stops here, that is the
    // image it writes (before, a target stop developed the same states twice).
    if (want) develop(check);
    if (check) {
      // Sparse schedule (ESTIMATOR.md section 7), drawn in where the crossing is near.
      const double tested = tested_quantity(o, report.summary);
      state_.next_check =
          next_check_after(pass, tested, state_.early_pass, state_.early_value, *o.target_error);
      if (state_.early_pass == 0 || pass >= 2 * state_.early_pass) {
        state_.early_pass = pass;
        state_.early_value = tested;
      }
    }

    if (o.passes && pass >= *o.passes) report.stop = StopReason::Passes;
    if (o.time_seconds && run_seconds >= *o.time_seconds) report.stop = StopReason::Time;
    // Success needs every pixel's bound: pixels left out of a mean cannot be within a target.
    // The means are +inf while a pixel is unknown; the pixel share's quantile is not (it may
    // leave the unknown pixels above it), so no rule stops on the target with a pixel unknown
    // (issue 37: every unknown pixel has a visible point, or has had fewer than 2 passes).
    if (check && report.summary.unknown_pixels == 0 &&
        tested_quantity(o, report.summary) <= *o.target_error)
      report.stop = StopReason::TargetError;
    // A target below the bias cannot be reached once the radii can no longer shrink (alpha = 1,
    // or every radius at its floor): more passes only shrink the noise.
    if (check && report.summary.mean_bias_metric >= *o.target_error && renderer_.radii_fixed())
      report.stop = StopReason::Unreachable;
    // Where the samples' drift with R^2 refutes the bias model (section 11b) every bound is
    // unknown, and stays so for a long time: the disagreement grows with the passes, and the
    // radius shrinks only as passes^-0.2 or so at the default alpha. Say so now rather than run
    // to the budget.
    if (check && report.summary.model_refuted) report.stop = StopReason::ModelRefuted;
    if (interrupt && interrupt->load()) report.stop = StopReason::Interrupted;

    if (report.stop != StopReason::None && !developed) develop(true);
    const PassInfo info{renderer_, state_,         pass,        run_seconds,
                        developed, report.summary, report.stop, develop_seconds};
    for (PassObserver* obs : observers) obs->after_pass(info);
    // A test that did not stop has no image to report; its planes are the next test's.
    if (report.stop == StopReason::None && report.film) spare.swap(report.film);
  }
  for (PassObserver* obs : observers) obs->finish();
  if (!developed) develop(true);
  report.work = renderer_.work();
  report.seconds = state_.seconds;
  return report;
}

}  // namespace pb
