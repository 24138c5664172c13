// Raw Embree ray rate, photon-pass rate, and the small helpers (median, peak RSS).
#include "bench.h"

#include "bsdf/bsdf.h"
#include "util/parallel.h"
#include "util/rng.h"

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <fstream>

namespace bench {

namespace {
bool cpu_time = false;
}  // namespace

void use_cpu_time() { cpu_time = true; }

double now() {
  timespec ts{};
  clock_gettime(cpu_time ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

void reset_peak_rss() {
  // "5" resets the peak RSS (VmHWM) to the current RSS (Linux >= 4.0); ignored elsewhere.
  std::ofstream("/proc/self/clear_refs") << "5";
}

double peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) * 1024.0;  // ru_maxrss is in KiB on Linux
}

RayRate raw_ray_rate(const pb::World& world, int threads, size_t n, int reps) {
  // Rays are generated before timing so only the traversal is measured.
  const pb::Bounds& b = world.scene().bounds;
  std::vector<pb::vec3> origin(n), dir(n);
  for (size_t i = 0; i < n; ++i) {
    pb::Rng rng(kSeed, 0, i, pb::Stream::Test);
    const pb::vec3 u(rng.next_float(), rng.next_float(), rng.next_float());
    origin[i] = b.lo + u * (b.hi - b.lo);
    dir[i] = pb::sample_uniform_sphere(rng.next_float(), rng.next_float());
  }
  pb::ThreadLimit limit(threads);
  const pb::Accel& accel = world.accel();
  std::vector<double> times;
  std::atomic<size_t> hits{0};
  for (int r = 0; r < reps; ++r) {
    hits = 0;
    const double t0 = now();
    pb::parallel_for(n, 4096, [&](size_t begin, size_t end) {
      size_t local = 0;
      pb::Hit hit;
      for (size_t i = begin; i < end; ++i)
        local += accel.intersect(origin[i], dir[i], 0.0f, INFINITY, hit) ? 1 : 0;
      hits += local;
    });
    times.push_back(seconds_since(t0));
  }
  RayRate rate;
  rate.rays_per_s = double(n) / median(times);
  rate.hit_fraction = double(hits.load()) / double(n);
  return rate;
}

PhotonRate photon_pass_rate(const pb::World& world, int threads, uint64_t photons, int passes) {
  pb::ThreadLimit limit(threads);
  pb::PhotonTracer tracer(world, false);  // --direct nee, the default
  std::vector<pb::PhotonHit> hits;
  tracer.run(kSeed, 1000, 0, photons / 8, hits);  // warm-up: buffers, TBB workers, page faults
  std::vector<double> times, ray_rates, rays, stored, order;
  for (int p = 1; p <= passes; ++p) {
    const double t0 = now();
    const pb::PhotonPassStats s = tracer.run(kSeed, uint64_t(p), 0, photons, hits);
    times.push_back(seconds_since(t0));
    ray_rates.push_back(double(s.rays) / times.back());
    rays.push_back(double(s.rays));
    stored.push_back(double(hits.size()));
    order.push_back(s.order_seconds);
  }
  PhotonRate rate;
  rate.seconds = median(times);
  rate.order_seconds = median(order);
  rate.rays_per_s = median(ray_rates);
  rate.paths_per_s = double(photons) / rate.seconds;
  rate.rays_per_path = median(rays) / double(photons);
  rate.hits_per_path = median(stored) / double(photons);
  return rate;
}

}  // namespace bench
