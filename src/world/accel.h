// Ray queries over the scene's triangles. The only file that includes Embree is
// src/world/accel.cpp.
#pragma once

#include "scene/scene.h"

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

  // Calls visit(mesh, prim) for every triangle whose bounding box meets the sphere (a superset
  // of the triangles within `radius` of `center`; the caller tests the geometry itself).
  using SphereVisit = void (*)(void* user, uint32_t mesh, uint32_t prim);
  void query_sphere(const vec3& center, float radius, SphereVisit visit, void* user) const;
  template <class F>
  void query_sphere(const vec3& center, float radius, F&& f) const {
    query_sphere(
        center, radius,
        [](void* u, uint32_t mesh, uint32_t prim) { (*static_cast<F*>(u))(mesh, prim); }, &f);
  }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pb
