// The prepared, immutable render state of a scene: plain Scene data plus the acceleration
// structure and the light sampler, and the geometric queries every pass needs.
#pragma once

#include "lights/lights.h"
#include "scene/scene.h"
#include "scene/texture.h"
#include "util/ray_offset.h"
#include "util/rng.h"
#include "world/accel.h"
#include "world/surface.h"

#include <optional>
#include <string>
#include <vector>

namespace pb {

// World owns the Scene it was built from; the acceleration structure and the light sampler
// point into it, so a World is neither copied nor moved.
class World {
 public:
  // follows_transmission: rough glass is a GGX component (SPPM follows it); false renders it
  // smooth (PPM's fixed points cannot follow it; bsdf.h BsdfParams).
  explicit World(Scene scene, float mirror_roughness = float(kDefaultMirrorRoughness),
                 bool follows_transmission = true);
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const Scene& scene() const { return scene_; }
  const Accel& accel() const { return accel_; }
  const Lights& lights() const { return lights_; }
  float scene_size() const { return scene_size_; }

  // The hit's position, normals, texture coordinates and material, and the Bsdf made from the
  // material's factors and textures there (src/world/surface.cpp). Runs once per photon bounce.
  Surface surface(const Hit& hit) const;

  // Radiance the surface emits toward wo: the material's emission (texture included) on its
  // front side, or on both sides when the material is doubleSided.
  vec3 emitted(const Surface& s, const vec3& wo) const {
    const Material& m = *s.material;
    if (!m.emits() || (!m.double_sided && glm::dot(wo, s.ng) <= 0.0f)) return vec3(0.0f);
    // KHR_materials_clearcoat darkens the emission: 1 - k at the geometric normal, with
    // clearcoatFactor alone (Lights does the same for next-event samples and photons).
    const float coat = 1.0f - clearcoat_fresnel(m.clearcoat, glm::dot(wo, s.ng));
    // Where a ray met the surface it is there (MASK and BLEND: the coverage chose it).
    if (!m.emissive_texture.present()) return coat * m.emission;
    return coat * surface_emission(scene_.images, m, s.uv);
  }

  // Beer-Lambert transmittance exp(-sigma d) of the segment from `from` (the surface point it
  // left, not the ray's offset origin) to s, when it ran inside the volume s bounds (s seen from
  // its back side, KHR_materials_volume); else 1. Volumes are bounded by their own closed mesh:
  // a segment inside is one that reaches its inside surface.
  vec3 transmittance(const Surface& s, const vec3& wo, const vec3& from) const {
    const Material& m = *s.material;
    if (m.thin || m.transmission <= 0.0f || glm::dot(wo, s.ng) >= 0.0f) return vec3(1.0f);
    return glm::exp(-m.attenuation * glm::distance(from, s.position));
  }

  // Whether visible points can lie on a surface of this material: its Bsdf has a non-delta
  // part for the factors, or a texture may lower its metalness or transmission.
  bool may_hold_points(const Material& m) const;

  // The roughness below which GGX lobes are perfect mirrors (--mirror-roughness).
  float mirror_roughness() const { return mirror_roughness_; }
  // "materials 'a', 'b': roughness below R ... rendered as perfect mirrors", or "" when no
  // material has a lobe that smooth (the note the command line prints).
  std::string mirror_note() const;
  // The materials whose transmitting part is rough (roughness at or above the mirror's, or
  // textured) or that transmit diffusely, as "materials 'a', 'b'"; empty when none. PPM renders
  // them as smooth glass and diffuse reflection (app/diagnostics.cpp).
  std::string followed_transmission_names() const;

  // Start point for a ray leaving surface point p (geometric normal ng, position error bound
  // `error` along it, Surface::error) toward dir's side (ray_offset.h). Nothing here depends on
  // the scene's size: a small object beside a huge one keeps offsets of its own scale.
  static vec3 spawn(const vec3& p, const vec3& ng, float error, const vec3& dir) {
    return offset_ray_origin(p, ng, error, dir);
  }
  static vec3 spawn(const Surface& s, const vec3& dir) {
    return offset_ray_origin(s.position, s.ng, s.error, dir);
  }

  // Closest hit from surface point p (normal ng, error bound `error`) in direction dir; BLEND
  // surfaces are met by the ray's key (Accel::intersect, ray_key).
  bool trace(const vec3& p, const vec3& ng, float error, const vec3& dir, Hit& hit,
             uint64_t key = 0) const {
    return accel_.intersect(spawn(p, ng, error, dir), dir, 0.0f, INFINITY, hit, key);
  }

  // The coverage key of a ray that meets BLEND surfaces by chance (Accel::intersect): 64 bits of
  // the work item's stream (pass, pixel or photon, and the bounce by the stream's position), so
  // the choice depends on the work item, never on the thread. 0 (every BLEND surface met) in a
  // scene without BLEND surfaces, which then draws no number: its images are unchanged.
  uint64_t ray_key(Rng& rng) const {
    if (!has_blend_) return 0;
    const uint64_t hi = rng.next_u32(), lo = rng.next_u32();
    return (hi << 32 | lo) | 1u;
  }
  // Whether some surface is BLEND (after settle_blend: its coverage is below 1 somewhere).
  bool has_blend() const { return has_blend_; }
  // The coverage of surface s at hit (texture.h coverage): 1 but on MASK and BLEND surfaces.
  float coverage(const Hit& hit, const Surface& s) const {
    const Material& m = *s.material;
    if (!m.blended() && !m.masked()) return 1.0f;
    return pb::coverage(scene_.images, m, s.uv,
                        mesh_alpha(scene_.meshes[hit.mesh], hit.prim, hit.u, hit.v));
  }
  // The first surface a camera ray from `origin` sees. glTF culls the back faces of a material
  // that is not doubleSided ("back-face culling is enabled", glTF 2.0 section 3.9.5), so the
  // camera sees through them, as every glTF viewer draws the scene: a camera placed inside a
  // vehicle's single-sided shell sees the street. Transmissive materials keep both sides (a
  // camera under water sees the surface from below). Only the camera's first ray culls: light,
  // shadows and the surfaces seen through mirrors and glass meet both sides of every surface.
  // Returns the number of faces passed through in `culled` (at most kMaxCulledFaces; beyond,
  // the last one is what the ray sees).
  bool camera_hit(const vec3& origin, const vec3& dir, Hit& hit, int* culled = nullptr,
                  uint64_t key = 0) const;
  // camera_hit for n <= Accel::kPacket rays from `origin` (directions dirs, keys keys), their
  // first hits traced as one packet (Accel::intersect_packet): found[i] and hits[i] are
  // camera_hit's for ray i, bit for bit.
  void camera_hits(const vec3& origin, const vec3* dirs, const uint64_t* keys, int n, Hit* hits,
                   bool* found) const;
  static constexpr int kMaxCulledFaces = 64;

  // Whether the camera at p is enclosed: in none of 256 directions spread over the sphere does
  // its ray (culling as camera_hit does) reach the environment unobstructed. Then `outermost`
  // lists the meshes such rays meet last, passing through everything, before they would reach
  // it, with the share of directions each is last in: those of at least a tenth, the most
  // frequent first, at most three (a sky box or dome made for viewers, and the ground below).
  // None when some direction is open.
  // Meshes are counted by name: the primitives of one glTF mesh are one shell.
  struct Enclosure {
    std::vector<std::pair<std::string, double>> outermost;  // mesh name, share
  };
  std::optional<Enclosure> camera_enclosure(const vec3& p) const;

  // True when the segment from `origin` (already spawned off its surface) toward dir is blocked
  // before the point at `dist`, less `margin`: the distance within which that point's own
  // surface may be found by rounding (DirectSample::margin; 0 for a point light, and dist is
  // infinite for directional and environment light).
  // A BLEND surface blocks it by the ray's key (ray_key; key 0: always).
  bool occluded(const vec3& origin, const vec3& dir, float dist, float margin,
                uint64_t key = 0) const {
    Accel::Ray r;
    return shadow_ray(origin, dir, dist, margin, key, r) &&
           accel_.occluded(r.origin, r.dir, r.tnear, r.tfar, r.key);
  }
  // The segment occluded() tests, as a ray; false where it is empty (nothing can block it).
  static bool shadow_ray(const vec3& origin, const vec3& dir, float dist, float margin,
                         uint64_t key, Accel::Ray& ray) {
    ray = {origin, dir, 0.0f, (dist - margin) * kShadowLengthFactor, key};
    return ray.tfar > 0.0f;
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
    const vec2* texcoords[2];   // null when the mesh has none
    const glm::vec4* tangents;  // null without a normal texture
    const glm::vec4* colors;    // COLOR_0, null without it
    bool textured;  // the material has a texture (or a MASK cut-out), or the mesh COLOR_0
    // Untextured with a frame-free Bsdf (Bsdf::frame_free): that Bsdf, at any frame.
    const Bsdf* plain;
  };
  // camera_hit's part after the first hit: through the backs of culled faces.
  bool beyond_culled(const vec3& dir, Hit& hit, int* culled, uint64_t key) const;

  const Scene scene_;
  std::vector<vec3> face_normals_;  // all meshes, concatenated
  std::vector<MeshView> meshes_;
  std::vector<Bsdf> plain_bsdfs_;         // per material, for MeshView::plain
  std::vector<uint32_t> first_triangle_;  // per mesh, and the total last
  Accel accel_;
  Lights lights_;
  float scene_size_;
  float mirror_roughness_;
  bool follows_transmission_;
  bool has_blend_ = false;
};

}  // namespace pb
