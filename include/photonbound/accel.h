// Ray queries over the scene's triangles. The only file that includes Embree is src/accel.cpp.
#pragma once

#include "photonbound/scene.h"

#include <cstdint>
#include <memory>

namespace pb {

struct Hit {
  float t = 0.0f;
  uint32_t mesh = 0;  // index into Scene::meshes
  uint32_t prim = 0;  // triangle index within the mesh
  float u = 0.0f;     // barycentrics of vertices 1 and 2
  float v = 0.0f;
};

class Accel {
 public:
  // Builds a static Embree scene with one triangle geometry per mesh (geometry id = mesh index).
  explicit Accel(const Scene& scene);
  ~Accel();
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  // Closest hit along origin + t dir for t in (tnear, tfar).
  bool intersect(const vec3& origin, const vec3& dir, float tnear, float tfar, Hit& hit) const;
  // True when anything lies along the segment (tnear, tfar).
  bool occluded(const vec3& origin, const vec3& dir, float tnear, float tfar) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pb
