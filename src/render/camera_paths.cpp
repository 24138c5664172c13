#include "render/camera_paths.h"

#include "bsdf/bsdf.h"
#include "render/lobe_split.h"
#include "render/next_event.h"
#include "util/rng.h"

#include <algorithm>
#include <optional>

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

// One camera path's state between its vertices (ESTIMATOR.md section 10).
struct CameraPath {
  Rng rng;
  vec3 origin{0.0f}, origin_normal{0.0f};  // the vertex the ray leaves (the camera at first)
  float origin_error = 0.0f;
  vec3 dir{0.0f};
  vec3 weight{1.0f};
  dvec3 emission{0.0};  // light the path saw (and its vertices' next-event samples)
  VisiblePoint point;   // the visible point; f = 0: none
  DiscMoments disc;
  // Where the region of the point's disc goes when the disc is not whole (disc.full false),
  // for the gather: the caller's.
  DiscRegion* region = nullptr;
  // The ray leaves a followed GGX lobe: the light it finds directly (an emitter, the
  // environment) is that vertex's direct light, which its next-event sample has counted.
  bool after_lobe = false;
  // When the followed lobe's draws are the environment's other strategy (next_event.h): their
  // density (the lobe's choice times its pdf) and the vertex they left, whose environment light
  // sample kept the rest; 0 otherwise.
  float lobe_density = 0.0f;
  vec3 lobe_origin{0.0f}, lobe_normal{0.0f};
  // The path went past --max-depth by roulette (a pass-over or a followed lobe): it goes on by
  // roulette through delta branches too, up to kPassOverDepth beyond, instead of being cut
  // where the limit would cut a path that reached it.
  bool past_limit = false;
  // The path left the camera's chain of delta branches (a followed lobe or a pass-over): it
  // estimates a surface's reflected light now, to which unlit surfaces give nothing.
  bool left_chain = false;
  int depth = 0;

  CameraPath(const CameraPathInputs& in, size_t pixel, uint32_t path)
      : rng(in.seed, in.pass, path_item(pixel, path), Stream::Camera) {
    const int width = in.camera.width();
    const float jx = rng.next_float(), jy = rng.next_float();
    const int x = int(pixel % size_t(width)), y = int(pixel / size_t(width));
    origin = in.camera.origin();
    dir = in.camera.direction(float(x) + jx, float(y) + jy);
  }

  // The next ray leaves surface s in direction wi.
  void leave(const Surface& s, const vec3& wi) {
    origin = s.position;
    origin_normal = s.ng;
    origin_error = s.error;
    dir = wi;
  }
};

// What a vertex tells the path: go on from it, or the path is over (with or without a point).
enum class Step { Continue, End };

// At or beyond --max-depth a path goes on only by Russian roulette, and kPassOverDepth vertices
// beyond it at most (a pass-over or a followed lobe; ESTIMATOR.md section 10).
bool beyond_limit_survives(CameraPath& path, const CameraPathInputs& in, vec3& weight) {
  if (path.depth < in.max_depth) return true;
  if (path.depth >= in.max_depth + kPassOverDepth || !survives(weight, path.rng)) return false;
  path.past_limit = true;
  return true;
}

// A followed GGX lobe below --follow-roughness (section 10; the split: lobe_split.h): this vertex's
// direct light with its whole Bsdf (so the choice adds no noise to it), then follow the lobe with
// p_lobe or gather photons at the diffuse base with 1 - p_lobe, each divided by its probability.
// Rough glass is followed with all light from photons too (its photons are never gathered); its
// direct light from the other side is one more sample, through the surface. Sharp rough glass is
// left out: its light comes from what its paths hit. With the base chosen, w and bsdf become the
// diffuse base's, whose direct light is counted.
enum class LobeChoice { Followed, PathEnded, Base };
LobeChoice follow_lobe(CameraPath& path, const CameraPathInputs& in, const Surface& s,
                       const vec3& wo, vec3& w, Bsdf& bsdf) {
  const bool glass_direct = s.bsdf.glass_lit_directly();
  const bool sharp_glass = s.bsdf.has_rough_glass() && !glass_direct;
  const PointBsdf whole{0, wo, sharp_glass ? s.bsdf.without_glass() : s.bsdf};
  path.point.f = w;
  const float p_lobe = lobe_probability(s.bsdf, wo, in.follow_roughness);
  const Bsdf lobe_bsdf = p_lobe > 0.0f ? lobe_part(s.bsdf, in.follow_roughness) : Bsdf();
  // The lobe's draws are the other strategy for the environment's light (next_event.h), with
  // density min(p_lobe, 1) x its pdf: the light sample keeps the balance heuristic's share of
  // the lobe's part, and a followed path that leaves the scene adds the rest.
  const bool mis = in.next_event && p_lobe > 0.0f && !sharp_glass &&
                   environment_mis_applies(in.world, lobe_bsdf, s.bsdf);
  const EnvironmentMis lobe_mis{&lobe_bsdf, wo, std::min(p_lobe, 1.0f), false};
  if (in.next_event) {
    path.emission +=
        direct_light(in.world, path.point, &whole, path.rng, mis ? &lobe_mis : nullptr);
    // Through the surface: diffuse transmission, and rough glass when broad.
    if (glass_direct || s.bsdf.transmits_diffusely())
      path.emission += direct_light_through(in.world, s, wo, w, glass_direct, path.rng);
  }
  if (p_lobe >= 1.0f || (p_lobe > 0.0f && path.rng.next_float() < p_lobe)) {
    const PointBsdf lobe{0, wo, lobe_bsdf};
    const vec3 vertex = path.point.position, vertex_normal = path.point.shading;
    path.weight = w / p_lobe;
    path.point = VisiblePoint{};  // no visible point here
    // At or beyond --max-depth the followed path goes on by Russian roulette, as a pass-over
    // does: the lobe's indirect light keeps its mean.
    if (!beyond_limit_survives(path, in, path.weight)) return LobeChoice::PathEnded;
    BsdfSample b;
    if (!lobe.bsdf.sample(wo, path.rng, Transport::Radiance, b)) return LobeChoice::PathEnded;
    path.weight *= b.weight;
    if (!(max_component(path.weight) > 0.0f)) return LobeChoice::PathEnded;
    path.leave(s, b.wi);
    // The light this path finds directly was counted by the next-event sample, unless it left
    // through sharp rough glass, which that sample left out.
    path.after_lobe = in.next_event && !(sharp_glass && b.glass);
    path.lobe_density = mis && !b.delta ? lobe_mis.share * b.pdf : 0.0f;
    path.lobe_origin = vertex;
    path.lobe_normal = vertex_normal;
    path.left_chain = true;
    return LobeChoice::Followed;
  }
  w /= 1.0f - p_lobe;
  bsdf = base_part(s.bsdf, in.follow_roughness);  // its direct light: next_event_pass skips it
  return LobeChoice::Base;
}

// Passing over (section 10, "Passing over"): almost all of the disc is off reachable surface,
// so photons cannot estimate the radiance here, but a path can: L = L_direct + integral of
// f L cos over the non-delta part, by one next-event sample and one direction from that part,
// and the photons gathered where it lands. At --max-depth the path does not keep the point (its
// pixel would be unknown for good: validity is the least mass over the passes, and over
// thousands of passes a rare deep path comes): it goes on by Russian roulette, so the indirect
// part keeps its mean; kPassOverDepth more vertices cut it (no point, the truncation every depth
// limit makes).
Step pass_over(CameraPath& path, const CameraPathInputs& in, const Surface& s, const vec3& wo,
               vec3 w, const Bsdf& bsdf, bool direct_counted) {
  if (in.next_event && !direct_counted) {
    const PointBsdf here{0, wo, bsdf};
    path.point.f = w;
    path.emission += direct_light(in.world, path.point, &here, path.rng);
  }
  path.point = VisiblePoint{};
  path.disc = DiscMoments{};
  if (!beyond_limit_survives(path, in, w)) return Step::End;
  BsdfSample b;
  if (!bsdf.sample_non_delta_part(wo, path.rng, b)) return Step::End;
  path.weight = w * b.weight;
  if (!(max_component(path.weight) > 0.0f)) return Step::End;
  path.leave(s, b.wi);
  path.after_lobe = in.next_event;  // the next-event sample counted what it finds directly
  path.left_chain = true;
  return Step::Continue;
}

// The path stops at the non-delta part of surface s (chosen with 1 - p_delta): a followed lobe,
// a pass-over, or the visible point, whose Bsdf goes to `glossy` when it is not Lambertian.
Step stop_at(CameraPath& path, const CameraPathInputs& in, const Hit& hit, const Surface& s,
             const vec3& wo, float p_delta, float radius, std::optional<PointBsdf>& glossy) {
  const bool front = glm::dot(wo, s.ng) > 0.0f;
  vec3 w = p_delta > 0.0f ? path.weight / (1.0f - p_delta) : path.weight;
  VisiblePoint& point = path.point;
  point.position = in.world.spawn(s, wo);  // lifted off the surface: shadow rays start here
  point.normal = front ? s.ng : -s.ng;
  point.shading = front ? s.ns : -s.ns;
  Bsdf bsdf = s.bsdf;
  bool direct_counted = false;  // this vertex's next-event sample is taken
  // A sharp lobe is followed at --max-depth too (by roulette beyond it): gathered with it, a
  // rare deep path would give its pixel the lobe's peak f in the sparse-photon bound
  // (ESTIMATOR.md section 12) for good.
  if (path.depth < in.max_depth + kPassOverDepth && has_lobe_below(s.bsdf, in.follow_roughness)) {
    switch (follow_lobe(path, in, s, wo, w, bsdf)) {
      case LobeChoice::Followed:
        return Step::Continue;
      case LobeChoice::PathEnded:
        return Step::End;
      case LobeChoice::Base:
        direct_counted = true;
    }
  }
  const bool lambertian = bsdf.is_lambertian();
  point.f = lambertian ? w * bsdf.diffuse_f() : w;
  point.triangle = in.world.triangle_index(hit);
  if (!(max_component(point.f) > 0.0f)) {
    point.f = vec3(0.0f);  // a black surface (or a path weight of 0): no visible point
    return Step::End;
  }
  if (in.boundary) {
    path.disc =
        in.boundary->region(point.triangle, point.position, point.normal, radius, *path.region)
            ? BoundaryIndex::moments_of(*path.region, radius)
            : DiscMoments{};
    if (path.disc.mass < kValidKernelMass)
      return pass_over(path, in, s, wo, w, bsdf, direct_counted);
  }
  if (!lambertian) glossy = PointBsdf{0, wo, bsdf};
  return Step::End;
}

// A vertex on surface `hit`: its emission, then stop there (the non-delta part) or follow a
// delta branch, with 1 - p_delta and p_delta.
Step at_vertex(CameraPath& path, const CameraPathInputs& in, const Hit& hit, float radius,
               std::optional<PointBsdf>& glossy) {
  const Surface s = in.world.surface(hit);
  const vec3 wo = -path.dir;
  path.weight *= in.world.transmittance(s, wo, path.origin);  // inside an absorbing volume
  if (s.material->emits() && !path.after_lobe)
    path.emission += dvec3(path.weight * in.world.emitted(s, wo));
  // An unlit surface's painted colour, seen along the camera's delta chain (docs/materials.md
  // "Unlit"); its Bsdf is black, so the path ends there without a visible point.
  if (s.material->unlit && !path.left_chain) path.emission += dvec3(path.weight * s.painted);
  path.after_lobe = false;
  path.lobe_density = 0.0f;
  const float p_delta = s.bsdf.delta_probability(wo);
  bool stop = p_delta < 1.0f;
  if (stop && p_delta > 0.0f) {
    const float u = path.rng.next_float();
    stop = u >= p_delta;
  }
  if (stop) return stop_at(path, in, hit, s, wo, p_delta, radius, glossy);
  // A delta branch: the chain is cut at --max-depth, unless it is past the limit already.
  if (path.depth >= in.max_depth) {
    if (!path.past_limit || path.depth >= in.max_depth + kPassOverDepth ||
        !survives(path.weight, path.rng))
      return Step::End;
  }
  BsdfSample b;
  if (!s.bsdf.sample_delta(wo, path.rng, Transport::Radiance, b, path.weight)) return Step::End;
  path.weight *= p_delta < 1.0f ? b.weight / p_delta : b.weight;
  if (!(max_component(path.weight) > 0.0f)) return Step::End;
  path.leave(s, b.wi);
  return Step::Continue;
}

// The path on from its camera ray's first hit (found: the ray met a surface) to its visible
// point or its end.
std::optional<PointBsdf> follow_path(CameraPath& path, const CameraPathInputs& in, float radius,
                                     bool found, Hit hit) {
  std::optional<PointBsdf> g;
  for (;; ++path.depth) {
    if (path.depth > 0) {
      // BLEND surfaces are met by chance, by a key of the path's stream (World::ray_key).
      const uint64_t key = in.world.ray_key(path.rng);
      found =
          in.world.trace(path.origin, path.origin_normal, path.origin_error, path.dir, hit, key);
    }
    if (!found) {  // the environment (black without one), seen along the path
      if (!path.after_lobe) {
        path.emission += dvec3(path.weight * in.world.lights().environment_radiance(path.dir));
      } else if (path.lobe_density > 0.0f && glm::dot(path.dir, path.lobe_normal) > 0.0f) {
        // The lobe's share of its vertex's environment light (balance heuristic).
        const float p_l =
            in.world.lights().environment_pdf(path.lobe_origin, path.lobe_normal, path.dir);
        if (p_l > 0.0f)
          path.emission += dvec3(path.weight * in.world.lights().environment_radiance(path.dir) *
                                 (path.lobe_density / (path.lobe_density + p_l)));
      }
      break;
    }
    if (at_vertex(path, in, hit, radius, g) == Step::End) break;
  }
  return g;
}

}  // namespace

std::optional<PointBsdf> trace_visible_point(const CameraPathInputs& in, size_t pixel,
                                             uint32_t path_index, float radius, VisiblePoint& point,
                                             OwnerValues& out, DiscRegion& region) {
  CameraPath path(in, pixel, path_index);
  path.region = &region;
  Hit hit;
  const uint64_t key = in.world.ray_key(path.rng);
  const bool found = in.world.camera_hit(path.origin, path.dir, hit, nullptr, key);
  std::optional<PointBsdf> g = follow_path(path, in, radius, found, hit);
  point = path.point;
  out = OwnerValues{path.emission, path.disc};
  return g;
}

size_t trace_visible_points(const CameraPathInputs& in, size_t first, std::span<const float> radii,
                            std::span<VisiblePoint> points, std::span<PointBsdf> glossy,
                            std::span<OwnerValues> out, RegionTable& regions) {
  size_t glossy_count = 0;
  regions.clear();
  DiscRegion region;
  constexpr int kGroup = Accel::kPacket;
  for (size_t k0 = 0; k0 < points.size(); k0 += kGroup) {
    // The camera rays of kGroup neighbouring pixels first, traced as one packet (they leave one
    // eye through neighbouring image points: one walk of the BVH serves them all), then each
    // path on alone. Each path draws its jitter and its ray's key as trace_visible_point does
    // (from its own stream), so the paths are the same bit for bit.
    const int n = int(std::min(points.size() - k0, size_t(kGroup)));
    std::optional<CameraPath> paths[kGroup];
    vec3 dirs[kGroup];
    uint64_t keys[kGroup];
    Hit hits[kGroup];
    bool found[kGroup];
    for (int i = 0; i < n; ++i) {
      CameraPath& path = paths[i].emplace(in, first + k0 + size_t(i), 0);
      keys[i] = in.world.ray_key(path.rng);
      dirs[i] = path.dir;
    }
    in.world.camera_hits(in.camera.origin(), dirs, keys, n, hits, found);
    for (int i = 0; i < n; ++i) {
      const size_t k = k0 + size_t(i);
      CameraPath& path = *paths[i];
      path.region = &region;
      std::optional<PointBsdf> g = follow_path(path, in, radii[k], found[i], hits[i]);
      points[k] = path.point;
      out[k] = OwnerValues{path.emission, path.disc};
      if (!out[k].disc.full && max_component(points[k].f) > 0.0f) regions.add(uint32_t(k), region);
      if (g) {
        g->point = uint32_t(k);
        glossy[glossy_count++] = *g;
      }
    }
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
