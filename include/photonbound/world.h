// The prepared, immutable render state of a scene: plain Scene data plus the acceleration
// structure and the light sampler, and the geometric queries every pass needs.
#pragma once

#include "photonbound/accel.h"
#include "photonbound/lights.h"
#include "photonbound/ray_offset.h"
#include "photonbound/scene.h"
#include "photonbound/surface.h"

#include <vector>

namespace pb {

// World owns the Scene it was built from; the acceleration structure and the light sampler
// point into it, so a World is neither copied nor moved.
class World {
 public:
  explicit World(Scene scene);
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const Scene& scene() const { return scene_; }
  const Accel& accel() const { return accel_; }
  const Lights& lights() const { return lights_; }
  float scene_size() const { return scene_size_; }

  // The hit's position, normals and material. Inline: it runs once per photon bounce.
  Surface surface(const Hit& hit) const {
    const MeshView& mesh = meshes_[hit.mesh];
    const uint32_t* tri = mesh.indices + 3 * size_t(hit.prim);
    const uint32_t i0 = tri[0], i1 = tri[1], i2 = tri[2];
    const float w = 1.0f - hit.u - hit.v;
    Surface s;
    // Barycentric interpolation is more accurate than origin + t dir far from the origin.
    s.position = w * mesh.positions[i0] + hit.u * mesh.positions[i1] + hit.v * mesh.positions[i2];
    s.ng = mesh.face_normals[hit.prim];
    s.error = surface_error(mesh.positions[i0], mesh.positions[i1], mesh.positions[i2], s.ng);
    s.ns = s.ng;
    if (mesh.normals) {
      const vec3 n = w * mesh.normals[i0] + hit.u * mesh.normals[i1] + hit.v * mesh.normals[i2];
      const float len = glm::length(n);
      if (len > 0.0f) {
        s.ns = n / len;
        if (glm::dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
      }
    }
    s.material = mesh.material;
    s.bsdf = Bsdf(*mesh.material, s.ng, s.ns);
    return s;
  }

  // Start point for a ray leaving surface point p (geometric normal ng, position error bound
  // `error` along it, Surface::error) toward dir's side (ray_offset.h). Nothing here depends on
  // the scene's size: a small object beside a huge one keeps offsets of its own scale.
  static vec3 spawn(const vec3& p, const vec3& ng, float error, const vec3& dir) {
    return offset_ray_origin(p, ng, error, dir);
  }
  static vec3 spawn(const Surface& s, const vec3& dir) {
    return offset_ray_origin(s.position, s.ng, s.error, dir);
  }

  // Closest hit from surface point p (normal ng, error bound `error`) in direction dir.
  bool trace(const vec3& p, const vec3& ng, float error, const vec3& dir, Hit& hit) const {
    return accel_.intersect(spawn(p, ng, error, dir), dir, 0.0f, INFINITY, hit);
  }
  // True when the segment from `origin` (already spawned off its surface) toward dir is blocked
  // before the point at `dist`, less `margin`: the distance within which that point's own
  // surface may be found by rounding (DirectSample::margin; 0 for a point light, and dist is
  // infinite for directional and environment light).
  bool occluded(const vec3& origin, const vec3& dir, float dist, float margin) const {
    const float tfar = (dist - margin) * kShadowLengthFactor;
    return tfar > 0.0f && accel_.occluded(origin, dir, 0.0f, tfar);
  }

  // Triangles by one global index (mesh after mesh, in Scene order), for the boundary index.
  uint32_t triangle_count() const { return uint32_t(face_normals_.size()); }
  uint32_t triangle_index(uint32_t mesh, uint32_t prim) const {
    return first_triangle_[mesh] + prim;
  }
  uint32_t triangle_index(const Hit& hit) const { return triangle_index(hit.mesh, hit.prim); }
  const vec3& face_normal(uint32_t triangle) const { return face_normals_[triangle]; }
  // The three corners of a triangle, in winding order.
  void triangle(uint32_t t, vec3& a, vec3& b, vec3& c) const;
  // The mesh a triangle belongs to, and its material.
  uint32_t mesh_of(uint32_t t) const;
  const Material& material_of(uint32_t t) const { return *meshes_[mesh_of(t)].material; }

 private:
  // What surface() reads, without the indirection through Scene::meshes. The face normals
  // normalize(cross(p1 - p0, p2 - p0)) are precomputed (12 bytes per triangle): one load per
  // hit instead of a cross product, a square root and a division on the photon's critical path.
  struct MeshView {
    const vec3* positions;
    const vec3* normals;  // null when the mesh has none
    const uint32_t* indices;
    const vec3* face_normals;
    const Material* material;
  };

  const Scene scene_;
  std::vector<vec3> face_normals_;  // all meshes, concatenated
  std::vector<MeshView> meshes_;
  std::vector<uint32_t> first_triangle_;  // per mesh, and the total last
  Accel accel_;
  Lights lights_;
  float scene_size_;
};

}  // namespace pb
