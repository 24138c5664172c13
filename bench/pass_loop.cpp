// The renderer's pass loop, phase by phase (Renderer::step), with and without error estimation,
// and the grid rebuild after the radii have shrunk 100x.
#include "bench.h"
#include "plain.h"

#include "options/options.h"
#include "render/pass_stages.h"
#include "render/ppm.h"
#include "render/renderer.h"
#include "scene/camera.h"
#include "util/parallel.h"
#include "util/rng.h"

#include <algorithm>
#include <cmath>

namespace bench {

namespace {

constexpr double kAlpha = 0.7;  // the renderer's default --alpha (option table)
constexpr size_t kGrain = 256;

struct Phase {
  std::vector<double> t;
  void add(double t0) { t.push_back(seconds_since(t0)); }
  double median() const { return bench::median(t); }
};

// Renderer::step's stages 3-5 for PPM: pb::ppm_pass over fold blocks of 16384 points.
void gather_on(const pb::World& world, const pb::CameraPassResult& eye, const pb::HashGrid& grid,
               const std::vector<pb::PhotonHit>& hits, const pb::EstimatorParams& params,
               uint64_t pass, std::vector<pb::PointState>& states, std::vector<float>& radii,
               std::vector<pb::PassSums>& sums, std::vector<pb::OwnerValues>& owner,
               std::vector<pb::RegionTable>& regions) {
  const pb::PassInputs in{.world = world,
                          .grid = grid,
                          .hits = hits,
                          .params = params,
                          .boundary = nullptr,
                          .seed = kSeed,
                          .pass = pass,
                          .next_event = true};
  pb::ppm_pass(in, eye.points, {}, {}, states, radii, sums, owner, nullptr, regions);
}

// The same without error estimation: no Laplacian sum (gather_photons<false>) and the PPM update
// without streaming moments (plain.h).
void gather_off(const pb::World& world, const pb::CameraPassResult& eye, const pb::HashGrid& grid,
                const std::vector<pb::PhotonHit>& hits, const pb::EstimatorParams& params,
                uint64_t pass, std::vector<PlainState>& states) {
  pb::parallel_for(states.size(), kGrain, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      pb::PassSums g;
      pb::gather_photons<false>(eye.points[k], states[k].r2, grid, hits, g);
      pb::Rng rng(kSeed, pass, k, pb::Stream::DirectLight);
      const pb::dvec3 direct = pb::direct_light(world, eye.points[k], rng);
      accumulate_plain(states[k], g, direct, params.alpha, params.min_r2);
    }
  });
}

}  // namespace

EyeSetup eye_setup(const pb::World& world, int width, int height) {
  EyeSetup s;
  const pb::PinholeCamera camera(world.scene().cameras.at(0), width, height);
  const double t0 = now();
  s.eye = pb::run_camera_pass(world, camera, pb::RenderOptions{}.max_depth);
  s.seconds = seconds_since(t0);
  const double r_min = pb::radius_floor(world);
  s.min_r2 = r_min * r_min;
  s.r0 = pb::default_initial_radius(s.eye, world);
  return s;
}

PassLoop pass_loop(const pb::World& world, const EyeSetup& setup, uint64_t photons, int passes,
                   int build_reps) {
  const pb::CameraPassResult& eye = setup.eye;
  const size_t n = eye.points.size();
  pb::EstimatorParams params;
  params.alpha = kAlpha;
  params.photons_per_pass = double(photons);
  params.min_r2 = setup.min_r2;
  pb::PointState initial;
  initial.r2 = setup.r0 * setup.r0;
  std::vector<pb::PointState> on(n, initial);
  PlainState plain_initial;
  plain_initial.r2 = initial.r2;
  std::vector<PlainState> off(n, plain_initial);

  pb::PhotonTracer tracer(world, false);
  pb::HashGrid grid;
  std::vector<pb::PhotonHit> hits;
  std::vector<pb::vec3> positions;
  std::vector<float> radii(n, pb::search_radius(initial.r2));
  std::vector<pb::PassSums> sums(std::min<size_t>(n, 16384));
  std::vector<pb::OwnerValues> owner(sums.size());
  std::vector<pb::RegionTable> regions((sums.size() + pb::kStageChunk - 1) / pb::kStageChunk);
  std::vector<pb::dvec3> direct(n);  // the next-event-only timing writes here
  Phase trace, build, t_on, t_off, t_nee;
  double stored = 0.0;

  for (int p = 1; p <= passes; ++p) {
    const uint64_t pass = uint64_t(p);
    double t0 = now();
    tracer.run(kSeed, pass, 0, photons, hits);
    trace.add(t0);
    stored += double(hits.size());

    t0 = now();
    pb::build_photon_grid(hits, radii, positions, grid);  // radii from the last fold
    build.add(t0);

    // Alternate the order so neither variant always finds the other's data in the caches.
    for (int v = 0; v < 2; ++v) {
      t0 = now();
      if ((v == 0) == (p % 2 == 1)) {
        gather_on(world, eye, grid, hits, params, pass, on, radii, sums, owner, regions);
        t_on.add(t0);
      } else {
        gather_off(world, eye, grid, hits, params, pass, off);
        t_off.add(t0);
      }
    }
    t0 = now();
    pb::parallel_for(n, kGrain, [&](size_t begin, size_t end) {
      for (size_t k = begin; k < end; ++k) {
        pb::Rng rng(kSeed, pass, k, pb::Stream::DirectLight);
        direct[k] = pb::direct_light(world, eye.points[k], rng);
      }
    });
    t_nee.add(t0);
  }

  PassLoop r;
  r.passes = passes;
  r.points = n;
  r.hits_per_pass = stored / passes;
  r.trace = trace.median();
  r.gather_on = t_on.median();
  r.gather_off = t_off.median();
  r.nee = t_nee.median();

  for (size_t k = 0; k < n; ++k) {
    if (on[k].tau != off[k].tau || on[k].r2 != off[k].r2) ++r.tau_mismatches;
    r.gathered += double(on[k].photons);
  }
  r.gathered /= double(std::max<size_t>(n, 1)) * passes;

  // The build alone is short and the machine noisy: time it again, repeatedly, on the last
  // pass's photons and radii; then with every radius 100x smaller (R^2 / 10^4).
  for (int rep = 0; rep < build_reps; ++rep) {
    const double t0 = now();
    pb::build_photon_grid(hits, radii, positions, grid);
    build.add(t0);
  }
  r.grid_build = build.median();
  r.grid_levels = grid.level_count();
  r.grid_bytes = grid.memory_bytes();
  for (size_t k = 0; k < n; ++k) {
    on[k].r2 = std::max(on[k].r2 * 1e-4, params.min_r2);
    radii[k] = pb::search_radius(on[k].r2);
  }
  Phase sbuild, sgather;
  for (int rep = 0; rep < build_reps; ++rep) {
    const double t0 = now();
    pb::build_photon_grid(hits, radii, positions, grid);
    sbuild.add(t0);
  }
  for (int rep = 0; rep < 2; ++rep) {
    std::vector<pb::PointState> scratch = on;
    std::vector<float> scratch_radii = radii;
    const double t0 = now();
    gather_on(world, eye, grid, hits, params, uint64_t(passes + 1), scratch, scratch_radii, sums,
              owner, regions);
    sgather.add(t0);
  }
  r.shrunk_grid_build = sbuild.median();
  r.shrunk_gather_on = sgather.median();
  r.shrunk_grid_levels = grid.level_count();
  return r;
}

}  // namespace bench
