#include "render/next_event.h"

namespace pb {

dvec3 direct_light(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                   Rng& rng) {
  DirectSample s;
  if (!world.lights().sample_direct(point.position, point.shading, rng, s)) return dvec3(0.0);
  const float cos_s = glm::dot(s.wi, point.shading);
  if (cos_s <= 0.0f || glm::dot(s.wi, point.normal) <= 0.0f) return dvec3(0.0);
  const vec3 f = glossy ? point.f * glossy->bsdf.eval(glossy->wo, s.wi) : point.f;
  if (glossy && !(max_component(f) > 0.0f)) return dvec3(0.0);  // no shadow ray for nothing
  if (world.occluded(point.position, s.wi, s.distance, s.margin, world.ray_key(rng)))
    return dvec3(0.0);
  return dvec3(f * s.li * cos_s);
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
