#include "render/renderer.h"

#include "render/pass_stages.h"
#include "render/ppm.h"
#include "render/scene_defaults.h"
#include "render/sppm.h"
#include "util/parallel.h"
#include "util/timer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pb {

namespace {

// Default initial radius: this many pixel footprints (median over visible points).
constexpr double kFootprintsPerRadius = 4.0;
// R is clamped from below at this fraction of the scene size (ESTIMATOR.md section 8).
constexpr double kMinRadiusFraction = 1e-6;
// The scene with what the options and the defaults add (scene_defaults.h); main has done it already
// and printed its notes, and doing it again changes nothing.
Scene completed(Scene scene, const RenderOptions& options) {
  complete_scene(scene, options);
  return scene;
}

std::unique_ptr<PhotonMethod> make_method(const World& world, const PinholeCamera& camera,
                                          const RenderOptions& options) {
  if (options.method == Method::PPM)
    return std::make_unique<PpmMethod>(world, camera, options.max_depth);
  // A followed lobe's direct light is its next-event sample (camera_paths.h).
  const bool nee = options.direct == DirectMode::NextEvent;
  return std::make_unique<SppmMethod>(
      world, camera,
      CameraPathSettings{options.max_depth, nee ? float(options.follow_roughness) : 0.0f,
                         options.adaptive_paths});
}

}  // namespace

double radius_floor(const World& world) { return kMinRadiusFraction * world.scene_size(); }

double default_initial_radius(const CameraPassResult& pass, const World& world) {
  double r = 0.01 * world.scene_size();
  if (pass.median_footprint > 0.0f) {
    const double f = kFootprintsPerRadius * double(pass.median_footprint);
    if (f > 0.0 && std::isfinite(f)) r = f;
  }
  return std::max(r, radius_floor(world));
}

Renderer::Renderer(Scene scene, const RenderOptions& options)
    : options_(options),
      world_(completed(std::move(scene), options), float(options.mirror_roughness),
             options.method == Method::SPPM),
      camera_(choose_camera(world_.scene(), options)),
      tracer_(world_, options.direct == DirectMode::Photons) {
  const auto t0 = Clock::now();
  method_ = make_method(world_, camera_, options_);
  timings_.camera = seconds_since(t0);
  params_.alpha = options_.alpha;
  params_.photons_per_pass = double(options_.photons_per_pass);
  params_.adaptive_radius = options_.adaptive_radius;
  const double r_min = radius_floor(world_);
  params_.min_r2 = r_min * r_min;
  initial_radius_ = options_.radius ? std::max(*options_.radius, r_min)
                                    : default_initial_radius(method_->camera_pass(), world_);
  // Radii only shrink: segments farther than the initial radius (as a float, what queries use)
  // from a triangle never matter to its points.
  PointState initial;
  initial.r2 = initial_radius_ * initial_radius_;
  // The states beside the boundary index: filling them is one thread's page faults (54 MB at
  // 512x512, 0.02 s, a tenth of what a 16-pass render spends outside its pass loop), and the
  // index is mostly serial too. (Faulting the first development's memory in on the other
  // thread meanwhile did not pay: 0.011 s less in the development, 0.012 s more here, the two
  // threads' faults contending.)
  parallel_invoke(
      [&] {
        states_.assign(method_->state_count(), initial);
        radii_.assign(states_.size(), search_radius(initial.r2));
      },
      [&] {
        boundary_ = BoundaryIndex(world_, std::nextafter(float(initial_radius_), INFINITY));
        method_->prepare(boundary_, initial_radius_);
      });
  max_photon_power_ = world_.lights().max_photon_flux();
  if (options_.adaptive_photons) guide_.emplace(world_.lights().emitter_count());
}

Renderer::~Renderer() = default;

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
  s.stop_fraction = options_.stop_fraction;
  s.bias_model = options_.bias_model;
  return s;
}

void Renderer::distribute(Exchange* exchange) {
  if (exchange && exchange->ranks() > 1) {
    if (options_.adaptive_photons)
      throw std::invalid_argument(
          "--adaptive photons does not run distributed yet (its learning needs every state on "
          "every rank); run it in one process, or without mpirun");
    exchange_ = exchange;
  } else {
    exchange_ = nullptr;
  }
}

void Renderer::collect() {
  if (!exchange_ || collected_ == work_.passes) return;
  if (exchange_->rank() == 0) exchange_->command(FollowerCommand::Collect);
  exchange_->share_owned(states_.data(), sizeof(PointState), states_.size(), false);
  for (const SideArray& a : method_->side_arrays())
    exchange_->share_owned(a.data, a.item_bytes, states_.size(), false);
  collected_ = work_.passes;
}

void Renderer::follow() {
  while (true) {
    switch (exchange_->command(FollowerCommand::End)) {
      case FollowerCommand::Pass:
        step();
        break;
      case FollowerCommand::Collect:
        collect();
        break;
      case FollowerCommand::End:
        return;
    }
  }
}

void Renderer::release_followers() {
  if (exchange_ && exchange_->rank() == 0) exchange_->command(FollowerCommand::End);
}

bool Renderer::step(std::vector<PointState>* copy, const Cutoff* cutoff) {
  const uint64_t pass = work_.passes + 1;
  auto t = Clock::now();
  const EmissionGuide* guide = guide_ ? &*guide_ : nullptr;
  uint64_t first = 0, last = options_.photons_per_pass;
  PhotonTracer::Combine combine;
  if (exchange_) {
    if (exchange_->rank() == 0) exchange_->command(FollowerCommand::Pass);
    cutoff = nullptr;  // the ranks could not agree where a pass was cut
    exchange_->photon_range(options_.photons_per_pass, first, last);
    combine = [this](std::vector<PhotonHit>& hits) { exchange_->all_hits(hits); };
  }
  PhotonPassStats stats = tracer_.run(options_.seed, pass, first, last, hits_, cutoff, guide,
                                      exchange_ ? &combine : nullptr);
  if (exchange_) {
    stats.rays = exchange_->sum(stats.rays);
    stats.paths = exchange_->sum(stats.paths);
  }
  timings_.trace += seconds_since(t);
  if (stats.cut) return false;

  const size_t n = states_.size();
  if (n > 0) {
    if (cutoff && cutoff->reached()) return false;
    t = Clock::now();
    build_photon_grid(hits_, radii_, hit_positions_, grid_);  // radii_ from the previous fold
    timings_.grid += seconds_since(t);

    t = Clock::now();
    if (copy) copy->resize(n);
    GuideInputs learn;
    if (guide_) {
      tally_.begin_pass(guide_->cells(), (kFoldBlock + kStageChunk - 1) / kStageChunk);
      learn = {&tally_, work_.passes, double(options_.photons_per_pass)};
    }
    const PassInputs in{world_,
                        grid_,
                        hits_,
                        params_,
                        boundary_on_ ? &boundary_ : nullptr,
                        options_.seed,
                        pass,
                        options_.direct == DirectMode::NextEvent,
                        cutoff,
                        learn,
                        work_.photons > 0 ? double(work_.rays) / double(work_.photons) : 2.0,
                        exchange_ ? Share{exchange_->rank(), exchange_->ranks()} : Share{},
                        kPeakWeight * max_photon_power_ / double(options_.photons_per_pass),
                        exchange_};
    // A distributed pass copies after collecting (below): the copy needs every rank's states.
    const bool whole =
        method_->step(in, states_, radii_, copy && !exchange_ ? copy->data() : nullptr);
    // Every rank builds the next grid for every state's radius.
    if (exchange_) exchange_->share_owned(radii_.data(), sizeof(float), radii_.size(), true);
    timings_.gather += seconds_since(t);
    if (!whole) return false;
  }
  // Only a whole pass counts: a pass cut short has changed none of what follows.
  work_.passes = pass;
  work_.rays += stats.rays;
  work_.photons += stats.paths;
  max_photon_power_ = std::max(max_photon_power_, double(stats.max_flux));
  if (exchange_ && copy && exchange_->rank() == 0) {
    collect();
    *copy = states_;
  }
  if (guide_ && n > 0) {
    // The next pass's photons come from what this one learnt: their largest power is the
    // lights' times the guide's largest weight (the sparse-photon bound's Phi_max, section 12).
    guide_->learn(tally_.sums());
    max_photon_power_ =
        std::max(max_photon_power_, world_.lights().max_photon_flux() * guide_->max_weight());
  }
  return true;
}

RenderState Renderer::snapshot(std::vector<PointState> states) const {
  RenderState s;
  s.work = work_;
  s.initial_radius = initial_radius_;
  s.states = std::move(states);
  method_->save(s);
  s.max_photon_power = max_photon_power_;
  if (guide_) {
    s.guide = guide_->histogram();
    s.guide_learnt = guide_->learnt();
  }
  return s;
}

void Renderer::restore(const RenderState& saved) {
  if (saved.states.size() != states_.size())
    throw StateError("the state holds " + std::to_string(saved.states.size()) +
                     " visible points but this scene and camera give " +
                     std::to_string(states_.size()));
  method_->restore(saved);
  states_ = saved.states;
  max_photon_power_ = saved.max_photon_power;
  if (guide_) {
    try {
      guide_->restore(saved.guide, saved.guide_learnt);
    } catch (const std::invalid_argument& e) {
      throw StateError(e.what());
    }
  } else if (!saved.guide.empty()) {
    throw StateError(
        "the state holds a photon guide but this render has --adaptive without photons");
  }
  for (size_t k = 0; k < states_.size(); ++k) radii_[k] = search_radius(states_[k].r2);
  work_ = saved.work;
  initial_radius_ = saved.initial_radius;
  collected_ = work_.passes;  // every rank restored the same states
}

PixelLayout Renderer::layout(const std::vector<PointState>& states, const RenderState* saved,
                             double max_photon_power) const {
  PixelLayout l = method_->layout(states, saved);
  l.photon_cap = kPeakWeight * max_photon_power / double(options_.photons_per_pass);
  l.footprint = method_->camera_pass().median_footprint;
  return l;
}

PixelLayout Renderer::layout() const { return layout(states_, nullptr, max_photon_power_); }

FilmSummary Renderer::develop(FilmImage* image) const {
  return develop(states_, nullptr, work_.passes, max_photon_power_, image);
}

FilmSummary Renderer::develop(const RenderState& state, FilmImage* image) const {
  return develop(state.states, &state, state.work.passes, state.max_photon_power, image);
}

FilmSummary Renderer::develop(const std::vector<PointState>& states, const RenderState* saved,
                              uint64_t passes, double max_photon_power, FilmImage* image) const {
  return pb::develop(layout(states, saved, max_photon_power), states, passes, film_settings(),
                     image, &develop_memory_);
}

}  // namespace pb
