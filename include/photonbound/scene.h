// Plain scene data, as loaded: no acceleration structures, no render state. Every mesh is
// already flattened to world space (the node hierarchy is applied by the loader).
#pragma once

#include "photonbound/math.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pb {

// The three reflection models photonbound supports (README "Materials").
enum class Reflection : uint8_t {
  Lambertian,  // f = base_color / pi
  Mirror,      // ideal specular reflection tinted by base_color
  Dielectric,  // smooth glass: Fresnel reflection + refraction, transmission tinted by base_color
};

struct Material {
  std::string name;
  Reflection model = Reflection::Lambertian;
  vec3 base_color{0.8f};  // reflectance (Lambertian, Mirror) or transmission tint (Dielectric)
  float ior = 1.5f;       // Dielectric only
  vec3 emission{0.0f};    // emitted radiance, front side only (winding order); 0 = not a light
  bool emits() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
};

struct Mesh {
  std::string name;             // glTF mesh name (or "mesh <index>") for messages
  std::vector<vec3> positions;  // world space
  std::vector<vec3> normals;    // world space, unit length; empty when the file has none
  // TEXCOORD_0 and TEXCOORD_1 as the file gives them (dequantised), one per position; empty
  // when absent. Read for the texture work to come; nothing uses them yet.
  std::vector<vec2> texcoords[2];
  std::vector<uint32_t> indices;  // three per triangle, degenerate triangles already removed
  uint32_t material = 0;          // index into Scene::materials
};

enum class PunctualKind : uint8_t { Point, Spot };

// KHR_lights_punctual light. intensity = color * intensity, taken as radiant intensity
// (W/sr per channel, in the image's radiance units).
struct PunctualLight {
  std::string name;
  PunctualKind kind = PunctualKind::Point;
  vec3 position{0.0f};
  vec3 direction{0.0f, 0.0f, -1.0f};  // spot axis, world space, unit length
  vec3 intensity{0.0f};
  float cos_inner = 1.0f;  // spot: full intensity inside the inner cone
  float cos_outer = 0.0f;  // spot: zero outside the outer cone
};

struct Camera {
  std::string name;
  vec3 position{0.0f};
  vec3 forward{0.0f, 0.0f, -1.0f};  // unit; the camera looks down its local -Z
  vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  vec3 right{1.0f, 0.0f, 0.0f};     // unit, forward x up
  float yfov = 0.8f;                // vertical field of view, radians
  std::optional<float> aspect;      // width / height when the file gives it
};

struct Scene {
  std::string source;  // the file it came from, for messages
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<PunctualLight> lights;
  std::vector<Camera> cameras;        // every perspective camera, in node order
  Bounds bounds;                      // of all triangle vertices
  uint64_t degenerate_triangles = 0;  // skipped at load time
  std::vector<std::string> warnings;  // each once, for the user
  // Identity of the loaded content (the file's bytes and every buffer it loads), which resume
  // compares: an edited external .bin must not continue a render of the old one.
  uint64_t content_hash = 0;

  size_t triangle_count() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.indices.size() / 3;
    return n;
  }
};

}  // namespace pb
