#include "photonbound/world.h"

namespace pb {

World::World(const Scene& scene)
    : scene_(scene),
      accel_(scene),
      lights_(scene),
      scene_size_(std::max(scene.bounds.diagonal(), 1e-30f)),
      // Offsets of 1e-5 of the scene keep rays off their own surface without skipping
      // neighbouring geometry; the |p| term in offset() covers float spacing far from 0.
      epsilon_(1e-5f * scene_size_) {}

Surface World::surface(const Hit& hit) const {
  const Mesh& mesh = scene_.meshes[hit.mesh];
  const uint32_t i0 = mesh.indices[3 * hit.prim];
  const uint32_t i1 = mesh.indices[3 * hit.prim + 1];
  const uint32_t i2 = mesh.indices[3 * hit.prim + 2];
  const vec3& p0 = mesh.positions[i0];
  const vec3& p1 = mesh.positions[i1];
  const vec3& p2 = mesh.positions[i2];
  const float w = 1.0f - hit.u - hit.v;

  Surface s;
  // Barycentric interpolation is more accurate than origin + t dir far from the origin.
  s.position = w * p0 + hit.u * p1 + hit.v * p2;
  s.ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  s.ns = s.ng;
  if (!mesh.normals.empty()) {
    const vec3 n = w * mesh.normals[i0] + hit.u * mesh.normals[i1] + hit.v * mesh.normals[i2];
    const float len = glm::length(n);
    if (len > 0.0f) {
      s.ns = n / len;
      if (glm::dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
    }
  }
  s.material = &scene_.materials[mesh.material];
  return s;
}

}  // namespace pb
