#include "photonbound/camera_paths.h"

#include "photonbound/bsdf.h"
#include "photonbound/rng.h"

namespace pb {

size_t trace_visible_points(const CameraPathInputs& in, size_t first,
                            std::span<MeasurementPoint> points, std::span<GlossyPoint> glossy,
                            std::span<PassGather> out) {
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
    for (int depth = 0;; ++depth) {
      Hit hit;
      const bool found = depth == 0 ? in.world.accel().intersect(origin, dir, 0.0f, INFINITY, hit)
                                    : in.world.trace(origin, origin_normal, origin_error, dir, hit);
      if (!found) {  // the environment (black without one), seen along the path
        emission += dvec3(weight * in.world.lights().environment_radiance(dir));
        break;
      }
      const Surface s = in.world.surface(hit);
      const vec3 wo = -dir;
      const bool front = glm::dot(wo, s.ng) > 0.0f;
      weight *= in.world.transmittance(s, wo, origin);  // inside an absorbing volume
      if (s.material->emits()) emission += dvec3(weight * in.world.emitted(s, wo));
      // Stop here (the non-delta part) or follow a delta branch: 1 - p_delta and p_delta.
      const float p_delta = s.bsdf.delta_probability(wo);
      bool stop = p_delta < 1.0f;
      if (stop && p_delta > 0.0f) {
        const float u = rng.next_float();
        stop = u >= p_delta;
      }
      if (stop) {
        const vec3 w = p_delta > 0.0f ? weight / (1.0f - p_delta) : weight;
        point.position = in.world.spawn(s, wo);  // lifted off the surface: shadow rays start here
        point.normal = front ? s.ng : -s.ng;
        point.shading = front ? s.ns : -s.ns;
        const bool lambertian = s.bsdf.is_lambertian();
        point.f = lambertian ? w * s.bsdf.diffuse_f() : w;
        point.triangle = in.world.triangle_index(hit);
        if (!(max_component(point.f) > 0.0f)) {
          point.f = vec3(0.0f);
        } else if (!lambertian) {
          glossy[glossy_count++] = {uint32_t(k), wo, s.bsdf};
        }
        break;
      }
      if (depth >= in.max_depth) break;  // the chain is cut
      BsdfSample b;
      if (!s.bsdf.sample_delta(wo, rng, Transport::Radiance, b)) break;
      weight *= p_delta < 1.0f ? b.weight / p_delta : b.weight;
      if (!(max_component(weight) > 0.0f)) break;
      origin = s.position;
      origin_normal = s.ng;
      origin_error = s.error;
      dir = b.wi;
    }
    points[k] = point;
    out[k] = PassGather{};
    out[k].direct = emission;
  }
  return glossy_count;
}

}  // namespace pb
