// Plain scene data, as loaded: no acceleration structures, no render state. Every mesh is
// already flattened to world space (the node hierarchy is applied by the loader).
#pragma once

#include "util/math.h"

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb {

// Bad input in a scene file. what() is one line: "<file>: <what is wrong>".
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// glTF's texture wrap modes (sampler wrapS / wrapT).
enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

// A decoded image (glTF "image"): texels row by row from the top (glTF's uv (0, 0) is the
// image's top-left corner), `channels` per texel, as 8-bit values or as floats in [0, 1].
struct Image {
  std::string name;  // for messages: the uri, or "image N"
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> u8;  // 8-bit images (PNG, JPEG)
  std::vector<float> f32;   // everything else (16-bit PNG, float formats)
};

// A glTF textureInfo resolved for lookups: the image, the sampler's wrap modes and filter, the
// texture coordinate set and KHR_texture_transform as an affine map of the coordinates:
// (s, t) = (m[0] u + m[1] v + m[2], m[3] u + m[4] v + m[5]).
struct TextureRef {
  int32_t image = -1;  // index into Scene::images; -1: no texture
  uint8_t texcoord = 0;
  Wrap wrap_s = Wrap::Repeat, wrap_t = Wrap::Repeat;
  bool nearest = false;  // sampler magFilter NEAREST; otherwise bilinear
  float m[6] = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
  bool present() const { return image >= 0; }
};

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

// glTF 2.0's metallic-roughness material with the extensions photonbound reads, as the file
// gives it (factors with glTF's defaults; each texture multiplies its factor). World::surface()
// evaluates the textures at a hit and makes the Bsdf from the result (docs/materials.md).
struct Material {
  std::string name;
  vec3 base_color{1.0f};  // baseColorFactor.rgb, linear
  float alpha = 1.0f;     // baseColorFactor.a
  float metallic = 1.0f, roughness = 1.0f;
  float ior = 1.5f;                       // KHR_materials_ior
  float specular = 1.0f;                  // KHR_materials_specular specularFactor
  vec3 specular_color{1.0f};              // KHR_materials_specular specularColorFactor
  float transmission = 0.0f;              // KHR_materials_transmission transmissionFactor
  bool thin = true;                       // no KHR_materials_volume (or thicknessFactor 0)
  float clearcoat = 0.0f;                 // KHR_materials_clearcoat clearcoatFactor (0: no coat)
  float clearcoat_roughness = 0.0f;       // clearcoatRoughnessFactor
  float clearcoat_normal_scale = 1.0f;    // clearcoatNormalTexture.scale
  vec3 sheen_color{0.0f};                 // KHR_materials_sheen sheenColorFactor (black: none)
  float sheen_roughness = 0.0f;           // sheenRoughnessFactor
  float anisotropy = 0.0f;                // KHR_materials_anisotropy anisotropyStrength (0: none)
  float anisotropy_rotation = 0.0f;       // anisotropyRotation, radians from the tangent to b
  float dispersion = 0.0f;                // KHR_materials_dispersion (20 / Abbe number; 0: none)
  float diffuse_transmission = 0.0f;      // KHR_materials_diffuse_transmission factor (0: none)
  vec3 diffuse_transmission_color{1.0f};  // diffuseTransmissionColorFactor
  float iridescence = 0.0f;               // KHR_materials_iridescence iridescenceFactor (0: none)
  float iridescence_ior = 1.3f;           // iridescenceIor
  float iridescence_thickness_minimum = 100.0f;  // nm, at the thickness texture's 0
  float iridescence_thickness_maximum = 400.0f;  // nm, at its 1 (and without it)
  vec3 attenuation{0.0f};     // KHR_materials_volume: Beer-Lambert coefficient, 1/length
  vec3 emission{0.0f};        // emissiveFactor x KHR_materials_emissive_strength
  bool double_sided = false;  // doubleSided: an emitter emits from both sides
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  // KHR_materials_unlit: the camera sees the base colour as the surface's radiance; to light it
  // is black (it reflects and emits nothing; docs/materials.md "Unlit").
  bool unlit = false;
  float normal_scale = 1.0f;                 // normalTexture.scale
  TextureRef base_color_texture;             // sRGB; alpha in A
  TextureRef metallic_roughness_texture;     // B metal, G rough (linear)
  TextureRef normal_texture;                 // tangent-space normal (linear)
  TextureRef emissive_texture;               // sRGB
  TextureRef transmission_texture;           // R (linear)
  TextureRef specular_texture;               // A (linear)
  TextureRef specular_color_texture;         // sRGB
  TextureRef clearcoat_texture;              // R (linear)
  TextureRef clearcoat_roughness_texture;    // G (linear)
  TextureRef clearcoat_normal_texture;       // tangent-space normal of the coat (linear)
  TextureRef sheen_color_texture;            // sRGB
  TextureRef sheen_roughness_texture;        // A (linear)
  TextureRef anisotropy_texture;             // RG direction in [-1, 1], B strength (linear)
  TextureRef iridescence_texture;            // R (linear)
  TextureRef iridescence_thickness_texture;  // G (linear)
  // KHR_materials_pbrSpecularGlossiness's specularGlossinessTexture (RGB specular sRGB, A
  // glossiness linear) and the factors it multiplies; the conversion to the fields above is in
  // the loader (gltf_material.cpp), this texture's part per hit (World::surface).
  TextureRef specular_glossiness_texture;
  TextureRef diffuse_transmission_texture;        // A (linear)
  TextureRef diffuse_transmission_color_texture;  // sRGB
  vec3 sg_specular{1.0f};
  float sg_glossiness = 1.0f;

  // Emits somewhere: the factor is positive (an emissive texture may still be black in places).
  bool emits() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
  // Rays pass through where the base colour's alpha is below the cutoff (alphaMode MASK).
  bool masked() const { return alpha_mode == AlphaMode::Mask; }
  // The base colour's alpha is the share of rays the surface stops (alphaMode BLEND as
  // stochastic coverage; docs/materials.md "Alpha").
  bool blended() const { return alpha_mode == AlphaMode::Blend; }

  // Plain materials for tests and defaults: a Lambertian (metallic 0 and KHR_materials_specular
  // specularFactor 0: glTF's way to say "no specular layer"), a smooth metal, smooth glass.
  static Material lambertian(const vec3& rho);
  static Material metal(const vec3& base, float roughness);
  static Material glass(float ior, bool thin = false);
};

inline Material Material::lambertian(const vec3& rho) {
  Material m;
  m.base_color = rho;
  m.metallic = 0.0f;
  m.specular = 0.0f;
  return m;
}
inline Material Material::metal(const vec3& base, float roughness) {
  Material m;
  m.base_color = base;
  m.roughness = roughness;
  return m;
}
inline Material Material::glass(float ior, bool thin) {
  Material m;
  m.metallic = 0.0f;
  m.roughness = 0.0f;
  m.transmission = 1.0f;
  m.ior = ior;
  m.thin = thin;
  return m;
}

struct Mesh {
  std::string name;             // glTF mesh name (or "mesh <index>") for messages
  std::vector<vec3> positions;  // world space
  std::vector<vec3> normals;    // world space, unit length; empty when the file has none
  // TEXCOORD_0 and TEXCOORD_1 as the file gives them (dequantised), one per position; empty
  // when absent.
  std::vector<vec2> texcoords[2];
  // Tangent frames for the normal texture and the anisotropy direction, one per position: xyz
  // unit (world space), w = +-1 the bitangent's sign (glTF TANGENT: bitangent = cross(normal,
  // xyz) w). The file's TANGENT, or made from the normal (or anisotropy) texture's coordinates;
  // empty when the material has neither a normal texture nor anisotropy.
  std::vector<glm::vec4> tangents;
  // COLOR_0, linear RGBA in [0, 1] (A = 1 from an RGB attribute), one per position: it multiplies
  // the base colour and its alpha; empty when absent.
  std::vector<glm::vec4> colors;
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
// is the default sky of a scene without lights (scene_defaults.h).
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
  std::optional<Environment> environment;  // none unless given or defaulted (scene_defaults.h)
  std::vector<Image> images;               // the decoded images the materials use
  Bounds bounds;                           // of all triangle vertices
  // Where the file's world origin lies in the coordinates stored here: positions (vertices,
  // cameras, lights) are the file's minus `origin`. Zero unless the model lies far from the
  // origin for its size (geo-referenced content at 4e6 m, where float steps are 0.5 m): the
  // loader then centres it in double precision (Loader::choose_origin), and view.cpp shifts
  // --look-from and --look-at, which are given in the file's coordinates, the same way.
  dvec3 origin{0.0};
  uint64_t degenerate_triangles = 0;  // skipped at load time
  std::vector<std::string> warnings;  // each once, for the user
  // Identity of the loaded content (the file's bytes, every buffer and image it loads), which
  // resume compares: an edited external .bin must not continue a render of the old one.
  uint64_t content_hash = 0;
  // Every file the loader read, as it opened them: the scene file first (load_gltf), then its
  // external buffers and images. The outputs of a render must be none of them.
  std::vector<std::string> files;

  size_t triangle_count() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.indices.size() / 3;
    return n;
  }
};

}  // namespace pb
