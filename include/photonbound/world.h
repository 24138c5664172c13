// The prepared, immutable render state of a scene: plain Scene data plus the acceleration
// structure and the light sampler, and the geometric queries every pass needs.
#pragma once

#include "photonbound/accel.h"
#include "photonbound/lights.h"
#include "photonbound/scene.h"
#include "photonbound/surface.h"

namespace pb {

class World {
 public:
  explicit World(const Scene& scene);

  const Scene& scene() const { return scene_; }
  const Accel& accel() const { return accel_; }
  const Lights& lights() const { return lights_; }
  float scene_size() const { return scene_size_; }

  Surface surface(const Hit& hit) const;

  // Start point for a ray leaving p in direction dir: moved off the surface along ng, to dir's
  // side, by an amount that scales with the scene and with |p| (float spacing).
  vec3 offset(const vec3& p, const vec3& ng, const vec3& dir) const {
    const float mag = max_component(glm::abs(p));
    const float eps = epsilon_ + mag * 4e-7f;
    return p + (glm::dot(dir, ng) >= 0.0f ? eps : -eps) * ng;
  }

  // Closest hit from p (on a surface with normal ng) in direction dir.
  bool trace(const vec3& p, const vec3& ng, const vec3& dir, Hit& hit) const {
    return accel_.intersect(offset(p, ng, dir), dir, 0.0f, INFINITY, hit);
  }
  // True when the segment from p toward dir of length dist is blocked.
  bool occluded(const vec3& p, const vec3& ng, const vec3& dir, float dist) const {
    const vec3 o = offset(p, ng, dir);
    return accel_.occluded(o, dir, 0.0f, dist * (1.0f - 1e-4f) - 2.0f * epsilon_);
  }

 private:
  const Scene& scene_;
  Accel accel_;
  Lights lights_;
  float scene_size_;
  float epsilon_;
};

}  // namespace pb
