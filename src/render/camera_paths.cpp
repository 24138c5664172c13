#include "render/camera_paths.h"

#include "bsdf/bsdf.h"
#include "render/next_event.h"
#include "util/rng.h"

#include <algorithm>

namespace pb {

// Passes over (ESTIMATOR.md section 10) a path may take beyond --max-depth, by roulette.
constexpr int kPassOverDepth = 16;

// Russian roulette past --max-depth: the path survives with q = min(1, its largest channel) and
// its weight is divided by q, so it keeps its mean and, below 1, a weight of 1 at most (a fixed
// 1/2 doubled the weight at every step: a path that bounced inside rough glass came out with
// 2^k, one pixel's firefly).
namespace {

bool survives(vec3& weight, Rng& rng) {
  const float q = std::min(1.0f, max_component(weight));
  if (!(q > 0.0f) || (q < 1.0f && rng.next_float() >= q)) return false;
  weight /= q;
  return true;
}

}  // namespace

size_t trace_visible_points(const CameraPathInputs& in, size_t first, std::span<const float> radii,
                            std::span<MeasurementPoint> points, std::span<GlossyPoint> glossy,
                            std::span<OwnerValues> out) {
  const int width = in.camera.width();
  size_t glossy_count = 0;
  for (size_t k = 0; k < points.size(); ++k) {
    const size_t pixel = first + k;
    Rng rng(in.seed, in.pass, pixel, Stream::Camera);
    const float jx = rng.next_float(), jy = rng.next_float();
    const int x = int(pixel % size_t(width)), y = int(pixel / size_t(width));
    vec3 origin = in.camera.origin(), origin_normal(0.0f);
    float origin_error = 0.0f;
    vec3 dir = in.camera.direction(float(x) + jx, float(y) + jy);
    vec3 weight(1.0f);
    dvec3 emission(0.0);
    MeasurementPoint point;  // f = 0: none
    DiscMoments disc;
    // The ray leaves a followed GGX lobe: the light it finds directly (an emitter, the
    // environment) is that vertex's direct light, which its next-event sample has counted.
    bool after_lobe = false;
    // The path went past --max-depth by roulette (a pass-over or a followed lobe): it goes on by
    // roulette through delta branches too, up to kPassOverDepth beyond, instead of being cut
    // where the limit would cut a path that reached it.
    bool past_limit = false;
    for (int depth = 0;; ++depth) {
      Hit hit;
      const bool found = depth == 0 ? in.world.camera_hit(origin, dir, hit)
                                    : in.world.trace(origin, origin_normal, origin_error, dir, hit);
      if (!found) {  // the environment (black without one), seen along the path
        if (!after_lobe) emission += dvec3(weight * in.world.lights().environment_radiance(dir));
        break;
      }
      const Surface s = in.world.surface(hit);
      const vec3 wo = -dir;
      const bool front = glm::dot(wo, s.ng) > 0.0f;
      weight *= in.world.transmittance(s, wo, origin);  // inside an absorbing volume
      if (s.material->emits() && !after_lobe) emission += dvec3(weight * in.world.emitted(s, wo));
      after_lobe = false;
      // Stop here (the non-delta part) or follow a delta branch: 1 - p_delta and p_delta.
      const float p_delta = s.bsdf.delta_probability(wo);
      bool stop = p_delta < 1.0f;
      if (stop && p_delta > 0.0f) {
        const float u = rng.next_float();
        stop = u >= p_delta;
      }
      if (stop) {
        vec3 w = p_delta > 0.0f ? weight / (1.0f - p_delta) : weight;
        point.position = in.world.spawn(s, wo);  // lifted off the surface: shadow rays start here
        point.normal = front ? s.ng : -s.ng;
        point.shading = front ? s.ns : -s.ns;
        Bsdf bsdf = s.bsdf;
        bool direct_counted = false;  // this vertex's next-event sample is taken
        // A sharp lobe is followed at --max-depth too (by roulette beyond it, below): gathered
        // with it, a rare deep path would give its pixel the lobe's peak f in the sparse-photon
        // bound (ESTIMATOR.md section 12) for good.
        if (depth < in.max_depth + kPassOverDepth && s.bsdf.has_lobe_below(in.follow_roughness)) {
          // This vertex's direct light with its whole Bsdf (so the choice below adds no noise
          // to it), then follow the GGX lobe with p_lobe or gather photons at the diffuse base
          // with 1 - p_lobe, each divided by its probability (ESTIMATOR.md section 10). Rough
          // glass is followed with all light from photons too (its photons are never gathered);
          // its direct light from the other side is one more sample, through the surface.
          // Sharp rough glass is left out: its light comes from what its paths hit.
          const bool glass_direct = s.bsdf.glass_lit_directly();
          const bool sharp_glass = s.bsdf.has_rough_glass() && !glass_direct;
          const GlossyPoint whole{0, wo, sharp_glass ? s.bsdf.without_glass() : s.bsdf};
          point.f = w;
          if (in.next_event) {
            emission += direct_light(in.world, point, &whole, rng);
            // Through the surface: diffuse transmission, and rough glass when broad.
            if (glass_direct || s.bsdf.transmits_diffusely())
              emission += direct_light_through(in.world, s, wo, w, glass_direct, rng);
          }
          const float p_lobe = s.bsdf.lobe_probability(wo, in.follow_roughness);
          if (p_lobe >= 1.0f || (p_lobe > 0.0f && rng.next_float() < p_lobe)) {
            const GlossyPoint lobe{0, wo, s.bsdf.lobe_part(in.follow_roughness)};
            weight = w / p_lobe;
            point = MeasurementPoint{};  // no visible point here
            // At or beyond --max-depth the followed path goes on by Russian roulette, as a
            // pass-over does: the lobe's indirect light keeps its mean.
            if (depth >= in.max_depth) {
              if (!survives(weight, rng)) break;
              past_limit = true;
            }
            BsdfSample b;
            if (!lobe.bsdf.sample(wo, rng, Transport::Radiance, b)) break;
            weight *= b.weight;
            if (!(max_component(weight) > 0.0f)) break;
            origin = s.position;
            origin_normal = s.ng;
            origin_error = s.error;
            dir = b.wi;
            // The light this path finds directly was counted by the next-event sample, unless
            // it left through sharp rough glass, which that sample left out.
            after_lobe = in.next_event && !(sharp_glass && b.glass);
            continue;
          }
          w /= 1.0f - p_lobe;
          bsdf = s.bsdf.base_part(
              in.follow_roughness);  // its direct light is counted: next_event_pass skips it
          direct_counted = true;
        }
        const bool lambertian = bsdf.is_lambertian();
        point.f = lambertian ? w * bsdf.diffuse_f() : w;
        point.triangle = in.world.triangle_index(hit);
        if (!(max_component(point.f) > 0.0f)) {
          point.f = vec3(0.0f);  // a black surface (or a path weight of 0): no visible point
          break;
        }
        if (in.boundary) {
          disc = in.boundary->moments(point.triangle, point.position, point.normal, radii[k]);
          if (disc.mass < kValidKernelMass) {
            // Almost all of the disc is off reachable surface: photons cannot estimate the
            // radiance here (ESTIMATOR.md section 10, "Passing over"), but a path can:
            // L = L_direct + integral of f L cos over the non-delta part, by one next-event
            // sample and one direction from that part, and the photons gathered where it lands.
            if (in.next_event && !direct_counted) {
              const GlossyPoint here{0, wo, bsdf};
              point.f = w;
              emission += direct_light(in.world, point, &here, rng);
            }
            point = MeasurementPoint{};
            disc = DiscMoments{};
            // At --max-depth the path does not keep the point (its pixel would be unknown for
            // good: validity is the least mass over the passes, and over thousands of passes a
            // rare deep path comes): it goes on by Russian roulette (survives), so the indirect
            // part keeps its mean; kPassOverDepth more vertices cut it (no point, the truncation
            // every depth limit makes).
            if (depth >= in.max_depth) {
              if (depth >= in.max_depth + kPassOverDepth || !survives(w, rng)) break;
              past_limit = true;
            }
            BsdfSample b;
            if (!bsdf.sample_non_delta_part(wo, rng, b)) break;
            weight = w * b.weight;
            if (!(max_component(weight) > 0.0f)) break;
            origin = s.position;
            origin_normal = s.ng;
            origin_error = s.error;
            dir = b.wi;
            after_lobe = in.next_event;  // the next-event sample counted what it finds directly
            continue;
          }
        }
        if (!lambertian) glossy[glossy_count++] = {uint32_t(k), wo, bsdf};
        break;
      }
      if (depth >= in.max_depth) {  // the chain is cut, unless it is past the limit already
        if (!past_limit || depth >= in.max_depth + kPassOverDepth || !survives(weight, rng)) break;
      }
      BsdfSample b;
      if (!s.bsdf.sample_delta(wo, rng, Transport::Radiance, b, weight)) break;
      weight *= p_delta < 1.0f ? b.weight / p_delta : b.weight;
      if (!(max_component(weight) > 0.0f)) break;
      origin = s.position;
      origin_normal = s.ng;
      origin_error = s.error;
      dir = b.wi;
    }
    points[k] = point;
    out[k] = OwnerValues{emission, disc};
  }
  return glossy_count;
}

double culled_view_share(const World& world, const PinholeCamera& camera) {
  const int nx = std::min(camera.width(), 128), ny = std::min(camera.height(), 128);
  size_t culled = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const float px = (float(i) + 0.5f) * float(camera.width()) / float(nx);
      const float py = (float(j) + 0.5f) * float(camera.height()) / float(ny);
      Hit hit;
      int passed = 0;
      world.camera_hit(camera.origin(), camera.direction(px, py), hit, &passed);
      culled += passed > 0;
    }
  return double(culled) / double(nx * ny);
}

}  // namespace pb
