// photonbound-bench: the measurements of issue 5 (bench/README.md), each a plain function over
// the renderer's own stages (World, PhotonTracer, HashGrid, gather_photons, direct_light,
// accumulate_pass, run_camera_pass), so every figure times exactly the code a render runs.
#pragma once

#include "estimator/estimator.h"
#include "render/camera_pass.h"
#include "render/hash_grid.h"
#include "render/photon_pass.h"
#include "world/world.h"

#include <cstdint>
#include <vector>

namespace bench {

// Seconds on the steady clock, or, once use_cpu_time() was called (--profile, one thread), on
// the process CPU-time clock, which other processes on a busy machine do not inflate.
double now();
void use_cpu_time();
inline double seconds_since(double t0) { return now() - t0; }

double median(std::vector<double> v);

// Peak resident set size: reset_peak() restarts the high-water mark (Linux /proc/self/clear_refs),
// peak_bytes() reads it through getrusage(RUSAGE_SELF).ru_maxrss.
void reset_peak_rss();
double peak_rss_bytes();

inline constexpr uint64_t kSeed = 1;

// Raw Embree rate: closest-hit rays with origins uniform in the scene bounds and directions
// uniform on the sphere, pre-generated, traced through pb::Accel::intersect (a thin wrapper
// over rtcIntersect1). Median of `reps` runs.
struct RayRate {
  double rays_per_s = 0.0;
  double hit_fraction = 0.0;
};
RayRate raw_ray_rate(const pb::World& world, int threads, size_t rays, int reps);

// PhotonTracer::run at `photons` per pass, median over `passes` passes (pass numbers 1..).
struct PhotonRate {
  double seconds = 0.0;        // per pass
  double order_seconds = 0.0;  // of which ordering the hits spatially
  double rays_per_s = 0.0;
  double paths_per_s = 0.0;
  double rays_per_path = 0.0;
  double hits_per_path = 0.0;
};
PhotonRate photon_pass_rate(const pb::World& world, int threads, uint64_t photons, int passes);

// Visible points and the renderer's default initial radius (4 pixel footprints, median).
struct EyeSetup {
  pb::CameraPassResult eye;
  double seconds = 0.0;
  double r0 = 0.0;
  double min_r2 = 0.0;
};
EyeSetup eye_setup(const pb::World& world, int width, int height);

// The pass loop of Renderer::step, phase by phase, with the gather run twice per pass: with error
// estimation (gather_photons + accumulate_pass, the renderer's code) and without (the same
// kernel-weighted PPM estimate, no Laplacian sum and no streaming moments; see plain.h).
struct PassLoop {
  int passes = 0;
  size_t points = 0;
  double hits_per_pass = 0.0;
  double trace = 0.0;       // per pass, median
  double grid_build = 0.0;  // pb::build_photon_grid (hit positions and HashGrid::build)
  double gather_on = 0.0;   // gather + next-event sample + accumulate_pass
  double gather_off = 0.0;  // the same without error estimation
  double nee = 0.0;         // next-event samples alone (part of both)
  double gathered = 0.0;    // photons gathered per point per pass (mean over points and passes)
  int grid_levels = 0;
  size_t grid_bytes = 0;
  size_t tau_mismatches = 0;  // points whose bounds-off tau differs from the full estimator's
  // After the radii have shrunk 100x (every R / 100, as after ~10^5 passes at alpha 0.7).
  double shrunk_grid_build = 0.0;
  double shrunk_gather_on = 0.0;
  int shrunk_grid_levels = 0;
  double on_pass() const { return trace + grid_build + gather_on; }
  double off_pass() const { return trace + grid_build + gather_off; }
};
// The grid build alone is short and the machine noisy: it is timed again `build_reps` times
// after the passes, at the last pass's radii and at radii 100x smaller.
PassLoop pass_loop(const pb::World& world, const EyeSetup& setup, uint64_t photons, int passes,
                   int build_reps = 7);

}  // namespace bench
