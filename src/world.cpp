#include "photonbound/world.h"

namespace pb {

World::World(Scene scene)
    : scene_(std::move(scene)),
      accel_(scene_),
      lights_(scene_),
      scene_size_(std::max(scene_.bounds.diagonal(), 1e-30f)) {
  size_t triangles = 0;
  for (const Mesh& m : scene_.meshes) triangles += m.indices.size() / 3;
  face_normals_.resize(triangles);
  size_t first = 0;
  for (const Mesh& m : scene_.meshes) {
    const size_t n = m.indices.size() / 3;
    for (size_t t = 0; t < n; ++t) {
      const vec3& p0 = m.positions[m.indices[3 * t]];
      const vec3& p1 = m.positions[m.indices[3 * t + 1]];
      const vec3& p2 = m.positions[m.indices[3 * t + 2]];
      face_normals_[first + t] = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    }
    meshes_.push_back({m.positions.data(), m.normals.empty() ? nullptr : m.normals.data(),
                       m.indices.data(), face_normals_.data() + first,
                       &scene_.materials[m.material]});
    first += n;
  }
}

}  // namespace pb
