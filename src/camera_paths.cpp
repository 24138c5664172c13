#include "photonbound/camera_paths.h"

#include "photonbound/bsdf.h"
#include "photonbound/rng.h"

namespace pb {

void trace_visible_points(const CameraPathInputs& in, size_t first,
                          std::span<MeasurementPoint> points, std::span<PassGather> out) {
  const int width = in.camera.width();
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
      if (s.material->emits() && front) emission += dvec3(weight * s.material->emission);
      if (!s.bsdf.is_delta()) {
        point.position = in.world.spawn(s, wo);  // lifted off the surface: shadow rays start here
        point.normal = front ? s.ng : -s.ng;
        point.shading = front ? s.ns : -s.ns;
        point.f = weight * s.bsdf.diffuse_f();
        point.triangle = in.world.triangle_index(hit);
        if (!(max_component(point.f) > 0.0f)) point.f = vec3(0.0f);
        break;
      }
      if (depth >= in.max_depth) break;  // the chain is cut
      BsdfSample b;
      if (!s.bsdf.sample(wo, rng, Transport::Radiance, b)) break;
      weight *= b.weight;
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
}

}  // namespace pb
