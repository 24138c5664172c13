// Ray queries over the scene's triangles. The only file that includes Embree is
// src/world/accel.cpp.
#pragma once

#include "scene/scene.h"
#include "util/rng.h"

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

// Whether the ray of key `key` stops at triangle `prim` of mesh `mesh`, a BLEND surface of
// coverage a there: a uniform number u in [0, 1) hashed from the three, the surface met when
// u < a (probability a, so 1 - a of the rays pass). One number per ray and triangle: Embree may
// report a triangle twice (spatial splits), and both reports get the same answer; two rays of a
// path (a reflection back through the same card) have independent keys.
inline bool stops_ray(uint64_t key, uint32_t mesh, uint32_t prim, float a) {
  const uint64_t h = mix64(key ^ mix64((uint64_t(mesh) << 32) | prim));
  return float(h >> 40) * 0x1p-24f < a;
}

class Accel {
 public:
  // Builds a static Embree scene with one triangle geometry per mesh (geometry id = mesh index).
  explicit Accel(const Scene& scene);
  ~Accel();
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  // Closest hit along origin + t dir for t in (tnear, tfar). MASK cut-outs are passed through.
  // A BLEND surface (Material::blended) is met with its coverage a as probability: the ray's
  // `key` (a random number of the work item's stream, World::ray_key) and the triangle decide,
  // stops_ray below. Key 0 meets every BLEND surface, whose caller weighs it by a itself.
  bool intersect(const vec3& origin, const vec3& dir, float tnear, float tfar, Hit& hit,
                 uint64_t key = 0) const;
  // A ray of a packet: intersect()'s arguments.
  struct Ray {
    vec3 origin{0.0f}, dir{0.0f, 0.0f, 1.0f};
    float tnear = 0.0f, tfar = 0.0f;
    uint64_t key = 0;
  };
  static constexpr int kPacket = 8;
  // The closest hits of n <= kPacket rays traced together (Embree 3's rtcIntersect8: one walk
  // of the BVH for the packet, which pays where the rays are coherent, as a row of camera rays
  // is): found[i] and hits[i] are what intersect() gives rays[i] alone.
  void intersect_packet(const Ray* rays, int n, Hit* hits, bool* found) const;
  // True when anything lies along the segment (tnear, tfar); BLEND surfaces as above.
  bool occluded(const vec3& origin, const vec3& dir, float tnear, float tfar,
                uint64_t key = 0) const;
  // occluded() for n <= kPacket rays traced together (rtcOccluded8): blocked[i] is what
  // occluded() gives rays[i] alone.
  void occluded_packet(const Ray* rays, int n, bool* blocked) const;

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
