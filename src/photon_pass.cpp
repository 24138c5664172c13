#include "photonbound/photon_pass.h"

#include "photonbound/bsdf.h"
#include "photonbound/parallel.h"
#include "photonbound/rng.h"

#include <atomic>

namespace pb {

namespace {
// Photons per work chunk: large enough to amortise scheduling, small enough to balance 2 cores.
constexpr size_t kChunk = 2048;
}  // namespace

PhotonTracer::PhotonTracer(const World& world, bool deposit_first_hit)
    : world_(world), deposit_first_hit_(deposit_first_hit) {}

void PhotonTracer::trace(uint64_t seed, uint64_t pass, uint64_t index, std::vector<PhotonHit>& out,
                         uint64_t& rays) const {
  Rng rng(seed, pass, index, Stream::Photon);
  const EmittedPhoton e = world_.lights().sample_photon(rng);
  vec3 origin = e.origin, dir = e.dir, flux = e.flux, origin_normal = e.normal;
  for (int bounce = 0; bounce < kMaxBounces; ++bounce) {
    Hit hit;
    ++rays;
    const bool found = glm::dot(origin_normal, origin_normal) > 0.0f
                           ? world_.trace(origin, origin_normal, dir, hit)
                           : world_.accel().intersect(origin, dir, 0.0f, INFINITY, hit);
    if (!found) return;
    const Surface s = world_.surface(hit);
    const Material& m = *s.material;
    const vec3 wo = -dir;
    const bool front = glm::dot(wo, s.ng) > 0.0f;
    const vec3 ng = front ? s.ng : -s.ng;
    const vec3 ns = front ? s.ns : -s.ns;

    vec3 next, factor;
    if (m.model == Reflection::Lambertian) {
      if (bounce >= 1 || deposit_first_hit_) out.push_back({s.position, wo, ng, flux});
      next = sample_cosine_hemisphere(ns, rng.next_float(), rng.next_float());
      if (glm::dot(next, ng) <= 0.0f) return;  // below the true surface: absorbed
      // Cosine sampling cancels f cos / pdf to rho; the shading-normal correction remains.
      factor = m.base_color * adjoint_shading_factor(wo, next, ng, ns);
    } else {
      SpecularBranch b[2];
      const int n = specular_branches(m, s, wo, Transport::Importance, b);
      int pick = 0;
      float p = 1.0f;
      if (n == 2) {
        // Choose reflection or refraction in proportion to their throughput.
        const float a0 = average(b[0].weight), a1 = average(b[1].weight);
        p = a0 / (a0 + a1);
        if (rng.next_float() >= p) {
          pick = 1;
          p = 1.0f - p;
        }
      }
      if (!(p > 0.0f)) return;
      next = b[pick].dir;
      factor = b[pick].weight / p * adjoint_shading_factor(wo, next, ng, ns);
    }
    // Russian roulette keeps the carried power roughly constant (survival = max throughput).
    const float q = std::min(1.0f, max_component(factor));
    if (!(q > 0.0f) || rng.next_float() >= q) return;
    flux *= factor / q;
    origin = s.position;
    origin_normal = s.ng;
    dir = next;
  }
}

PhotonPassStats PhotonTracer::run(uint64_t seed, uint64_t pass, uint64_t count,
                                  std::vector<PhotonHit>& hits) {
  const size_t chunks = size_t((count + kChunk - 1) / kChunk);
  if (chunk_hits_.size() < chunks) chunk_hits_.resize(chunks);
  std::atomic<uint64_t> rays{0};
  parallel_chunks(size_t(count), kChunk, [&](size_t k, size_t begin, size_t end) {
    std::vector<PhotonHit>& out = chunk_hits_[k];
    out.clear();
    uint64_t local_rays = 0;
    for (size_t i = begin; i < end; ++i) trace(seed, pass, i, out, local_rays);
    rays += local_rays;
  });
  hits.clear();
  for (size_t k = 0; k < chunks; ++k)
    hits.insert(hits.end(), chunk_hits_[k].begin(), chunk_hits_[k].end());
  PhotonPassStats stats;
  stats.rays = rays.load();
  stats.paths = count;
  return stats;
}

}  // namespace pb
