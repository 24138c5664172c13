#include "render/next_event.h"

#include "render/lobe_split.h"

namespace pb {

// Multiple importance sampling of the environment (Veach thesis 9.2, the balance heuristic):
// an environment light sample keeps p_l / (p_l + p_b) of the part of f whose draws are the
// other strategy, and a draw of that part that leaves the scene adds f L cos / p_b times
// p_b / (p_l + p_b). Light samples alone give single values of f_peak pi L wherever a glossy
// lobe is narrower than the cosine the sky is drawn by, rare and large: on Blender's textured
// sphere (roughness 0.4) under the default sky the per-pass variance a 94-pass stop measured was
// a sixth of what 400 passes showed in 10% of its pixels, and its 90% bounds held for 76-79% of
// them (issue 37's fireflies around metal).
// Only for a lobe narrower than kMisRoughness: on a white metal under a uniform sky at normal
// view (EnvironmentMis.AGlossyPlaneUnderTheSkyShowsItsAlbedoWithLessNoise) the per-pass
// variance of light samples alone is 74, 21, 8.6 and 3.2 times the balance heuristic's at
// roughness 0.3, 0.4, 0.5 and 0.6, and 0.024 times it at 0.8, where pi f hardly varies and
// splitting the integral between two samples adds the variance of the split.
bool environment_mis_applies(const World& world, const Bsdf& draws, const Bsdf& whole) {
  return world.lights().environment() && !draws.has_delta() && !draws.transmits() &&
         has_lobe_below(whole, kMisRoughness);
}

int direct_light_tests(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                       Rng& rng, const EnvironmentMis* mis, ShadowTest* tests) {
  int n = 0;
  DirectSample s;
  if (world.lights().sample_direct(point.position, point.shading, rng, s)) {
    const float cos_s = glm::dot(s.wi, point.shading);
    if (cos_s > 0.0f && glm::dot(s.wi, point.normal) > 0.0f) {
      vec3 f = glossy ? point.f * glossy->bsdf.eval(glossy->wo, s.wi) : point.f;
      if (mis && s.environment_pdf > 0.0f) {
        const float p_b = mis->density(s.wi);
        if (p_b > 0.0f) {
          const vec3 part = point.f * mis->bsdf->eval(mis->wo, s.wi);
          f -= part * (p_b / (s.environment_pdf + p_b));
        }
      }
      // No shadow ray for nothing.
      if (!glossy || max_component(f) > 0.0f) {
        ShadowTest& t = tests[n++];
        t.traced = World::shadow_ray(point.position, s.wi, s.distance, s.margin, world.ray_key(rng),
                                     t.ray);
        t.value = dvec3(f * s.li * cos_s);
      }
    }
  }
  if (!mis || !mis->draw) return n;
  BsdfSample b;
  if (!mis->bsdf->sample_non_delta_part(mis->wo, rng, b) || !(b.pdf > 0.0f)) return n;
  if (!(glm::dot(b.wi, point.shading) > 0.0f) || !(glm::dot(b.wi, point.normal) > 0.0f)) return n;
  const float p_l = world.lights().environment_pdf(point.position, point.shading, b.wi);
  if (!(p_l > 0.0f)) return n;  // the light sample covers what its density reaches
  const vec3 value = point.f * b.weight * world.lights().environment_radiance(b.wi);
  if (!(max_component(value) > 0.0f)) return n;
  ShadowTest& t = tests[n++];
  t.traced = World::shadow_ray(point.position, b.wi, INFINITY, 0.0f, world.ray_key(rng), t.ray);
  const float p_b = mis->share * b.pdf;
  t.value = dvec3(value * (p_b / (p_b + p_l)));
  return n;
}

dvec3 shadow_sum(const World& world, const ShadowTest* tests, int n, const bool* blocked) {
  dvec3 total(0.0);
  for (int i = 0; i < n; ++i) {
    const ShadowTest& t = tests[i];
    const bool b = blocked ? blocked[i]
                           : t.traced && world.accel().occluded(t.ray.origin, t.ray.dir,
                                                                t.ray.tnear, t.ray.tfar, t.ray.key);
    if (!b) total += t.value;
  }
  return total;
}

dvec3 direct_light(const World& world, const VisiblePoint& point, const PointBsdf* glossy, Rng& rng,
                   const EnvironmentMis* mis) {
  ShadowTest tests[kMaxShadowTests];
  const int n = direct_light_tests(world, point, glossy, rng, mis, tests);
  return shadow_sum(world, tests, n);
}

dvec3 direct_light_through(const World& world, const Surface& s, const vec3& wo, const vec3& weight,
                           bool glass, Rng& rng) {
  const float side = glm::dot(wo, s.ng) > 0.0f ? -1.0f : 1.0f;  // the other side's sign
  const vec3 n = side * s.ng, ns = side * s.ns;
  const vec3 origin = World::spawn(s, n);
  DirectSample d;
  if (!world.lights().sample_direct(origin, ns, rng, d)) return dvec3(0.0);
  const float cos_s = glm::dot(d.wi, ns);
  if (cos_s <= 0.0f || glm::dot(d.wi, n) <= 0.0f) return dvec3(0.0);
  const vec3 f = weight * s.bsdf.eval_transmission(wo, d.wi, glass);
  if (!(max_component(f) > 0.0f)) return dvec3(0.0);  // no shadow ray for nothing
  if (world.occluded(origin, d.wi, d.distance, d.margin, world.ray_key(rng))) return dvec3(0.0);
  return dvec3(f * d.li * cos_s);
}

}  // namespace pb
