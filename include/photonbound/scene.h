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

enum class PunctualKind : uint8_t { Point, Spot, Directional };

// KHR_lights_punctual light. intensity = color * intensity, taken as radiant intensity (W/sr per
// channel, in the image's radiance units) for point and spot lights, and as the irradiance on a
// surface facing a directional light (W/m^2 per channel; glTF's lux).
struct PunctualLight {
  std::string name;
  PunctualKind kind = PunctualKind::Point;
  vec3 position{0.0f};                // point and spot
  vec3 direction{0.0f, 0.0f, -1.0f};  // spot axis or the directional light's travel, unit
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

// Light arriving from infinitely far away in every direction: a uniform colour (a 1 x 1 map) or
// an equirectangular (latitude-longitude) map. Pixel (x, y) of a W x H map covers the polar
// angles theta in [pi y / H, pi (y + 1) / H] from +Y and the azimuths phi in [2 pi x / W,
// 2 pi (x + 1) / W] of the directions d = (-sin theta sin phi, cos theta, sin theta cos phi):
// row 0 is the zenith (+Y, glTF's up), the centre column -Z (where the default view looks),
// the left and right quarters -X and +X, the edges +Z. Not glTF: it comes from --environment, or
// is the default sky of a scene without lights (scene_setup.h).
struct Environment {
  std::string source;  // for messages: "the default sky", "--environment 0.5", a file
  int width = 1, height = 1;
  std::vector<vec3> radiance;  // row-major, already times --environment-scale
};

struct Scene {
  std::string source;  // the file it came from, for messages
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<PunctualLight> lights;
  std::vector<Camera> cameras;             // every perspective camera, in node order
  std::optional<Environment> environment;  // none unless given or defaulted (scene_setup.h)
  Bounds bounds;                           // of all triangle vertices
  uint64_t degenerate_triangles = 0;       // skipped at load time
  std::vector<std::string> warnings;       // each once, for the user
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
