#include "photonbound/renderer.h"

#include "photonbound/compare.h"
#include "photonbound/gather.h"
#include "photonbound/parallel.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <future>
#include <sstream>

namespace pb {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Default initial radius: this many pixel footprints (median over measurement points).
constexpr double kFootprintsPerRadius = 4.0;
// R is clamped from below at this fraction of the scene size (ESTIMATOR.md section 8): far
// below it float positions cannot resolve the distance test anyway.
constexpr double kMinRadiusFraction = 1e-6;

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

PinholeCamera choose_camera(const Scene& scene, const RenderOptions& o) {
  const Camera* cam = nullptr;
  for (const Camera& c : scene.cameras) {
    if (o.camera.empty() || c.name == o.camera) {
      cam = &c;
      break;
    }
  }
  if (!cam)
    throw UsageError("--camera: " + scene.source + " has no perspective camera named '" + o.camera +
                     "'");
  int w = 512, h = 512;
  if (o.width && o.height) {
    w = *o.width;
    h = *o.height;
  } else {
    const float aspect = cam->aspect.value_or(1.0f);
    h = std::clamp(int(std::lround(512.0f / aspect)), 1, 16384);
  }
  return PinholeCamera(*cam, w, h);
}

Renderer::Renderer(const Scene& scene, const RenderOptions& options)
    : options_(options),
      world_(scene),
      camera_(choose_camera(scene, options)),
      tracer_(world_, options.direct == DirectMode::Photons) {
  const auto t0 = Clock::now();
  eye_ = run_eye_pass(world_, camera_, options_.max_depth);
  timings_.eye = seconds_since(t0);
  params_.alpha = options_.alpha;
  params_.photons_per_pass = double(options_.photons_per_pass);
  const double r_min = kMinRadiusFraction * world_.scene_size();
  params_.min_r2 = r_min * r_min;
  const double r0 = std::max(options_.radius ? *options_.radius : default_radius(), r_min);
  initial_radius_ = r0;
  PointState initial;
  initial.r2 = r0 * r0;
  states_.assign(eye_.points.size(), initial);
  radii_.assign(eye_.points.size(), search_radius(initial.r2));
}

double Renderer::default_radius() const {
  if (eye_.points.empty()) return 0.01 * world_.scene_size();
  const double r = kFootprintsPerRadius * double(eye_.median_footprint);
  return r > 0.0 && std::isfinite(r) ? r : 0.01 * world_.scene_size();
}

bool Renderer::radii_fixed() const {
  if (options_.alpha >= 1.0) return true;
  for (const PointState& s : states_)
    if (s.r2 > params_.min_r2) return false;
  return !states_.empty();
}

FilmSettings Renderer::film_settings() const {
  FilmSettings s;
  s.photons_per_pass = double(options_.photons_per_pass);
  s.confidence = options_.confidence;
  s.metric = options_.metric;
  s.target = options_.target_error.value_or(0.0);
  return s;
}

namespace {

// A checkpoint snapshot is written once and read later by another thread: non-temporal stores
// skip reading the destination's cache lines first and leave the cache to the pass's own data.
// PointState is 160 bytes (16-byte multiple) and the vector's storage is 16-byte aligned.
void stream_copy(PointState* dst, const PointState& src) {
#if defined(__SSE2__)
  static_assert(sizeof(PointState) % 16 == 0 && alignof(std::max_align_t) >= 16);
  const __m128i* s = reinterpret_cast<const __m128i*>(&src);
  __m128i* d = reinterpret_cast<__m128i*>(dst);
  for (size_t i = 0; i < sizeof(PointState) / 16; ++i)
    _mm_stream_si128(d + i, _mm_loadu_si128(s + i));
#else
  *dst = src;
#endif
}

void store_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace

void Renderer::step(std::vector<PointState>* copy) {
  const uint64_t pass = ++loop_.passes;
  auto t = Clock::now();
  const PhotonPassStats stats = tracer_.run(options_.seed, pass, options_.photons_per_pass, hits_);
  loop_.rays += stats.rays;
  loop_.photons += stats.paths;
  timings_.trace += seconds_since(t);

  const size_t n = states_.size();
  if (n == 0) return;
  t = Clock::now();
  hit_positions_.resize(hits_.size());
  parallel_for(hits_.size(), 16384, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) hit_positions_[k] = hits_[k].position;
  });
  grid_.build(hit_positions_, radii_);  // radii_ was filled by the previous update loop
  timings_.grid += seconds_since(t);

  t = Clock::now();
  const bool nee = options_.direct == DirectMode::NextEvent;
  if (copy) copy->resize(n);
  parallel_for(n, 256, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      PassGather g;
      gather_photons(eye_.points[k], states_[k].r2, grid_, hits_, g);
      if (nee) {
        Rng rng(options_.seed, pass, k, Stream::DirectLight);
        g.direct = direct_light(world_, eye_.points[k], rng);
      }
      accumulate_pass(states_[k], g, params_, pass);
      radii_[k] = search_radius(states_[k].r2);
      if (copy) stream_copy(&(*copy)[k], states_[k]);
    }
    if (copy) store_fence();  // the streamed stores are visible before the writer reads them
  });
  timings_.gather += seconds_since(t);
}

std::string Renderer::progress_line(const RenderReport& report, double run_seconds) const {
  const FilmSummary& s = report.summary;
  const uint64_t pass = report.passes;
  std::ostringstream line;
  line.precision(4);
  line << "pass " << pass << " | " << format_count(double(report.photons)) << " photons";
  if (pass >= 2) {
    line << " | bound " << s.mean_bound;
    if (options_.target_error) line << " | " << int(100.0 * s.below_target) << "% below target";
    line << " | " << s.unknown_pixels << " unknown";
  }
  line << " | " << report.seconds << " s";
  // Time left: the smallest of what the stop conditions imply; the target's from the observed
  // power-law decay of the mean bound since an earlier check.
  const double per_pass = report.seconds / double(pass);
  double left = INFINITY;
  if (options_.passes) left = std::min(left, double(*options_.passes - pass) * per_pass);
  if (options_.time_seconds) left = std::min(left, *options_.time_seconds - run_seconds);
  const uint64_t early = loop_.early_pass;
  if (options_.target_error && early > 0 && pass > early && s.mean_bound < loop_.early_bound &&
      s.mean_bound > *options_.target_error) {
    const double k = std::log(loop_.early_bound / s.mean_bound) / std::log(double(pass) / early);
    const double needed = double(pass) * std::pow(s.mean_bound / *options_.target_error, 1.0 / k);
    left = std::min(left, (needed - double(pass)) * per_pass);
  }
  if (std::isfinite(left)) line << " | ~" << std::max(0.0, left) << " s left";
  return line.str();
}

void Renderer::write_log_line(const RenderReport& report, const PassLog& log) const {
  const FilmSummary& s = report.summary;
  std::ostringstream line;
  line.precision(9);
  auto finite = [](double v) { return std::isfinite(v) ? v : -1.0; };  // JSON has no inf
  line << "{\"pass\": " << report.passes << ", \"seconds\": " << report.seconds
       << ", \"photons\": " << report.photons << ", \"mean_bound\": " << finite(s.mean_bound)
       << ", \"mean_noise\": " << s.mean_noise << ", \"mean_abs_bias\": " << s.mean_abs_bias
       << ", \"below_target\": " << s.below_target << ", \"unknown_pixels\": " << s.unknown_pixels;
  if (log.reference) {
    FilmImage film;
    develop(eye_, states_, report.passes, film_settings(), &film);
    const CompareResult c =
        compare_images(pack_channels(film), *log.reference, "render", "reference");
    line << ", \"mae\": " << c.mean_abs_error << ", \"rmse\": " << c.rmse
         << ", \"coverage\": " << c.coverage;
  }
  line << "}\n";
  *log.out << line.str() << std::flush;
}

RenderReport Renderer::run(const std::atomic<bool>* stop, std::ostream* progress,
                           const CheckpointPolicy& checkpoint, const PassLog& log) {
  RenderReport report;
  report.initial_radius = initial_radius_;
  const FilmSettings settings = film_settings();
  const auto t0 = Clock::now();
  const double seconds_before = loop_.seconds;
  double last_print = -1.0, last_checkpoint = 0.0, log_seconds = 0.0;
  if (loop_.next_check == 0) loop_.next_check = options_.min_passes;
  auto fill = [&] {
    report.passes = loop_.passes;
    report.photons = loop_.photons;
    report.rays = loop_.rays;
    report.seconds = loop_.seconds = seconds_before + seconds_since(t0);
  };
  // A resumed render that already did its passes does not run another one.
  if (options_.passes && loop_.passes >= *options_.passes) report.stop_reason = "passes";

  // The checkpoint in flight, if any: it returns its snapshot so the buffer is reused.
  std::future<SavedRender> pending;
  auto finish_pending = [&] {  // waits, rethrows a failed write, takes the buffer back
    const auto t_wait = Clock::now();
    SavedRender done = pending.get();
    checkpoint_states_ = std::move(done.states);
    timings_.checkpoint_stall += seconds_since(t_wait);
  };

  while (report.stop_reason.empty()) {
    // Snapshot this pass when a checkpoint is due and none is being written.
    const bool writer_idle =
        !pending.valid() || pending.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    if (pending.valid() && writer_idle) finish_pending();
    const bool snap = checkpoint.every > 0.0 && writer_idle &&
                      seconds_since(t0) - last_checkpoint >= checkpoint.every;
    step(snap ? &checkpoint_states_ : nullptr);
    fill();
    const uint64_t pass = loop_.passes;
    const double run_seconds = seconds_since(t0);

    const bool check = options_.target_error && pass >= loop_.next_check;
    const bool want_progress = progress && run_seconds - last_print >= 0.5;
    const bool want_log = log.out && log_seconds <= log.max_overhead * run_seconds;
    const bool developed = check || want_progress || want_log;
    if (developed) report.summary = develop(eye_, states_, pass, settings, nullptr);
    if (check) {
      // Sparse schedule (ESTIMATOR.md section 7): checks about 10% apart in pass count, so the
      // criterion is not retried after every pass (optional stopping).
      loop_.next_check = pass + std::max<uint64_t>(1, pass / 10);
      if (loop_.early_pass == 0 || pass >= 2 * loop_.early_pass) {
        loop_.early_pass = pass;
        loop_.early_bound = report.summary.mean_bound;
      }
    }

    if (options_.passes && pass >= *options_.passes) report.stop_reason = "passes";
    if (options_.time_seconds && run_seconds >= *options_.time_seconds) report.stop_reason = "time";
    if (check && report.summary.mean_bound <= *options_.target_error)
      report.stop_reason = "target-error";
    // A target below the bias cannot be reached once the radii can no longer shrink (alpha = 1,
    // or every radius at its floor): more passes only shrink the noise.
    if (check && report.summary.mean_bias_metric >= *options_.target_error && radii_fixed())
      report.stop_reason = "unreachable: the radius cannot shrink and the bias is above the target";
    if (stop && stop->load()) report.stop_reason = "interrupted";

    if (log.out && (want_log || !report.stop_reason.empty())) {
      const auto t_log = Clock::now();
      if (!developed) report.summary = develop(eye_, states_, pass, settings, nullptr);
      write_log_line(report, log);
      log_seconds += seconds_since(t_log);
    }
    if (want_progress || (progress && !report.stop_reason.empty())) {
      last_print = run_seconds;
      *progress << progress_line(report, run_seconds) << std::endl;
    }
    // The final image and state are written by the caller after run() returns, so a
    // snapshot of the last pass is not written here.
    if (snap && report.stop_reason.empty()) {
      const auto t_submit = Clock::now();
      last_checkpoint = run_seconds;
      SavedRender saved = snapshot_with(std::move(checkpoint_states_));
      pending = std::async(std::launch::async,
                           [this, &checkpoint, report, saved = std::move(saved)]() mutable {
                             const auto t_write = Clock::now();
                             checkpoint.write(report, saved);
                             timings_.checkpoint_write += seconds_since(t_write);
                             ++timings_.checkpoints;
                             return std::move(saved);
                           });
      timings_.checkpoint_stall += seconds_since(t_submit);
    }
  }
  if (pending.valid()) finish_pending();
  fill();
  report.summary = develop(eye_, states_, report.passes, settings, nullptr);
  return report;
}

void Renderer::restore(const SavedRender& saved) {
  if (saved.states.size() != states_.size())
    throw StateError("the state holds " + std::to_string(saved.states.size()) +
                     " measurement points but this scene and camera give " +
                     std::to_string(states_.size()));
  states_ = saved.states;
  for (size_t k = 0; k < states_.size(); ++k) radii_[k] = search_radius(states_[k].r2);
  loop_ = saved.loop;
  initial_radius_ = saved.initial_radius;
}

SavedRender Renderer::snapshot() const { return snapshot_with(states_); }

SavedRender Renderer::snapshot_with(std::vector<PointState> states) const {
  SavedRender s;
  s.options = options_;
  s.initial_radius = initial_radius_;
  s.loop = loop_;
  s.states = std::move(states);
  return s;
}

}  // namespace pb
