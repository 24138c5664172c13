#include "world/world.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace pb {

namespace {
Scene with_settled_blend(Scene scene) {
  settle_blend(scene);
  return scene;
}
}  // namespace

World::World(Scene scene, float mirror_roughness, bool follows_transmission)
    : scene_(with_settled_blend(std::move(scene))),
      accel_(scene_),
      lights_(scene_),
      scene_size_(std::max(scene_.bounds.diagonal(), 1e-30f)),
      mirror_roughness_(mirror_roughness),
      follows_transmission_(follows_transmission) {
  size_t triangles = 0;
  for (const Mesh& m : scene_.meshes) triangles += m.indices.size() / 3;
  face_normals_.resize(triangles);
  // Every material's Bsdf at a frame of its own, for the untextured meshes whose Bsdf a frame
  // moves (World::surface); built whole before any mesh points into the vector.
  std::vector<bool> frame_free;
  plain_bsdfs_.reserve(scene_.materials.size());
  for (const Material& mat : scene_.materials) {
    BsdfParams p = BsdfParams::of(mat);
    p.follows_transmission = follows_transmission_;
    frame_free.push_back(!mat.unlit && Bsdf::frame_free(p));
    plain_bsdfs_.emplace_back(p, vec3(0, 0, 1), vec3(0, 0, 1), mirror_roughness_);
  }
  size_t first = 0;
  for (const Mesh& m : scene_.meshes) {
    const size_t n = m.indices.size() / 3;
    for (size_t t = 0; t < n; ++t) {
      const vec3& p0 = m.positions[m.indices[3 * t]];
      const vec3& p1 = m.positions[m.indices[3 * t + 1]];
      const vec3& p2 = m.positions[m.indices[3 * t + 2]];
      face_normals_[first + t] = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    }
    const Material& mat = scene_.materials[m.material];
    has_blend_ = has_blend_ || mat.blended();
    const bool textured =
        mat.base_color_texture.present() || mat.metallic_roughness_texture.present() ||
        mat.normal_texture.present() || mat.emissive_texture.present() ||
        mat.transmission_texture.present() || mat.specular_texture.present() ||
        mat.specular_color_texture.present() || mat.masked() || mat.clearcoat_texture.present() ||
        mat.clearcoat_roughness_texture.present() || mat.clearcoat_normal_texture.present() ||
        mat.sheen_color_texture.present() || mat.sheen_roughness_texture.present() ||
        (mat.anisotropy > 0.0f && !m.tangents.empty()) ||  // the direction needs the tangents
        mat.iridescence_texture.present() || mat.iridescence_thickness_texture.present() ||
        mat.specular_glossiness_texture.present() || mat.diffuse_transmission_texture.present() ||
        mat.diffuse_transmission_color_texture.present() || !m.colors.empty();
    auto uv = [&](int set) { return m.texcoords[set].empty() ? nullptr : m.texcoords[set].data(); };
    first_triangle_.push_back(uint32_t(first));
    meshes_.push_back({m.positions.data(),
                       m.normals.empty() ? nullptr : m.normals.data(),
                       m.indices.data(),
                       face_normals_.data() + first,
                       &mat,
                       {uv(0), uv(1)},
                       m.tangents.empty() ? nullptr : m.tangents.data(),
                       m.colors.empty() ? nullptr : m.colors.data(),
                       textured,
                       !textured && frame_free[m.material] ? &plain_bsdfs_[m.material] : nullptr});
    first += n;
  }
  first_triangle_.push_back(uint32_t(first));
}

uint32_t World::mesh_of(uint32_t t) const {
  const auto it = std::upper_bound(first_triangle_.begin(), first_triangle_.end(), t);
  return uint32_t(it - first_triangle_.begin()) - 1;
}

void World::triangle(uint32_t t, vec3& a, vec3& b, vec3& c) const {
  const uint32_t m = mesh_of(t);
  const MeshView& mv = meshes_[m];
  const uint32_t* tri = mv.indices + 3 * size_t(t - first_triangle_[m]);
  a = mv.positions[tri[0]];
  b = mv.positions[tri[1]];
  c = mv.positions[tri[2]];
}

bool World::camera_hit(const vec3& origin, const vec3& dir, Hit& hit, int* culled,
                       uint64_t key) const {
  if (culled) *culled = 0;
  // One key for the whole line: a BLEND surface beyond a culled face gets the same choice when
  // the ray goes on from that face.
  if (!accel_.intersect(origin, dir, 0.0f, INFINITY, hit, key)) return false;
  return beyond_culled(dir, hit, culled, key);
}

void World::camera_hits(const vec3& origin, const vec3* dirs, const uint64_t* keys, int n,
                        Hit* hits, bool* found) const {
  Accel::Ray rays[Accel::kPacket];
  for (int i = 0; i < n; ++i) rays[i] = {origin, dirs[i], 0.0f, INFINITY, keys[i]};
  accel_.intersect_packet(rays, n, hits, found);
  for (int i = 0; i < n; ++i)
    if (found[i]) found[i] = beyond_culled(dirs[i], hits[i], nullptr, keys[i]);
}

bool World::beyond_culled(const vec3& dir, Hit& hit, int* culled, uint64_t key) const {
  for (int k = 0; k < kMaxCulledFaces; ++k) {
    const Material& m = *meshes_[hit.mesh].material;
    const uint32_t t = triangle_index(hit);
    if (m.double_sided || m.transmission > 0.0f || glm::dot(dir, face_normals_[t]) <= 0.0f)
      return true;
    // The back of a single-sided face: go on from just beyond it.
    const Surface s = surface(hit);
    if (culled) *culled = k + 1;
    if (!trace(s.position, s.ng, s.error, dir, hit, key)) return false;
  }
  return true;
}

std::optional<World::Enclosure> World::camera_enclosure(const vec3& p) const {
  constexpr int kDirections = 256, kMaxHits = 256;
  std::vector<uint32_t> last_count(scene_.meshes.size(), 0);
  for (int k = 0; k < kDirections; ++k) {
    // Fibonacci points on the sphere: even coverage without randomness.
    const float z = 1.0f - 2.0f * (float(k) + 0.5f) / float(kDirections);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.39996323f * float(k);
    const vec3 dir(r * std::cos(phi), r * std::sin(phi), z);
    Hit hit;
    if (!camera_hit(p, dir, hit)) return std::nullopt;  // the camera sees the environment
    int hits = 1;
    uint32_t last = hit.mesh;
    for (;;) {
      const Surface s = surface(hit);
      if (!trace(s.position, s.ng, s.error, dir, hit)) break;
      last = hit.mesh;
      if (++hits == kMaxHits) break;
    }
    ++last_count[last];
  }
  std::map<std::string, uint32_t> by_name;
  for (uint32_t m = 0; m < last_count.size(); ++m) by_name[scene_.meshes[m].name] += last_count[m];
  Enclosure e;
  for (const auto& [name, count] : by_name)
    if (count * 10 >= kDirections) e.outermost.push_back({name, double(count) / kDirections});
  std::stable_sort(e.outermost.begin(), e.outermost.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  if (e.outermost.size() > 3) e.outermost.resize(3);
  return e;
}

}  // namespace pb
