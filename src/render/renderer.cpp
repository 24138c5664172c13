#include "render/renderer.h"

#include "render/camera_paths.h"
#include "util/parallel.h"
#include "render/pass_stages.h"
#include "render/scene_setup.h"
#include "util/timer.h"

#include <algorithm>
#include <cmath>

namespace pb {

namespace {

// Default initial radius: this many pixel footprints (median over measurement points).
constexpr double kFootprintsPerRadius = 4.0;
// R is clamped from below at this fraction of the scene size (ESTIMATOR.md section 8).
constexpr double kMinRadiusFraction = 1e-6;
// Points per fold block: the pass sums of a block are gathered (stages 3-4) into one array,
// then folded (stage 5). 16384 points keep the block's sums (1.3 MB) and states (2.6 MB) in the
// last-level cache between the two, and the array exists whole for a distributed reduction.
constexpr size_t kFoldBlock = 16384;

// The scene with what the options and the defaults add (scene_setup.h); main has done it already
// and printed its notes, and doing it again changes nothing.
Scene completed(Scene scene, const RenderOptions& options) {
  complete_scene(scene, options);
  return scene;
}

}  // namespace

double min_radius(const World& world) { return kMinRadiusFraction * world.scene_size(); }

double default_initial_radius(const EyePassResult& eye, const World& world) {
  double r = 0.01 * world.scene_size();
  if (eye.median_footprint > 0.0f) {
    const double f = kFootprintsPerRadius * double(eye.median_footprint);
    if (f > 0.0 && std::isfinite(f)) r = f;
  }
  return std::max(r, min_radius(world));
}

Renderer::Renderer(Scene scene, const RenderOptions& options)
    : options_(options),
      world_(completed(std::move(scene), options), float(options.mirror_roughness),
             options.method == Method::SPPM),
      camera_(choose_camera(world_.scene(), options)),
      tracer_(world_, options.direct == DirectMode::Photons) {
  const auto t0 = Clock::now();
  size_t states = 0;
  if (options_.method == Method::PPM) {
    eye_ = run_eye_pass(world_, camera_, options_.max_depth);
    states = eye_.points.size();
  } else {
    // SPPM keeps no points: the default radius comes from the footprints of a sample of
    // pixel-centre paths (every 4th pixel each way).
    eye_.width = camera_.width();
    eye_.height = camera_.height();
    eye_.median_footprint = median_footprint(world_, camera_, options_.max_depth, 4);
    states = size_t(eye_.width) * size_t(eye_.height);
    visible_.assign(states, 0);
    min_mass_.assign(states, 1.0f);
    glossy_f_.assign(states, 0.0f);
  }
  timings_.eye = seconds_since(t0);
  params_.alpha = options_.alpha;
  params_.photons_per_pass = double(options_.photons_per_pass);
  const double r_min = min_radius(world_);
  params_.min_r2 = r_min * r_min;
  initial_radius_ =
      options_.radius ? std::max(*options_.radius, r_min) : default_initial_radius(eye_, world_);
  // Radii only shrink: segments farther than the initial radius (as a float, what queries use)
  // from a triangle never matter to its points.
  boundary_ = BoundaryIndex(world_, std::nextafter(float(initial_radius_), INFINITY));
  if (options_.method == Method::PPM) {
    clearance_.resize(eye_.points.size());
    const float r0 = search_radius(initial_radius_ * initial_radius_);
    parallel_for(eye_.points.size(), 4096, [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) {
        const MeasurementPoint& p = eye_.points[k];
        clearance_[k] = boundary_.clearance(p.triangle, p.position, r0);
      }
    });
  }
  max_photon_power_ = world_.lights().max_photon_flux();
  // The largest BRDF of any Lambertian surface a visible point can lie on (the sparse-photon
  // bound); glossy points bound theirs with Bsdf::max_f (capped_points_, glossy_f_).
  const vec3 up(0.0f, 0.0f, 1.0f);
  for (const Material& m : world_.scene().materials)
    if (Bsdf(m, up, up, world_.mirror_roughness()).is_lambertian())
      max_f_ = glm::max(max_f_, lambertian(m.base_color));
  if (!eye_.glossy.empty()) {
    capped_points_ = eye_.points;
    for (const GlossyPoint& g : eye_.glossy) capped_points_[g.point].f *= g.bsdf.max_f(g.wo);
  }
  PointState initial;
  initial.r2 = initial_radius_ * initial_radius_;
  states_.assign(states, initial);
  radii_.assign(states, search_radius(initial.r2));
  sums_.resize(std::min(kFoldBlock, states_.size()));
  if (options_.method == Method::SPPM) {
    visible_points_.resize(sums_.size());
    visible_glossy_.resize(sums_.size());
  }
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
  s.stop_fraction = options_.stop_fraction;
  return s;
}

void Renderer::step(std::vector<PointState>* copy) {
  const uint64_t pass = ++work_.passes;
  auto t = Clock::now();
  const PhotonPassStats stats = tracer_.run(options_.seed, pass, options_.photons_per_pass, hits_);
  work_.rays += stats.rays;
  work_.photons += stats.paths;
  max_photon_power_ = std::max(max_photon_power_, double(stats.max_flux));
  timings_.trace += seconds_since(t);

  const size_t n = states_.size();
  if (n == 0) return;
  t = Clock::now();
  build_photon_grid(hits_, radii_, hit_positions_, grid_);  // radii_ from the previous fold
  timings_.grid += seconds_since(t);

  t = Clock::now();
  const bool nee = options_.direct == DirectMode::NextEvent;
  if (copy) copy->resize(n);
  const BoundaryIndex* boundary = boundary_on_ ? &boundary_ : nullptr;
  const PassInputs in{world_,        grid_, hits_, params_,     boundary,
                      options_.seed, pass,  nee,   eye_.glossy, clearance_};
  PointState* const out = copy ? copy->data() : nullptr;
  if (options_.method == Method::PPM) {
    gather_and_fold(in, eye_.points, states_, radii_, sums_, out);
  } else {
    // A followed lobe's direct light is its next-event sample (camera_paths.h).
    const float follow = nee ? float(options_.follow_roughness) : 0.0f;
    const CameraPathInputs cam{world_, camera_, options_.max_depth, follow, options_.seed, pass,
                               nee,    boundary};
    sppm_gather_and_fold(in, cam, states_, radii_, visible_, min_mass_, glossy_f_, visible_points_,
                         visible_glossy_, sums_, out);
  }
  timings_.gather += seconds_since(t);
}

RenderState Renderer::snapshot(std::vector<PointState> states) const {
  RenderState s;
  s.work = work_;
  s.initial_radius = initial_radius_;
  s.states = std::move(states);
  s.visible = visible_;
  s.min_mass = min_mass_;
  s.max_photon_power = max_photon_power_;
  s.glossy_f = glossy_f_;
  return s;
}

void Renderer::restore(const RenderState& saved) {
  if (saved.states.size() != states_.size())
    throw StateError("the state holds " + std::to_string(saved.states.size()) +
                     " measurement points but this scene and camera give " +
                     std::to_string(states_.size()));
  if (saved.visible.size() != visible_.size())
    throw StateError("the state holds " + std::to_string(saved.visible.size()) +
                     " SPPM pixel counters but this render has " + std::to_string(visible_.size()));
  if (saved.min_mass.size() != min_mass_.size())
    throw StateError("the state holds " + std::to_string(saved.min_mass.size()) +
                     " SPPM kernel masses but this render has " + std::to_string(min_mass_.size()));
  if (saved.glossy_f.size() != glossy_f_.size())
    throw StateError("the state holds " + std::to_string(saved.glossy_f.size()) +
                     " SPPM glossy caps but this render has " + std::to_string(glossy_f_.size()));
  states_ = saved.states;
  visible_ = saved.visible;
  min_mass_ = saved.min_mass;
  glossy_f_ = saved.glossy_f;
  max_photon_power_ = saved.max_photon_power;
  for (size_t k = 0; k < states_.size(); ++k) radii_[k] = search_radius(states_[k].r2);
  work_ = saved.work;
  initial_radius_ = saved.initial_radius;
}

PixelLayout Renderer::layout(const View& v) const {
  PixelLayout l = options_.method == Method::PPM ? layout_of(eye_) : PixelLayout{};
  if (options_.method == Method::SPPM) {
    l.width = eye_.width;
    l.height = eye_.height;
    l.visible_passes = v.visible;
    l.max_f = max_f_;
    l.glossy_f = v.glossy_f;
    l.mass = v.min_mass;
  } else {
    if (!capped_points_.empty()) l.point_f = colours_of(capped_points_);
    // Each point's disc's kernel mass at the current radius (the sparse-photon bound and the
    // validity of the bias model need it; points within their clearance are whole).
    l.mass.assign(v.states.size(), 1.0f);
    parallel_for(v.states.size(), 1024, [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) {
        const MeasurementPoint& p = eye_.points[k];
        const float r = search_radius(v.states[k].r2);
        if (!clearance_.empty() && r <= clearance_[k]) continue;  // the whole disc: mass 1
        l.mass[k] = float(boundary_.moments(p.triangle, p.position, p.normal, r).mass);
      }
    });
  }
  l.photon_cap = kPeakWeight * v.max_photon_power / double(options_.photons_per_pass);
  l.footprint = eye_.median_footprint;
  return l;
}

PixelLayout Renderer::layout() const { return layout(view()); }

FilmSummary Renderer::develop(FilmImage* image) const { return develop(view(), image); }

FilmSummary Renderer::develop(const RenderState& state, FilmImage* image) const {
  return develop(view(state), image);
}

FilmSummary Renderer::develop(const View& v, FilmImage* image) const {
  return pb::develop(layout(v), v.states, v.work.passes, film_settings(), image);
}

}  // namespace pb
