// glTF loader tests. Every test writes its own small glTF into a temporary directory; only
// SmokeLoadsShippedScenes reads scenes/ (and skips when it is empty).
#include "gltf/gltf_loader.h"
#include "io/image_io.h"
#include "lights/lights.h"
#include "render/scene_setup.h"
#include "render/view.h"
#include "world/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using pb::load_gltf;
using pb::Scene;
using pb::SceneError;
using pb::vec3;

std::string base64(const std::vector<unsigned char>& d) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < d.size(); i += 3) {
    const uint32_t n = uint32_t(d[i]) << 16 | (i + 1 < d.size() ? uint32_t(d[i + 1]) << 8 : 0u) |
                       (i + 2 < d.size() ? uint32_t(d[i + 2]) : 0u);
    out += t[n >> 18 & 63];
    out += t[n >> 12 & 63];
    out += i + 1 < d.size() ? t[n >> 6 & 63] : '=';
    out += i + 2 < d.size() ? t[n & 63] : '=';
  }
  return out;
}

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const std::string& i : items) s += (s.empty() ? "" : ",") + i;
  return s;
}

// A glTF document with one buffer; sections hold raw JSON objects.
struct Gltf {
  std::vector<unsigned char> bin;
  std::vector<std::string> views, accessors, meshes, nodes, materials, lights, cameras;
  std::optional<std::vector<int>> roots;  // scene 0 nodes; default: every node added
  std::string top;                        // extra top-level members, each followed by ','
  std::string buffer_uri;                 // overrides the embedded data URI
  bool scenes = true;                     // false: no "scene"/"scenes" at all

  template <class T>
  int view(const std::vector<T>& v, const std::string& extra = "") {
    while (bin.size() % 4) bin.push_back(0);
    const size_t off = bin.size(), len = v.size() * sizeof(T);
    bin.resize(off + len);
    if (len) std::memcpy(bin.data() + off, v.data(), len);
    views.push_back("{\"buffer\":0,\"byteOffset\":" + std::to_string(off) +
                    ",\"byteLength\":" + std::to_string(len) + extra + "}");
    return int(views.size()) - 1;
  }
  int accessor(int view, int component, size_t count, const char* type,
               const std::string& extra = "") {
    accessors.push_back("{\"bufferView\":" + std::to_string(view) + ",\"componentType\":" +
                        std::to_string(component) + ",\"count\":" + std::to_string(count) +
                        ",\"type\":\"" + type + "\"" + extra + "}");
    return int(accessors.size()) - 1;
  }
  int vec3s(const std::vector<float>& xyz) {
    return accessor(view(xyz), 5126, xyz.size() / 3, "VEC3");
  }
  int indices(const std::vector<uint16_t>& i) {
    return accessor(view(i), 5123, i.size(), "SCALAR");
  }
  // A mesh with one primitive; attributes and extra are raw JSON.
  int mesh(const std::string& name, int position, int index = -1, int material = -1,
           const std::string& extra_attributes = "", const std::string& extra = "") {
    std::string p =
        "{\"attributes\":{\"POSITION\":" + std::to_string(position) + extra_attributes + "}";
    if (index >= 0) p += ",\"indices\":" + std::to_string(index);
    if (material >= 0) p += ",\"material\":" + std::to_string(material);
    meshes.push_back("{\"name\":\"" + name + "\",\"primitives\":[" + p + extra + "}]}");
    return int(meshes.size()) - 1;
  }
  int node(const std::string& body) {
    nodes.push_back("{" + body + "}");
    return int(nodes.size()) - 1;
  }
  int material(const std::string& body) {
    materials.push_back("{" + body + "}");
    return int(materials.size()) - 1;
  }
  int light(const std::string& body) {
    lights.push_back("{" + body + "}");
    return int(lights.size()) - 1;
  }
  int camera(double yfov, const std::string& extra = "") {
    cameras.push_back("{\"type\":\"perspective\",\"perspective\":{\"yfov\":" +
                      std::to_string(yfov) + ",\"znear\":0.01" + extra + "}}");
    return int(cameras.size()) - 1;
  }

  std::string json(bool glb = false) const {
    std::vector<int> r;
    if (roots)
      r = *roots;
    else
      for (size_t i = 0; i < nodes.size(); ++i) r.push_back(int(i));
    std::vector<std::string> rs;
    for (int i : r) rs.push_back(std::to_string(i));
    std::string j = "{\"asset\":{\"version\":\"2.0\"}," + top +
                    (scenes ? "\"scene\":0,\"scenes\":[{\"nodes\":[" + join(rs) + "]}]," : "") +
                    "\"extras\":{}";
    auto section = [&](const char* key, const std::vector<std::string>& items) {
      if (!items.empty()) j += std::string(",\"") + key + "\":[" + join(items) + "]";
    };
    section("nodes", nodes);
    section("meshes", meshes);
    section("materials", materials);
    section("cameras", cameras);
    section("accessors", accessors);
    section("bufferViews", views);
    if (!bin.empty()) {
      std::string uri =
          buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(bin) : buffer_uri;
      j += ",\"buffers\":[{\"byteLength\":" + std::to_string(bin.size()) +
           (glb ? std::string() : ",\"uri\":\"" + uri + "\"") + "}]";
    }
    if (!lights.empty())
      j += ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[" + join(lights) + "]}}";
    return j + "}";
  }

  std::vector<unsigned char> glb() const {
    std::string j = json(true);
    while (j.size() % 4) j += ' ';
    std::vector<unsigned char> b = bin;
    while (b.size() % 4) b.push_back(0);
    std::vector<unsigned char> out = {'g', 'l', 'T', 'F'};
    auto u32 = [&](uint32_t v) {
      for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
    };
    u32(2);
    u32(uint32_t(12 + 8 + j.size() + 8 + b.size()));
    u32(uint32_t(j.size()));
    u32(0x4E4F534Au);
    out.insert(out.end(), j.begin(), j.end());
    u32(uint32_t(b.size()));
    u32(0x004E4942u);
    out.insert(out.end(), b.begin(), b.end());
    return out;
  }
};

// One triangle in z = 0 facing +z (grey Lambertian), a camera at z = 5 and a point light.
Gltf basic() {
  Gltf g;
  const int pos = g.vec3s({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int nor = g.vec3s({0, 0, 1, 0, 0, 1, 0, 0, 1});
  const int ind = g.indices({0, 1, 2});
  const int mat = g.material(
      "\"name\":\"grey\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.6,0.7,1],"
      "\"metallicFactor\":0}");
  g.mesh("tri", pos, ind, mat, ",\"NORMAL\":" + std::to_string(nor));
  g.node("\"name\":\"geometry\",\"mesh\":0");
  g.camera(0.7, ",\"aspectRatio\":1.5");
  g.node("\"name\":\"eye\",\"camera\":0,\"translation\":[0,0,5]");
  g.light("\"name\":\"bulb\",\"type\":\"point\",\"color\":[1,0.5,0.25],\"intensity\":8");
  g.node(
      "\"name\":\"lamp\",\"translation\":[0,2,0],\"extensions\":{\"KHR_lights_punctual\":{"
      "\"light\":0}}");
  return g;
}

class LoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = fs::temp_directory_path() /
           ("photonbound_loader_" + name + "_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) {
    return write(name, std::vector<unsigned char>(text.begin(), text.end()));
  }
  std::string write(const std::string& name, const std::vector<unsigned char>& bytes) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return p.string();
  }
  Scene load(const Gltf& g) { return load_gltf(write("scene.gltf", g.json())); }
  // Loading must throw SceneError with one line "<path>: ...phrase...".
  void expect_error(const std::string& path, const std::string& phrase) {
    try {
      load_gltf(path);
      ADD_FAILURE() << "expected SceneError containing \"" << phrase << "\"";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
      EXPECT_NE(m.find(phrase), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
  void expect_error(const Gltf& g, const std::string& phrase) {
    expect_error(write("scene.gltf", g.json()), phrase);
  }
  fs::path dir_;
};

bool has_warning(const Scene& s, const std::string& phrase) {
  for (const std::string& w : s.warnings)
    if (w.find(phrase) != std::string::npos) return true;
  return false;
}

void expect_vec(const vec3& a, const vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

vec3 face_normal(const pb::Mesh& m, size_t t) {
  const vec3 p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]],
             p2 = m.positions[m.indices[3 * t + 2]];
  return glm::normalize(glm::cross(p1 - p0, p2 - p0));
}

TEST_F(LoaderTest, LoadsMinimalScene) {
  Gltf g = basic();
  g.nodes[0] = "{\"mesh\":0,\"translation\":[1,2,3]}";
  const std::string path = write("scene.gltf", g.json());
  const Scene s = load_gltf(path);
  EXPECT_EQ(s.source, path);
  ASSERT_EQ(s.meshes.size(), 1u);
  const pb::Mesh& m = s.meshes[0];
  EXPECT_EQ(m.name, "tri");
  ASSERT_EQ(m.positions.size(), 3u);
  expect_vec(m.positions[0], vec3(1, 2, 3));
  expect_vec(m.positions[1], vec3(2, 2, 3));
  expect_vec(m.positions[2], vec3(1, 3, 3));
  ASSERT_EQ(m.normals.size(), 3u);
  expect_vec(m.normals[1], vec3(0, 0, 1));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[m.material].name, "grey");
  EXPECT_EQ(s.materials[m.material].metallic, 0.0f);
  EXPECT_EQ(s.materials[m.material].roughness, 1.0f);  // glTF's default
  expect_vec(s.materials[m.material].base_color, vec3(0.5f, 0.6f, 0.7f));
  EXPECT_FALSE(s.materials[m.material].emits());
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].name, "bulb");
  EXPECT_EQ(s.lights[0].kind, pb::PunctualKind::Point);
  expect_vec(s.lights[0].position, vec3(0, 2, 0));
  expect_vec(s.lights[0].intensity, vec3(8, 4, 2));
  ASSERT_EQ(s.cameras.size(), 1u);
  const pb::Camera& c = s.cameras[0];
  expect_vec(c.position, vec3(0, 0, 5));
  expect_vec(c.forward, vec3(0, 0, -1));
  expect_vec(c.up, vec3(0, 1, 0));
  expect_vec(c.right, vec3(1, 0, 0));
  EXPECT_NEAR(c.yfov, 0.7f, 1e-6f);
  ASSERT_TRUE(c.aspect.has_value());
  EXPECT_NEAR(*c.aspect, 1.5f, 1e-6f);
  expect_vec(s.bounds.lo, vec3(1, 2, 3));
  expect_vec(s.bounds.hi, vec3(2, 3, 3));
  EXPECT_EQ(s.degenerate_triangles, 0u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

TEST_F(LoaderTest, LoadsBinaryGlb) {
  const Scene s = load_gltf(write("scene.glb", basic().glb()));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_EQ(s.cameras.size(), 1u);
  EXPECT_EQ(s.lights.size(), 1u);
}

TEST_F(LoaderTest, LoadsExternalBuffer) {
  Gltf g = basic();
  g.buffer_uri = "data.bin";
  write("data.bin", g.bin);
  EXPECT_EQ(load(g).triangle_count(), 1u);
}

TEST_F(LoaderTest, MaterialsKeepGltfParametersAndDefaults) {
  Gltf g = basic();
  const std::vector<std::string> bodies = {
      // 0: no pbrMetallicRoughness: glTF's defaults, a rough white metal
      "\"name\":\"plain\"",
      // 1: every extension photonbound reads
      "\"name\":\"all\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.9,0.8,0.7,0.5],"
      "\"metallicFactor\":0.25,\"roughnessFactor\":0.5},\"emissiveFactor\":[1,0.5,0],"
      "\"doubleSided\":true,\"alphaMode\":\"MASK\",\"alphaCutoff\":0.3,\"extensions\":{"
      "\"KHR_materials_ior\":{\"ior\":1.33},\"KHR_materials_emissive_strength\":{"
      "\"emissiveStrength\":4},\"KHR_materials_specular\":{\"specularFactor\":0.5,"
      "\"specularColorFactor\":[1,2,0.5]},\"KHR_materials_transmission\":{"
      "\"transmissionFactor\":0.75},\"KHR_materials_volume\":{\"thicknessFactor\":0.1,"
      "\"attenuationDistance\":2,\"attenuationColor\":[0.5,1,0.25]}}",
      // 2: transmission without a volume: thin-walled
      "\"name\":\"thin\",\"pbrMetallicRoughness\":{\"roughnessFactor\":0},\"extensions\":{"
      "\"KHR_materials_transmission\":{\"transmissionFactor\":1}}",
      // 3: a volume with thickness 0 is thin-walled too
      "\"name\":\"zero\",\"pbrMetallicRoughness\":{\"roughnessFactor\":0},\"extensions\":{"
      "\"KHR_materials_transmission\":{\"transmissionFactor\":1},\"KHR_materials_volume\":{}}",
      // 4: BLEND is rendered opaque
      "\"name\":\"blend\",\"alphaMode\":\"BLEND\""};
  for (const std::string& body : bodies) {
    const int mat = g.material(body);
    const int mesh = g.mesh("m" + std::to_string(mat), 0, 2, mat);
    g.node("\"mesh\":" + std::to_string(mesh));
  }
  g.node("\"mesh\":" + std::to_string(g.mesh("nomat", 0, 2)));
  const Scene s = load(g);
  ASSERT_EQ(s.meshes.size(), 7u);
  auto mat = [&](size_t mesh) { return s.materials[s.meshes[mesh].material]; };
  const pb::Material plain = mat(1);
  EXPECT_EQ(plain.metallic, 1.0f);
  EXPECT_EQ(plain.roughness, 1.0f);
  expect_vec(plain.base_color, vec3(1.0f));
  EXPECT_EQ(plain.specular, 1.0f);
  EXPECT_TRUE(plain.thin);
  EXPECT_FALSE(plain.double_sided);
  EXPECT_FALSE(plain.masked());
  const pb::Material all = mat(2);
  expect_vec(all.base_color, vec3(0.9f, 0.8f, 0.7f));
  EXPECT_NEAR(all.alpha, 0.5f, 1e-7f);
  EXPECT_NEAR(all.metallic, 0.25f, 1e-7f);
  EXPECT_NEAR(all.roughness, 0.5f, 1e-7f);
  EXPECT_NEAR(all.ior, 1.33f, 1e-6f);
  EXPECT_NEAR(all.specular, 0.5f, 1e-7f);
  expect_vec(all.specular_color, vec3(1, 2, 0.5f));
  EXPECT_NEAR(all.transmission, 0.75f, 1e-7f);
  EXPECT_FALSE(all.thin);
  // sigma = -ln(color) / distance per channel.
  expect_vec(all.attenuation, vec3(std::log(2.0f) / 2, 0.0f, std::log(4.0f) / 2));
  expect_vec(all.emission, vec3(4, 2, 0));
  EXPECT_TRUE(all.double_sided);
  EXPECT_TRUE(all.masked());
  EXPECT_NEAR(all.alpha_cutoff, 0.3f, 1e-7f);
  EXPECT_TRUE(has_warning(s, "material 'all': KHR_materials_specular does not change a volume"));
  EXPECT_TRUE(mat(3).thin);
  EXPECT_FALSE(has_warning(s, "material 'thin'"));
  EXPECT_TRUE(mat(4).thin);
  EXPECT_EQ(mat(5).alpha_mode, pb::AlphaMode::Blend);
  EXPECT_TRUE(has_warning(s, "material 'blend': alphaMode BLEND is rendered opaque"));
  EXPECT_EQ(mat(6).name, "default");
  EXPECT_EQ(mat(6).metallic, 0.0f);
  EXPECT_EQ(mat(6).specular, 0.0f);  // Lambertian
  expect_vec(mat(6).base_color, vec3(0.8f));
  EXPECT_TRUE(has_warning(s, "default"));
}

TEST_F(LoaderTest, MaterialFactorsOutOfRangeAreRefused) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"\"pbrMetallicRoughness\":{\"metallicFactor\":1.5}", "metallicFactor 1.5"},
      {"\"pbrMetallicRoughness\":{\"roughnessFactor\":-0.1}", "roughnessFactor -0.1"},
      {"\"extensions\":{\"KHR_materials_ior\":{\"ior\":0.5}}", "ior 0.5"},
      {"\"extensions\":{\"KHR_materials_specular\":{\"specularFactor\":2}}", "specularFactor 2"},
      {"\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":-1}}",
       "transmissionFactor -1"},
      {"\"extensions\":{\"KHR_materials_volume\":{\"attenuationDistance\":0}}",
       "attenuationDistance 0"},
      {"\"extensions\":{\"KHR_materials_volume\":{\"attenuationColor\":[2,0,0]}}",
       "attenuationColor must be 3 numbers in [0, 1]"},
      {"\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1.5}}",
       "clearcoatFactor 1.5"},
      {"\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatRoughnessFactor\":-1}}",
       "clearcoatRoughnessFactor -1"},
      {"\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorFactor\":[2,0,0]}}",
       "sheenColorFactor must be 3 numbers in [0, 1]"},
      {"\"extensions\":{\"KHR_materials_sheen\":{\"sheenRoughnessFactor\":1.5}}",
       "sheenRoughnessFactor 1.5"},
      {"\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":1.25}}",
       "anisotropyStrength 1.25"},
      {"\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyRotation\":\"up\"}}",
       "anisotropyRotation is not a number"},
      {"\"extensions\":{\"KHR_materials_iridescence\":{\"iridescenceFactor\":-0.5}}",
       "iridescenceFactor -0.5"},
      {"\"extensions\":{\"KHR_materials_iridescence\":{\"iridescenceIor\":0.8}}",
       "iridescenceIor 0.8 must be finite and at least 1"},
      {"\"extensions\":{\"KHR_materials_iridescence\":{\"iridescenceThicknessMaximum\":-1}}",
       "iridescenceThicknessMaximum -1 must be finite and at least 0"},
      {"\"extensions\":{\"KHR_materials_diffuse_transmission\":{"
       "\"diffuseTransmissionFactor\":1.5}}",
       "diffuseTransmissionFactor 1.5"},
      {"\"extensions\":{\"KHR_materials_dispersion\":{\"dispersion\":-0.1}}",
       "dispersion -0.1 must be finite and at least 0"},
      {"\"alphaMode\":\"SOMETIMES\"", "unknown alphaMode 'SOMETIMES'"},
      {"\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":3}}",
       "texture 3, which does not"},
  };
  for (const auto& [body, phrase] : cases) {
    Gltf g = basic();
    g.materials[0] = "{\"name\":\"bad\"," + body + "}";
    expect_error(g, "material 'bad'");
    expect_error(g, phrase);
  }
}

// The bytes of an 8-bit RGB PNG of w x h texels (texel k has R = 40 k mod 256, G = 255 - k,
// B = 7), written by image_io.h.
std::vector<unsigned char> png_bytes(int w, int h, const fs::path& dir, int seed = 0) {
  std::vector<unsigned char> rgb;
  for (int k = 0; k < w * h; ++k)
    rgb.insert(rgb.end(), {uint8_t(40 * k + seed), uint8_t(255 - k), 7});
  const fs::path p = dir / ("tmp_" + std::to_string(seed) + ".png");
  pb::write_png(p.string(), w, h, rgb);
  std::ifstream f(p, std::ios::binary);
  std::vector<unsigned char> out{std::istreambuf_iterator<char>(f), {}};
  fs::remove(p);
  return out;
}

// basic() with TEXCOORD_0 and _1 on its triangle and `material` as its material.
Gltf textured(const std::string& images, const std::string& material) {
  Gltf g = basic();
  const int uv0 = g.accessor(g.view(std::vector<float>{0, 0, 1, 0, 0, 1}), 5126, 3, "VEC2");
  const int uv1 =
      g.accessor(g.view(std::vector<float>{0.5f, 0.5f, 1, 0.5f, 0.5f, 1}), 5126, 3, "VEC2");
  g.meshes[0] =
      "{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,"
      "\"TEXCOORD_0\":" +
      std::to_string(uv0) + ",\"TEXCOORD_1\":" + std::to_string(uv1) +
      "},\"indices\":2,\"material\":0}]}";
  g.materials[0] = "{\"name\":\"tex\"," + material + "}";
  g.top = images;
  return g;
}

TEST_F(LoaderTest, TexturesAreDecodedWithSamplersAndTransforms) {
  // One embedded PNG (a data URI) used by four textures: decoded once. Sampler 0 clamps S,
  // mirrors T and filters NEAREST; KHR_texture_transform sets the matrix and texCoord.
  const std::vector<unsigned char> png = png_bytes(3, 2, dir_);
  const std::string images =
      "\"images\":[{\"uri\":\"data:image/png;base64," + base64(png) +
      "\"}],\"samplers\":[{\"magFilter\":9728,\"wrapS\":33071,\"wrapT\":33648}],"
      "\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":0}],";
  const std::string xf =
      "\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.5,0.25],\"rotation\":0.3,"
      "\"scale\":[2,4],\"texCoord\":1}}";
  const Scene s = load(textured(
      images,
      "\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0," + xf +
          "},"
          "\"metallicRoughnessTexture\":{\"index\":1}},\"normalTexture\":{\"index\":1,\"scale\":0."
          "5},"
          "\"emissiveFactor\":[1,1,1],\"emissiveTexture\":{\"index\":1,\"texCoord\":1},"
          "\"extensions\":{\"KHR_materials_specular\":{\"specularColorTexture\":{\"index\":0}}}"));
  ASSERT_EQ(s.images.size(), 1u);
  EXPECT_EQ(s.images[0].width, 3);
  EXPECT_EQ(s.images[0].height, 2);
  EXPECT_EQ(s.images[0].u8[3], 40);  // texel 1, R
  const pb::Material& m = s.materials[s.meshes[0].material];
  const pb::TextureRef& b = m.base_color_texture;
  EXPECT_EQ(b.image, 0);
  EXPECT_EQ(b.wrap_s, pb::Wrap::ClampToEdge);
  EXPECT_EQ(b.wrap_t, pb::Wrap::MirroredRepeat);
  EXPECT_TRUE(b.nearest);
  EXPECT_EQ(b.texcoord, 1);
  const float c = std::cos(0.3f), sn = std::sin(0.3f);
  const float want[6] = {2 * c, 4 * sn, 0.5f, -2 * sn, 4 * c, 0.25f};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(b.m[k], want[k], 1e-6f) << k;
  EXPECT_EQ(m.metallic_roughness_texture.wrap_s, pb::Wrap::Repeat);  // no sampler: REPEAT
  EXPECT_FALSE(m.metallic_roughness_texture.nearest);
  EXPECT_EQ(m.emissive_texture.texcoord, 1);
  EXPECT_NEAR(m.normal_scale, 0.5f, 1e-7f);
  EXPECT_TRUE(m.specular_color_texture.present());
  EXPECT_FALSE(m.transmission_texture.present());
  // A normal texture and no TANGENT: tangents are made from TEXCOORD_0 (u along +x here).
  ASSERT_EQ(s.meshes[0].tangents.size(), 3u);
  for (const glm::vec4& t : s.meshes[0].tangents) {
    EXPECT_NEAR(t.x, 1.0f, 1e-5f);
    EXPECT_EQ(std::fabs(t.w), 1.0f);
  }
  ASSERT_EQ(s.meshes[0].texcoords[1].size(), 3u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST_F(LoaderTest, ClearcoatIsReadWithItsTexturesAndTangents) {
  // KHR_materials_clearcoat: the factors, clearcoatTexture (R), clearcoatRoughnessTexture (G)
  // and clearcoatNormalTexture with its scale; tangents for the coat's normal texture alone;
  // not warned about as an ignored extension. clearcoatFactor 0 disables the whole layer.
  const std::vector<unsigned char> png = png_bytes(2, 2, dir_);
  const std::string images =
      "\"extensionsUsed\":[\"KHR_materials_clearcoat\"],"
      "\"images\":[{\"uri\":\"data:image/png;base64," +
      base64(png) + "\"}],\"textures\":[{\"source\":0}],";
  const std::string coat =
      "\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatFactor\":0.75,"
      "\"clearcoatRoughnessFactor\":0.25,\"clearcoatTexture\":{\"index\":0},"
      "\"clearcoatRoughnessTexture\":{\"index\":0,\"texCoord\":1},"
      "\"clearcoatNormalTexture\":{\"index\":0,\"scale\":0.5}}}";
  const Scene s = load(textured(images, coat));
  const pb::Material& m = s.materials[s.meshes[0].material];
  EXPECT_NEAR(m.clearcoat, 0.75f, 1e-7f);
  EXPECT_NEAR(m.clearcoat_roughness, 0.25f, 1e-7f);
  EXPECT_TRUE(m.clearcoat_texture.present());
  EXPECT_EQ(m.clearcoat_roughness_texture.texcoord, 1);
  EXPECT_TRUE(m.clearcoat_normal_texture.present());
  EXPECT_NEAR(m.clearcoat_normal_scale, 0.5f, 1e-7f);
  EXPECT_EQ(s.meshes[0].tangents.size(), 3u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Scene off = load(textured(images, std::string(coat).replace(coat.find("0.75"), 4, "0")));
  const pb::Material& o = off.materials[off.meshes[0].material];
  EXPECT_EQ(o.clearcoat, 0.0f);
  EXPECT_FALSE(o.clearcoat_texture.present() || o.clearcoat_normal_texture.present());
  EXPECT_TRUE(off.meshes[0].tangents.empty());
}

TEST_F(LoaderTest, AnisotropyIsReadWithItsTextureAndMakesTangents) {
  // KHR_materials_anisotropy: anisotropyStrength, anisotropyRotation (kept in (-pi, pi]) and
  // anisotropyTexture; tangents are made from the texture's coordinates without a TANGENT or a
  // normal texture (the direction needs them); not warned about. Strength 0 disables it, and
  // then no tangents are made; without texture coordinates or TANGENT it warns "isotropic".
  const std::vector<unsigned char> png = png_bytes(2, 2, dir_);
  const std::string images =
      "\"extensionsUsed\":[\"KHR_materials_anisotropy\"],"
      "\"images\":[{\"uri\":\"data:image/png;base64," +
      base64(png) + "\"}],\"textures\":[{\"source\":0}],";
  const std::string aniso =
      "\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":0.6,"
      "\"anisotropyRotation\":7.0,\"anisotropyTexture\":{\"index\":0,\"texCoord\":1}}}";
  const Scene s = load(textured(images, aniso));
  const pb::Material& m = s.materials[s.meshes[0].material];
  EXPECT_NEAR(m.anisotropy, 0.6f, 1e-7f);
  EXPECT_NEAR(m.anisotropy_rotation, 7.0 - 2.0 * M_PI, 1e-6);
  EXPECT_TRUE(m.anisotropy_texture.present());
  EXPECT_EQ(m.anisotropy_texture.texcoord, 1);
  ASSERT_EQ(s.meshes[0].tangents.size(), 3u);
  for (const glm::vec4& t : s.meshes[0].tangents) EXPECT_NEAR(t.x, 1.0f, 1e-5f);  // u along +x
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Scene off = load(textured(images, std::string(aniso).replace(aniso.find("0.6"), 3, "0")));
  const pb::Material& o = off.materials[off.meshes[0].material];
  EXPECT_EQ(o.anisotropy, 0.0f);
  EXPECT_FALSE(o.anisotropy_texture.present());
  EXPECT_TRUE(off.meshes[0].tangents.empty());
  Gltf bare = basic();  // no texture coordinates, no TANGENT
  bare.materials[0] =
      "{\"name\":\"brushed\",\"extensions\":{\"KHR_materials_anisotropy\":{"
      "\"anisotropyStrength\":1}}}";
  const Scene b = load(bare);
  EXPECT_TRUE(b.meshes[0].tangents.empty());
  EXPECT_TRUE(has_warning(b, "anisotropy without TANGENT or texture coordinates")) << b.warnings[0];
}

TEST_F(LoaderTest, IridescenceIsReadWithItsTextures) {
  // KHR_materials_iridescence: the factor, the film's index, the thickness range (the minimum
  // may exceed the maximum) and both textures; iridescenceFactor 0 disables it, textures too.
  const std::vector<unsigned char> png = png_bytes(2, 2, dir_);
  const std::string images =
      "\"extensionsUsed\":[\"KHR_materials_iridescence\"],"
      "\"images\":[{\"uri\":\"data:image/png;base64," +
      base64(png) + "\"}],\"textures\":[{\"source\":0}],";
  const std::string film =
      "\"extensions\":{\"KHR_materials_iridescence\":{\"iridescenceFactor\":0.7,"
      "\"iridescenceIor\":1.8,\"iridescenceThicknessMinimum\":500,"
      "\"iridescenceThicknessMaximum\":200,\"iridescenceTexture\":{\"index\":0},"
      "\"iridescenceThicknessTexture\":{\"index\":0,\"texCoord\":1}}}";
  const Scene s = load(textured(images, film));
  const pb::Material& m = s.materials[s.meshes[0].material];
  EXPECT_NEAR(m.iridescence, 0.7f, 1e-7f);
  EXPECT_NEAR(m.iridescence_ior, 1.8f, 1e-7f);
  EXPECT_EQ(m.iridescence_thickness_minimum, 500.0f);
  EXPECT_EQ(m.iridescence_thickness_maximum, 200.0f);
  EXPECT_TRUE(m.iridescence_texture.present());
  EXPECT_EQ(m.iridescence_thickness_texture.texcoord, 1);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Scene off = load(textured(images, std::string(film).replace(film.find("0.7"), 3, "0")));
  const pb::Material& o = off.materials[off.meshes[0].material];
  EXPECT_EQ(o.iridescence, 0.0f);
  EXPECT_FALSE(o.iridescence_texture.present() || o.iridescence_thickness_texture.present());
}

TEST_F(LoaderTest, DispersionIsReadAndIgnoredOnThinWalls) {
  // KHR_materials_dispersion: the value as given (20 / Abbe number, any value >= 0) on a
  // volume; on a thin wall, which does not refract, it is kept but warned to have no effect.
  Gltf g = basic();
  g.top = "\"extensionsUsed\":[\"KHR_materials_dispersion\"],";
  const std::string volume =
      "{\"name\":\"prism\",\"pbrMetallicRoughness\":{\"metallicFactor\":0,"
      "\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{"
      "\"transmissionFactor\":1},\"KHR_materials_volume\":{\"thicknessFactor\":1},"
      "\"KHR_materials_dispersion\":{\"dispersion\":2.5}}}";
  g.materials[0] = volume;
  const Scene s = load(g);
  const pb::Material& m = s.materials[s.meshes[0].material];
  EXPECT_EQ(m.dispersion, 2.5f);
  EXPECT_FALSE(m.thin);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  g.materials[0] = std::string(volume).replace(volume.find("\"thicknessFactor\":1"), 19,
                                               "\"thicknessFactor\":0");
  const Scene thin = load(g);
  EXPECT_TRUE(thin.materials[thin.meshes[0].material].thin);
  EXPECT_TRUE(has_warning(thin, "material 'prism': dispersion without KHR_materials_volume"));
}

TEST_F(LoaderTest, DiffuseTransmissionIsReadWithItsTextures) {
  // KHR_materials_diffuse_transmission: the factor and colour, the A texture and the sRGB colour
  // texture; a factor of 0 is none, textures too.
  const std::vector<unsigned char> png = png_bytes(2, 2, dir_);
  const std::string images =
      "\"extensionsUsed\":[\"KHR_materials_diffuse_transmission\"],"
      "\"images\":[{\"uri\":\"data:image/png;base64," +
      base64(png) + "\"}],\"textures\":[{\"source\":0}],";
  const std::string dt =
      "\"extensions\":{\"KHR_materials_diffuse_transmission\":{"
      "\"diffuseTransmissionFactor\":0.25,\"diffuseTransmissionColorFactor\":[1,0.5,0.25],"
      "\"diffuseTransmissionTexture\":{\"index\":0},"
      "\"diffuseTransmissionColorTexture\":{\"index\":0,\"texCoord\":1}}}";
  const Scene s = load(textured(images, dt));
  const pb::Material& m = s.materials[s.meshes[0].material];
  EXPECT_EQ(m.diffuse_transmission, 0.25f);
  expect_vec(m.diffuse_transmission_color, vec3(1, 0.5f, 0.25f));
  EXPECT_TRUE(m.diffuse_transmission_texture.present());
  EXPECT_EQ(m.diffuse_transmission_color_texture.texcoord, 1);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Scene off = load(textured(images, std::string(dt).replace(dt.find("0.25"), 4, "0")));
  const pb::Material& o = off.materials[off.meshes[0].material];
  EXPECT_EQ(o.diffuse_transmission, 0.0f);
  EXPECT_FALSE(o.diffuse_transmission_texture.present() ||
               o.diffuse_transmission_color_texture.present());
}

TEST_F(LoaderTest, SheenIsReadWithItsTextures) {
  // KHR_materials_sheen: sheenColorFactor, sheenRoughnessFactor, sheenColorTexture (sRGB) and
  // sheenRoughnessTexture (A); a black sheenColorFactor disables the layer, textures and all.
  const std::vector<unsigned char> png = png_bytes(2, 2, dir_);
  const std::string images =
      "\"extensionsUsed\":[\"KHR_materials_sheen\"],"
      "\"images\":[{\"uri\":\"data:image/png;base64," +
      base64(png) + "\"}],\"textures\":[{\"source\":0}],";
  const std::string sheen =
      "\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.9,0.5,0.25],"
      "\"sheenRoughnessFactor\":0.75,\"sheenColorTexture\":{\"index\":0},"
      "\"sheenRoughnessTexture\":{\"index\":0,\"texCoord\":1}}}";
  const Scene s = load(textured(images, sheen));
  const pb::Material& m = s.materials[s.meshes[0].material];
  expect_vec(m.sheen_color, vec3(0.9f, 0.5f, 0.25f));
  EXPECT_NEAR(m.sheen_roughness, 0.75f, 1e-7f);
  EXPECT_TRUE(m.sheen_color_texture.present());
  EXPECT_EQ(m.sheen_roughness_texture.texcoord, 1);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Scene off = load(
      textured(images, std::string(sheen).replace(sheen.find("[0.9,0.5,0.25]"), 14, "[0,0,0]")));
  const pb::Material& o = off.materials[off.meshes[0].material];
  EXPECT_EQ(o.sheen_color, vec3(0.0f));
  EXPECT_FALSE(o.sheen_color_texture.present() || o.sheen_roughness_texture.present());
}

TEST_F(LoaderTest, ImagesInBufferViewsAndTheirErrors) {
  // A GLB's image in a bufferView is read from the buffer (its range checked); a bufferView
  // past the buffer, undecodable bytes, a missing file and an absent image are refused, naming
  // the image.
  Gltf g = textured("", "\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}");
  const std::vector<unsigned char> png = png_bytes(2, 2, dir_);
  const int view = g.view(png);
  g.top = "\"images\":[{\"bufferView\":" + std::to_string(view) +
          ",\"mimeType\":\"image/png\"}],\"textures\":[{\"source\":0}],";
  const Scene s = load_gltf(write("scene.glb", g.glb()));
  ASSERT_EQ(s.images.size(), 1u);
  EXPECT_EQ(s.images[0].width, 2);
  g.views[size_t(view)] = "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":999999}";
  expect_error(write("long.glb", g.glb()), "image 0");
  Gltf junk = textured(
      "\"images\":[{\"uri\":\"data:image/png;base64,AAAAAAAA\"}],"
      "\"textures\":[{\"source\":0}],",
      "\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}");
  expect_error(junk, "image 0: cannot decode the image");  // named once, not "image 0: image 0"
  Gltf missing = textured("\"images\":[{\"uri\":\"nowhere.png\"}],\"textures\":[{\"source\":0}],",
                          "\"emissiveTexture\":{\"index\":0}");
  expect_error(missing, "image 'nowhere.png' has no data");
  Gltf absent = textured("\"textures\":[{\"source\":4}],", "\"emissiveTexture\":{\"index\":0}");
  expect_error(absent, "image 4, which does not exist");
  // Unused images are never decoded: junk nobody uses loads.
  Gltf unused = textured("\"images\":[{\"uri\":\"data:image/png;base64,AAAAAAAA\"}],",
                         "\"doubleSided\":false");
  EXPECT_TRUE(load(unused).images.empty());
}

TEST_F(LoaderTest, ExternalImagesArePartOfTheSceneIdentity) {
  // Editing an external texture changes Scene::content_hash (resume refuses the old state).
  write("wood.png", png_bytes(2, 2, dir_, 0));
  const Gltf g = textured("\"images\":[{\"uri\":\"wood.png\"}],\"textures\":[{\"source\":0}],",
                          "\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}");
  const uint64_t before = load(g).content_hash;
  EXPECT_EQ(load(g).content_hash, before);
  write("wood.png", png_bytes(2, 2, dir_, 1));
  EXPECT_NE(load(g).content_hash, before);
}

TEST_F(LoaderTest, FileTangentsAreTransformedAndTexturesWithoutImagesWarn) {
  // TANGENT through a mirroring node transform: xyz by the linear part, w flipped.
  Gltf g =
      textured("\"images\":[{\"uri\":\"data:image/png;base64," + base64(png_bytes(1, 1, dir_)) +
                   "\"}],\"textures\":[{\"source\":0},{\"extensions\":{"
                   "\"KHR_texture_basisu\":{\"source\":0}}}],",
               "\"normalTexture\":{\"index\":0},\"emissiveFactor\":[1,1,1],"
               "\"emissiveTexture\":{\"index\":1}");
  const int tan =
      g.accessor(g.view(std::vector<float>{0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, -1}), 5126, 3, "VEC4");
  g.meshes[0].insert(g.meshes[0].find("\"NORMAL\""), "\"TANGENT\":" + std::to_string(tan) + ",");
  g.nodes[0] = "{\"mesh\":0,\"scale\":[-1,2,1]}";
  const Scene s = load(g);
  ASSERT_EQ(s.meshes[0].tangents.size(), 3u);
  expect_vec(vec3(s.meshes[0].tangents[0]), vec3(0, 1, 0));  // (0, 1, 0) scaled by 2, unit
  EXPECT_EQ(s.meshes[0].tangents[0].w, -1.0f);
  EXPECT_EQ(s.meshes[0].tangents[2].w, 1.0f);
  EXPECT_TRUE(has_warning(s, "has no image photonbound can decode"));
  EXPECT_FALSE(s.materials[0].emissive_texture.present());
}

TEST_F(LoaderTest, KtxTwoImagesAsPlainSourcesFallBackToTheirFactorsWithOneWarning) {
  // glTF-Sample-Assets' KTX2 variants point texture.source at a KTX2 image without requiring
  // KHR_texture_basisu: that is the factor alone, warned once for the image however many
  // textures use it, as a basisu-only texture is (above), not a refusal.
  std::vector<unsigned char> ktx2 = {0xab, 'K',  'T',  'X',  ' ',  '2',
                                     '0',  0xbb, '\r', '\n', 0x1a, '\n'};
  ktx2.resize(64, 0);
  write("lamp.ktx2", ktx2);
  const Gltf g =
      textured("\"images\":[{\"uri\":\"lamp.ktx2\"}],\"textures\":[{\"source\":0},{\"source\":0}],",
               "\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,1,1],"
               "\"baseColorTexture\":{\"index\":0}},\"emissiveFactor\":[1,1,1],"
               "\"emissiveTexture\":{\"index\":1}");
  const Scene s = load(g);
  EXPECT_TRUE(s.images.empty());
  EXPECT_FALSE(s.materials[0].base_color_texture.present());
  EXPECT_FALSE(s.materials[0].emissive_texture.present());
  expect_vec(s.materials[0].base_color, vec3(0.5f, 0.25f, 1.0f));
  size_t warned = 0;
  for (const std::string& w : s.warnings) warned += w.find("is KTX2 (Basis Universal)") != w.npos;
  EXPECT_EQ(warned, 1u);
}

TEST_F(LoaderTest, HierarchyComposesTrsAndMatrix) {
  Gltf g = basic();
  g.nodes[0] = "{\"mesh\":0}";
  // parent: T(10,0,0) * R(90 deg about z) * S(2); child: matrix T(1,0,0) (column-major).
  const double h = std::sqrt(0.5);
  g.node("\"translation\":[10,0,0],\"rotation\":[0,0," + std::to_string(h) + "," +
         std::to_string(h) + "],\"scale\":[2,2,2],\"children\":[4]");
  g.node("\"matrix\":[1,0,0,0, 0,1,0,0, 0,0,1,0, 1,0,0,1],\"mesh\":0,\"children\":[5]");
  g.node("\"camera\":0");
  g.roots = std::vector<int>{1, 2, 3};
  const Scene s = load(g);
  ASSERT_EQ(s.meshes.size(), 1u);
  const pb::Mesh& m = s.meshes[0];
  // local (0,0,0) -> (1,0,0) -> (2,0,0) -> (0,2,0) -> (10,2,0); local (1,0,0) -> (10,4,0).
  expect_vec(m.positions[0], vec3(10, 2, 0), 1e-4f);
  expect_vec(m.positions[1], vec3(10, 4, 0), 1e-4f);
  expect_vec(m.positions[2], vec3(8, 2, 0), 1e-4f);
  expect_vec(m.normals[0], vec3(0, 0, 1));
  ASSERT_EQ(s.cameras.size(), 2u);
  const pb::Camera& c = s.cameras[1];  // node 5, under the rotated parent
  expect_vec(c.position, vec3(10, 2, 0), 1e-4f);
  expect_vec(c.forward, vec3(0, 0, -1));
  expect_vec(c.up, vec3(-1, 0, 0));
  expect_vec(c.right, vec3(0, 1, 0));
}

TEST_F(LoaderTest, NormalsUseTheInverseTranspose) {
  Gltf g = basic();
  // The plane x + y = 1 has normal (1,1,0)/sqrt2; scaling y by 2 makes it (1,0.5,0)/|.|.
  const int pos = g.vec3s({1, 0, 0, 0, 1, 0, 1, 0, 1});
  const float r = std::sqrt(0.5f);
  const int nor = g.vec3s({r, r, 0, r, r, 0, r, r, 0});
  g.meshes[0] =
      "{\"name\":\"slant\",\"primitives\":[{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
      ",\"NORMAL\":" + std::to_string(nor) + "}}]}";
  g.nodes[0] = "{\"mesh\":0,\"scale\":[1,2,1]}";
  const Scene s = load(g);
  expect_vec(s.meshes[0].positions[1], vec3(0, 2, 0));
  expect_vec(s.meshes[0].normals[2], glm::normalize(vec3(1, 0.5f, 0)));
}

TEST_F(LoaderTest, NegativeDeterminantFlipsWinding) {
  Gltf g = basic();
  g.nodes[0] = "{\"mesh\":0,\"scale\":[-1,1,1]}";
  const Scene s = load(g);
  const pb::Mesh& m = s.meshes[0];
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 2, 1}));
  expect_vec(m.positions[1], vec3(-1, 0, 0));
  expect_vec(face_normal(m, 0), vec3(0, 0, 1));  // the front side still faces +z
  expect_vec(m.normals[0], vec3(0, 0, 1));
}

TEST_F(LoaderTest, NonIndexedAndInterleavedAndIndexTypes) {
  Gltf g = basic();
  // Interleaved POSITION + NORMAL, byteStride 24, two triangles, non-indexed.
  const std::vector<float> data = {0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1,
                                   0, 0, 1, 0, 0, 1, 1, 0, 1, 0, 0, 1, 0, 1, 1, 0, 0, 1};
  const int v = g.view(data, ",\"byteStride\":24");
  const int pos = g.accessor(v, 5126, 6, "VEC3");
  const int nor = g.accessor(v, 5126, 6, "VEC3", ",\"byteOffset\":12");
  g.node("\"mesh\":" +
         std::to_string(g.mesh("flat", pos, -1, 0, ",\"NORMAL\":" + std::to_string(nor))));
  const int i8 = g.accessor(g.view(std::vector<uint8_t>{0, 1, 2}), 5121, 3, "SCALAR");
  g.node("\"mesh\":" + std::to_string(g.mesh("u8", 0, i8, 0)));
  const int i32 = g.accessor(g.view(std::vector<uint32_t>{2, 0, 1}), 5125, 3, "SCALAR");
  g.node("\"mesh\":" + std::to_string(g.mesh("u32", 0, i32, 0)));
  const Scene s = load(g);
  ASSERT_EQ(s.meshes.size(), 4u);
  EXPECT_EQ(s.meshes[1].indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
  expect_vec(s.meshes[1].positions[4], vec3(1, 0, 1));
  expect_vec(s.meshes[1].normals[4], vec3(0, 0, 1));
  EXPECT_EQ(s.meshes[2].indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(s.meshes[3].indices, (std::vector<uint32_t>{2, 0, 1}));
}

TEST_F(LoaderTest, SpotLightDirectionAndCones) {
  Gltf g = basic();
  g.lights[0] =
      "{\"type\":\"spot\",\"intensity\":3,\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.5}"
      "}";
  const double h = std::sqrt(0.5);  // 90 degrees about x: local -z becomes world +y
  g.nodes[2] = "{\"rotation\":[" + std::to_string(h) + ",0,0," + std::to_string(h) +
               "],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}";
  const Scene s = load(g);
  ASSERT_EQ(s.lights.size(), 1u);
  const pb::PunctualLight& l = s.lights[0];
  EXPECT_EQ(l.kind, pb::PunctualKind::Spot);
  EXPECT_EQ(l.name, "light 0");
  expect_vec(l.direction, vec3(0, 1, 0));
  expect_vec(l.intensity, vec3(3));
  EXPECT_NEAR(l.cos_inner, std::cos(0.2f), 1e-6f);
  EXPECT_NEAR(l.cos_outer, std::cos(0.5f), 1e-6f);
}

TEST_F(LoaderTest, EmissiveTrianglesAloneLightTheScene) {
  Gltf g = basic();
  g.materials[0] = "{\"emissiveFactor\":[1,1,1],\"pbrMetallicRoughness\":{\"metallicFactor\":0}}";
  g.roots = std::vector<int>{0, 1};
  const Scene s = load(g);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_TRUE(s.materials[s.meshes[0].material].emits());
}

// An exporter's "no emission": emissiveFactor 1 over an all-black emissive texture. The file then
// has no light and gets the default sky (it was refused: "the scene's lights emit no finite
// positive power", naming no file); one lit texel makes the material a light again.
TEST_F(LoaderTest, AnEmissiveFactorOverABlackTextureIsNoLight) {
  auto with_texel = [&](uint8_t value) {
    std::vector<unsigned char> rgb(12, 0);
    rgb[4] = value;  // the second texel's green
    pb::write_png((dir_ / "emit.png").string(), 2, 2, rgb);
    Gltf g = textured("\"images\":[{\"uri\":\"emit.png\"}],\"textures\":[{\"source\":0}],",
                      "\"emissiveFactor\":[1,1,1],\"emissiveTexture\":{\"index\":0}");
    g.roots = std::vector<int>{0, 1};  // no lamp
    return load(g);
  };
  Scene black = with_texel(0);
  EXPECT_TRUE(black.materials[black.meshes[0].material].emits());  // the factor is positive
  EXPECT_FALSE(pb::has_light(black));
  pb::RenderOptions o;
  const std::vector<std::string> notes = pb::complete_scene(black, o);
  ASSERT_TRUE(black.environment.has_value());
  EXPECT_EQ(black.environment->source, "the default sky");
  EXPECT_NO_THROW(pb::Lights{black});
  EXPECT_TRUE(pb::has_light(with_texel(200)));
}

// A GLB is known by its magic, whatever its name says: BOX.GLB, or a binary file named .gltf.
TEST_F(LoaderTest, AGlbIsKnownByItsMagicNotItsName) {
  for (const char* name : {"BOX.GLB", "binary.gltf", "model.bin"}) {
    const Scene s = load_gltf(write(name, basic().glb()));
    EXPECT_EQ(s.triangle_count(), 1u) << name;
  }
}

// glTF pads every GLB chunk to 4 bytes and tinygltf 2.7 refuses a BIN chunk that is not ("BIN
// Chunk end does not aligned"); FME 2018 wrote one. The loader pads it: the same triangle loads.
TEST_F(LoaderTest, AnUnpaddedBinChunkIsPadded) {
  Gltf g = basic();
  ASSERT_NE(g.bin.size() % 4, 0u);  // 3 uint16 indices end the buffer two bytes past a boundary
  std::vector<unsigned char> glb = g.glb();
  const uint32_t json = uint32_t(glb[12]) | uint32_t(glb[13]) << 8 | uint32_t(glb[14]) << 16 |
                        uint32_t(glb[15]) << 24;
  const size_t bin_at = 20 + json, unpadded = g.bin.size();
  glb.resize(bin_at + 8 + unpadded);
  for (int k = 0; k < 4; ++k) {
    glb[bin_at + size_t(k)] = uint8_t(unpadded >> (8 * k));
    glb[8 + size_t(k)] = uint8_t(glb.size() >> (8 * k));
  }
  const Scene s = load_gltf(write("unpadded.glb", glb));
  EXPECT_EQ(s.triangle_count(), 1u);
  expect_vec(s.meshes[0].positions[1], vec3(1, 0, 0));
}

// KHR_animation_pointer's channels target a JSON pointer, not a node; tinygltf 2.7 refused the
// whole file ("'node' property is missing"). Animations are ignored, with their warning.
TEST_F(LoaderTest, AnimationPointerChannelsDoNotRefuseTheFile) {
  Gltf g = basic();
  const int times =
      g.accessor(g.view(std::vector<float>{0, 1}), 5126, 2, "SCALAR", ",\"min\":[0],\"max\":[1]");
  const int values = g.accessor(g.view(std::vector<float>{0, 1}), 5126, 2, "SCALAR");
  g.top =
      "\"extensionsUsed\":[\"KHR_animation_pointer\"],\"animations\":[{\"samplers\":[{"
      "\"input\":" +
      std::to_string(times) + ",\"output\":" + std::to_string(values) +
      "}],\"channels\":[{\"sampler\":0,\"target\":{\"path\":\"pointer\",\"extensions\":{"
      "\"KHR_animation_pointer\":{\"pointer\":\"/materials/0/emissiveStrength\"}}}},"
      "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}],";
  const Scene s = load(g);
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "1 animation is ignored"));
}

// Geo-referenced content lies millions of units from the origin (3D Tiles in ECEF: 4e6 m) where a
// float's step is 0.25-0.5: a 0.1-unit triangle there collapses. The loader centres such a model
// in double precision (Scene::origin), cameras, lights and --look-from / --look-at with it.
TEST_F(LoaderTest, AModelFarFromTheOriginIsCentredBeforeItIsRoundedToFloat) {
  // basic() with a 0.1-unit triangle (and the min / max glTF requires of POSITION) under a parent
  // node translated by t.
  auto placed = [](const glm::dvec3& t) {
    Gltf g = basic();
    g.accessors[0] = "{\"bufferView\":" +
                     std::to_string(g.view(std::vector<float>{0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0})) +
                     ",\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
                     "\"min\":[0,0,0],\"max\":[0.1,0.1,0]}";
    char node[128];
    std::snprintf(node, sizeof node, "\"translation\":[%.3f,%.3f,%.3f],\"children\":[0,1,2]", t.x,
                  t.y, t.z);
    g.node(node);
    g.roots = std::vector<int>{3};
    return g;
  };
  const glm::dvec3 shift(4e6, 3e6, 3.5e6);
  const Scene s = load(placed(shift));
  ASSERT_EQ(s.triangle_count(), 1u);  // in float about 4e6 it would be degenerate
  EXPECT_EQ(s.degenerate_triangles, 0u);
  // The origin is the box centre, (0.05, 0.05, 0) + shift; stored = file - origin.
  EXPECT_LT(glm::length(s.origin - (shift + glm::dvec3(0.05, 0.05, 0))), 1e-6);
  const glm::dvec3 corner[3] = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 stored(s.meshes[0].positions[s.meshes[0].indices[size_t(k)]]);
    EXPECT_LT(glm::length(stored + s.origin - (shift + corner[k])), 1e-7) << k;
  }
  // The camera (0, 0, 5) and the lamp (0, 2, 0) under the same parent move with it.
  EXPECT_LT(
      glm::length(glm::dvec3(s.cameras[0].position) + s.origin - (shift + glm::dvec3(0, 0, 5))),
      1e-6);
  EXPECT_LT(
      glm::length(glm::dvec3(s.lights[0].position) + s.origin - (shift + glm::dvec3(0, 2, 0))),
      1e-6);
  // --look-from and --look-at are the file's coordinates.
  pb::RenderOptions o;
  o.look_from = std::array<double, 3>{shift.x, shift.y, shift.z + 3};
  o.look_at = std::array<double, 3>{shift.x + 0.05, shift.y + 0.05, shift.z};
  const pb::PinholeCamera cam = pb::choose_camera(s, o);
  EXPECT_LT(glm::length(glm::dvec3(cam.origin()) + s.origin - (shift + glm::dvec3(0, 0, 3))), 1e-6);
  expect_vec(cam.camera().forward, vec3(0.05f, 0.05f, -3.0f) / std::sqrt(9.005f), 1e-6f);
  // At 64 sizes from the origin or closer nothing moves: ordinary files keep their coordinates.
  EXPECT_EQ(load(placed(glm::dvec3(5, 2, 0))).origin, glm::dvec3(0.0));
}

TEST_F(LoaderTest, DegenerateTrianglesAreSkippedAndCounted) {
  Gltf g = basic();
  const int pos = g.vec3s({0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 1e-20f, 1e-20f, 0});
  // good, repeated index, collinear, area underflow
  const int ind = g.indices({0, 1, 2, 0, 0, 1, 0, 1, 3, 0, 4, 1});
  g.meshes[0] =
      "{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
      "},\"indices\":" + std::to_string(ind) + "}]}";
  const Scene s = load(g);
  EXPECT_EQ(s.degenerate_triangles, 3u);
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "3 degenerate triangles skipped"));
}

TEST_F(LoaderTest, OnlyDegenerateTrianglesMeansNoTriangles) {
  Gltf g = basic();
  const int ind = g.indices({0, 0, 1, 2, 2, 2});
  g.meshes[0] = "{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":" +
                std::to_string(ind) + "}]}";
  expect_error(g, ": no triangles");
}

TEST_F(LoaderTest, MissingFile) {
  expect_error((dir_ / "nope.gltf").string(), "cannot open (No such file or directory)");
}

TEST_F(LoaderTest, MalformedJson) {
  expect_error(write("bad.gltf", "{ this is not json ]"), "malformed glTF: ");
}

TEST_F(LoaderTest, TruncatedJson) {
  const std::string j = basic().json();
  expect_error(write("cut.gltf", j.substr(0, j.size() / 2)), "malformed glTF: ");
}

TEST_F(LoaderTest, WrongLengthBaseColorIsMalformed) {
  Gltf g = basic();
  g.materials[0] = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5]}}";
  expect_error(g, "malformed glTF: Array length of `baseColorFactor`");
}

TEST_F(LoaderTest, AccessorIndexOutOfRange) {
  Gltf g = basic();
  g.meshes[0] = "{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":99}}]}";
  expect_error(g, "mesh 'tri' primitive 0 POSITION refers to accessor 99, which does not exist");
}

TEST_F(LoaderTest, BufferViewOutOfRange) {
  Gltf g = basic();
  g.accessors[0] = "{\"bufferView\":42,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}";
  expect_error(g, "POSITION accessor 0 refers to bufferView 42, which does not exist");
}

TEST_F(LoaderTest, AccessorReadsPastTheBufferView) {
  Gltf g = basic();
  g.accessors[0] = "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}";
  expect_error(g, "mesh 'tri' primitive 0 POSITION accessor 0 reads past the end of bufferView 0");
}

TEST_F(LoaderTest, AccessorOffsetPastTheBufferView) {
  Gltf g = basic();
  g.accessors[0] =
      "{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}";
  expect_error(g, "reads past the end of bufferView 0");
}

TEST_F(LoaderTest, BufferViewPastTheBufferEnd) {
  Gltf g = basic();
  g.views[0] = "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":36}";
  expect_error(g, "extends past the end of buffer 0");
}

TEST_F(LoaderTest, IndexValueOutOfRange) {
  Gltf g = basic();
  g.node("\"mesh\":" + std::to_string(g.mesh("bad", 0, g.indices({0, 1, 7}), 0)));
  expect_error(g,
               "mesh 'bad' primitive 0 indices accessor 3: index 2 has value 7, out of range for 3 "
               "vertices");
}

TEST_F(LoaderTest, IndexCountNotMultipleOfThree) {
  Gltf g = basic();
  g.node("\"mesh\":" + std::to_string(g.mesh("bad", 0, g.indices({0, 1, 2, 0}), 0)));
  expect_error(g, "has 4 indices, not a multiple of 3");
}

TEST_F(LoaderTest, WrongComponentTypeForPosition) {
  Gltf g = basic();
  const int a =
      g.accessor(g.view(std::vector<uint32_t>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5125, 3, "VEC3");
  g.node("\"mesh\":" + std::to_string(g.mesh("ints", a)));
  expect_error(g,
               "POSITION accessor 3 has componentType UNSIGNED_INT; expected FLOAT or BYTE or "
               "UNSIGNED_BYTE or SHORT or UNSIGNED_SHORT");
}

TEST_F(LoaderTest, WrongTypeForPosition) {
  Gltf g = basic();
  g.accessors[0] = "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}";
  expect_error(g, "POSITION accessor 0 has type VEC2; expected VEC3");
}

TEST_F(LoaderTest, PointsBesideSurfacesAreSkippedWithAWarning) {
  Gltf g = basic();
  g.mesh("dots", 0, -1, 0, "", ",\"mode\":0");
  g.node("\"mesh\":1");
  const Scene s = load(g);
  ASSERT_EQ(s.meshes.size(), 1u);  // the triangle alone
  EXPECT_EQ(s.meshes[0].indices.size(), 3u);
  bool warned = false;
  for (const std::string& w : s.warnings)
    warned = warned || w.find(
                           "mesh 'dots' primitive 0 uses mode POINTS: points and lines have "
                           "no area and are not drawn") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Lines alone leave the file nothing to draw; a mode glTF does not define is refused.
TEST_F(LoaderTest, LinesAloneLeaveNoTrianglesAndUndefinedModesAreRefused) {
  Gltf g = basic();
  g.meshes[0] = "{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":1}]}";
  expect_error(g,
               "no triangles to render: the scene's nodes reference no mesh with a "
               "non-degenerate triangle (1 primitive is points or lines, which have no area)");
  g.meshes[0] = "{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":9}]}";
  expect_error(g, "mesh 'tri' primitive 0 uses mode 9, which glTF 2.0 does not define");
}

// A strip and a fan over five vertices give the triangles glTF 2.0 section 3.7.2.1 defines, in
// order and each with the winding of the first (all facing +z here).
TEST_F(LoaderTest, StripsAndFansUnrollIntoTheirTriangles) {
  struct Case {
    int mode;
    std::vector<float> xyz;
    std::vector<uint32_t> order;     // the vertex order written to the file
    std::vector<uint32_t> expected;  // the triangles, in file indices
  };
  // Strip 0 1 2 3 4 over a zigzag: (0 1 2) (1 3 2) (2 3 4). Fan 0 1 3 2 4 around vertex 0:
  // (1 3 0) (3 2 0) (2 4 0).
  const Case cases[] = {{5,
                         {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0},
                         {0, 1, 2, 3, 4},
                         {0, 1, 2, 1, 3, 2, 2, 3, 4}},
                        {6,
                         {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, -1, 1, 0},
                         {0, 1, 3, 2, 4},
                         {1, 3, 0, 3, 2, 0, 2, 4, 0}}};
  for (const Case& c : cases) {
    SCOPED_TRACE("mode " + std::to_string(c.mode));
    Gltf g = basic();
    const int pos = g.vec3s(c.xyz);
    const int ind = g.indices(std::vector<uint16_t>(c.order.begin(), c.order.end()));
    g.meshes[0] =
        "{\"name\":\"m\",\"primitives\":[{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
        "},\"indices\":" + std::to_string(ind) + ",\"mode\":" + std::to_string(c.mode) + "}]}";
    const Scene s = load(g);
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].indices, c.expected);
    for (size_t t = 0; t < 3; ++t) {  // counter-clockwise seen from +z
      const vec3 a = s.meshes[0].positions[c.expected[3 * t]],
                 b = s.meshes[0].positions[c.expected[3 * t + 1]],
                 d = s.meshes[0].positions[c.expected[3 * t + 2]];
      EXPECT_GT(glm::cross(b - a, d - a).z, 0.0f) << "triangle " << t;
    }
  }
}

TEST_F(LoaderTest, SparseIndicesMustIncrease) {  // test_gltf_accessors.cpp: the valid cases
  Gltf g = basic();
  const int iv = g.view(std::vector<uint16_t>{1, 0});
  const int vv = g.view(std::vector<float>{5, 5, 5, 6, 6, 6});
  g.accessors[0] =
      "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":{"
      "\"count\":2,\"indices\":{\"bufferView\":" +
      std::to_string(iv) +
      ",\"componentType\":5123},\"values\":{\"bufferView\":" + std::to_string(vv) + "}}}";
  expect_error(g,
               "POSITION accessor 0 sparse indices are not strictly increasing (index 1 is 0 "
               "after 1)");
}

TEST_F(LoaderTest, NanCoordinate) {
  Gltf g = basic();
  const int pos = g.vec3s({0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0, 0, 0, 1, 0});
  g.node("\"mesh\":" + std::to_string(g.mesh("nan", pos)));
  expect_error(g, "mesh 'nan' has a non-finite vertex coordinate");
}

TEST_F(LoaderTest, InfCoordinate) {
  Gltf g = basic();
  const int pos = g.vec3s({0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::infinity(), 0});
  g.node("\"mesh\":" + std::to_string(g.mesh("inf", pos)));
  expect_error(g, "mesh 'inf' has a non-finite vertex coordinate");
}

TEST_F(LoaderTest, NanNormal) {
  Gltf g = basic();
  const int nor = g.vec3s({0, 0, 1, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0, 0, 1});
  g.node("\"mesh\":" +
         std::to_string(g.mesh("nn", 0, -1, 0, ",\"NORMAL\":" + std::to_string(nor))));
  expect_error(g, "mesh 'nn' has a non-finite vertex coordinate");
}

TEST_F(LoaderTest, ZeroNormalsAreDroppedWithAWarning) {
  Gltf g = basic();
  const int nor = g.vec3s({0, 0, 1, 0, 0, 0, 0, 0, 1});
  g.node("\"mesh\":" +
         std::to_string(g.mesh("zn", 0, -1, 0, ",\"NORMAL\":" + std::to_string(nor))));
  const Scene s = load(g);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_FALSE(s.meshes[0].normals.empty());
  EXPECT_TRUE(s.meshes[1].normals.empty());
  EXPECT_TRUE(has_warning(s, "mesh 'zn': zero or non-finite normals"));
}

TEST_F(LoaderTest, AbsurdCoordinate) {
  Gltf g = basic();
  const int pos = g.vec3s({0, 0, 0, 1e12f, 0, 0, 0, 1, 0});
  g.node("\"mesh\":" + std::to_string(g.mesh("huge", pos)));
  expect_error(g, "mesh 'huge' has a vertex coordinate beyond the limit of 1e10");
}

TEST_F(LoaderTest, AbsurdCoordinateAfterTransform) {
  Gltf g = basic();
  g.nodes[0] = "{\"mesh\":0,\"scale\":[1e11,1e11,1e11]}";
  expect_error(g, "mesh 'tri' has a vertex coordinate beyond the limit of 1e10");
}

TEST_F(LoaderTest, SingularTransform) {
  Gltf g = basic();
  g.nodes[0] = "{\"name\":\"flat\",\"mesh\":0,\"scale\":[1,1,0]}";
  expect_error(g, "node 'flat' has a singular transform");
}

TEST_F(LoaderTest, NodeCycle) {
  Gltf g = basic();
  g.nodes[0] = "{\"name\":\"loop\",\"mesh\":0,\"children\":[0]}";
  expect_error(g, "node 'loop' is reached twice");
}

TEST_F(LoaderTest, NoScenesUsesEveryRootNode) {
  Gltf g = basic();
  g.scenes = false;
  g.node("\"translation\":[0,0,1],\"children\":[0]");  // node 0 is now a child, not a root
  const Scene s = load(g);
  ASSERT_EQ(s.meshes.size(), 1u);
  expect_vec(s.meshes[0].positions[1], vec3(1, 0, 1));
  EXPECT_EQ(s.cameras.size(), 1u);
  EXPECT_EQ(s.lights.size(), 1u);
}

TEST_F(LoaderTest, ExcessiveDepth) {
  Gltf g = basic();
  const int first = int(g.nodes.size());
  for (int i = 0; i < 1100; ++i) g.node("\"children\":[" + std::to_string(first + i + 1) + "]");
  g.node("\"mesh\":0");
  expect_error(g, "the node hierarchy is deeper than 1000 levels");
}

TEST_F(LoaderTest, MeshIndexOutOfRange) {
  Gltf g = basic();
  g.nodes[0] = "{\"name\":\"geometry\",\"mesh\":4}";
  expect_error(g, "node 'geometry' refers to mesh 4, which does not exist (the file has 1 mesh)");
  g.mesh("second", 0);
  expect_error(g, "(the file has 2 meshes)");
}

TEST_F(LoaderTest, MaterialIndexOutOfRange) {
  Gltf g = basic();
  g.node("\"mesh\":" + std::to_string(g.mesh("odd", 0, 2, 5)));
  expect_error(g, "mesh 'odd' primitive 0 refers to material 5, which does not exist");
}

// No camera is not an error: the render frames the bounds (view.h).
TEST_F(LoaderTest, NoCamera) {
  Gltf g = basic();
  g.roots = std::vector<int>{0, 2};
  const Scene s = load(g);
  EXPECT_TRUE(s.cameras.empty());
  EXPECT_EQ(s.lights.size(), 1u);
}

TEST_F(LoaderTest, OrthographicCameraIsSkipped) {
  Gltf g = basic();
  g.cameras.push_back(
      "{\"name\":\"ortho\",\"type\":\"orthographic\",\"orthographic\":"
      "{\"xmag\":1,\"ymag\":1,\"znear\":0.1,\"zfar\":10}}");
  g.node("\"camera\":1");
  const Scene s = load(g);
  EXPECT_EQ(s.cameras.size(), 1u);
  EXPECT_TRUE(has_warning(s, "camera 'ortho' is orthographic and is skipped"));
  g.roots = std::vector<int>{0, 2, 3};
  EXPECT_TRUE(load(g).cameras.empty());
}

TEST_F(LoaderTest, InvalidYfov) {
  Gltf g = basic();
  g.cameras[0] = "{\"type\":\"perspective\",\"perspective\":{\"yfov\":3.5,\"znear\":0.1}}";
  expect_error(g, "camera 0: yfov 3.5 must be in (0, pi)");
}

// No light is not an error either: the render adds the default sky (scene_setup.h).
TEST_F(LoaderTest, NoLight) {
  Gltf g = basic();
  g.roots = std::vector<int>{0, 1};
  const Scene s = load(g);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_FALSE(pb::has_light(s));
}

TEST_F(LoaderTest, ZeroIntensityLightIsNoLight) {
  Gltf g = basic();
  g.lights[0] = "{\"type\":\"point\",\"intensity\":0}";
  const Scene s = load(g);
  EXPECT_EQ(s.lights.size(), 1u);
  EXPECT_FALSE(pb::has_light(s));
}

// KHR_lights_punctual directional: light travels along the node's -Z; color x intensity is the
// irradiance on a surface facing it; position and range do not apply.
TEST_F(LoaderTest, DirectionalLight) {
  Gltf g = basic();
  g.lights[0] =
      "{\"name\":\"sun\",\"type\":\"directional\",\"color\":[1,0.5,0.25],\"intensity\":4}";
  // Rotated 90 degrees about +X: local -Z becomes world -Y (straight down).
  g.nodes[2] =
      "{\"name\":\"lamp\",\"translation\":[5,6,7],\"rotation\":[-0.7071067811865476,0,0,"
      "0.7071067811865476],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}";
  const Scene s = load(g);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].kind, pb::PunctualKind::Directional);
  expect_vec(s.lights[0].direction, vec3(0, -1, 0));
  expect_vec(s.lights[0].intensity, vec3(4, 2, 1));
  EXPECT_TRUE(s.warnings.empty());
}

TEST_F(LoaderTest, NegativeIntensity) {
  Gltf g = basic();
  g.lights[0] = "{\"name\":\"dark\",\"type\":\"point\",\"intensity\":-1}";
  expect_error(g, "light 'dark': intensity and color must be finite and >= 0");
}

TEST_F(LoaderTest, PowerBeyondFloatRange) {
  // Each intensity fits in a float; their total power (4 pi I per light) does not.
  Gltf g = basic();
  g.lights[0] = "{\"name\":\"flood\",\"type\":\"point\",\"intensity\":3e38}";
  expect_error(g, "the lights emit");
  expect_error(g, "beyond the float range");
  // 1e30, the extremes suite's brightest emitter, still loads.
  g.lights[0] = "{\"name\":\"bright\",\"type\":\"point\",\"intensity\":1e30}";
  EXPECT_EQ(load(g).lights.size(), 1u);
}

TEST_F(LoaderTest, LightIndexOutOfRange) {
  Gltf g = basic();
  g.nodes[2] = "{\"name\":\"lamp\",\"extensions\":{\"KHR_lights_punctual\":{\"light\":3}}}";
  expect_error(g, "node 'lamp' refers to light 3, which does not exist");
}

TEST_F(LoaderTest, SpotConeAnglesInvalid) {
  Gltf g = basic();
  g.lights[0] = "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.6,\"outerConeAngle\":0.5}}";
  expect_error(g, "spot cone angles inner 0.6, outer 0.5 must satisfy 0 <= inner < outer <= pi/2");
  g.lights[0] = "{\"type\":\"spot\",\"spot\":{\"outerConeAngle\":2}}";
  expect_error(g, "must satisfy 0 <= inner < outer <= pi/2");
}

TEST_F(LoaderTest, IorBelowOne) {
  Gltf g = basic();
  g.materials[0] =
      "{\"name\":\"odd\",\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
      "\"KHR_materials_ior\":{\"ior\":0.9}}}";
  expect_error(g, "material 'odd': ior 0.9 must be 0 or finite and >= 1");
}

TEST_F(LoaderTest, BaseColorAboveOne) {
  Gltf g = basic();
  g.materials[0] =
      "{\"name\":\"hot\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1.2,0.5,0.5,1]}}";
  expect_error(g, "material 'hot': baseColorFactor (1.2, 0.5, 0.5) is outside [0, 1]");
}

TEST_F(LoaderTest, NegativeEmission) {
  Gltf g = basic();
  g.materials[0] =
      "{\"name\":\"sink\",\"emissiveFactor\":[1,1,1],"
      "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":-2}}}";
  expect_error(
      g, "material 'sink': emission (emissiveFactor x emissiveStrength) must be finite and >= 0");
}

// What is not implemented is warned about, not refused: unknown extensions (required ones too),
// animations.
TEST_F(LoaderTest, UnsupportedRequiredExtension) {
  Gltf g = basic();
  g.top =
      "\"extensionsUsed\":[\"EXT_lights_image_based\",\"EXT_lights_ies\"],"
      "\"extensionsRequired\":[\"EXT_lights_image_based\"],";
  const Scene s = load(g);
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0],
            "extension 'EXT_lights_image_based' is required but not implemented; rendered "
            "without it");
  EXPECT_EQ(s.warnings[1], "extension 'EXT_lights_ies' is ignored");
}

TEST_F(LoaderTest, ExtensionsWithoutWhichTheImageIsTheSameAreNotWarned) {
  // Metadata, the variants' default materials and MSFT_lod's finest level are what photonbound
  // draws anyway; unlit materials are lit, which the warning says.
  Gltf g = basic();
  g.top =
      "\"extensionsUsed\":[\"KHR_xmp_json_ld\",\"KHR_materials_variants\",\"MSFT_lod\","
      "\"KHR_materials_unlit\"],";
  const Scene s = load(g);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(
      s.warnings[0],
      "extension 'KHR_materials_unlit' is ignored: its materials are lit (light is simulated, "
      "not painted on), by their metallic-roughness factors");
}

TEST_F(LoaderTest, MorphTargetsAreDrawnAtTheMeshsWeights) {
  // As viewers draw the mesh with no animation playing: weight 1 lifts it by the target's 1
  // (tests/gltf/test_gltf_deform.cpp has the rest).
  Gltf g = basic();
  const int delta = g.vec3s({0, 0, 1, 0, 0, 1, 0, 0, 1});
  g.meshes[0] =
      "{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":0},"
      "\"indices\":2,\"material\":0,\"targets\":[{\"POSITION\":" +
      std::to_string(delta) + "}]}],\"weights\":[1]}";
  const Scene s = load(g);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  EXPECT_EQ(s.meshes[0].positions[0].z, 1.0f);
}

TEST_F(LoaderTest, AnimationsAreIgnoredWithAWarning) {
  Gltf g = basic();
  const int times =
      g.accessor(g.view(std::vector<float>{0, 1}), 5126, 2, "SCALAR", ",\"min\":[0],\"max\":[1]");
  const int values = g.vec3s({0, 0, 0, 1, 0, 0});
  g.top = "\"animations\":[{\"samplers\":[{\"input\":" + std::to_string(times) +
          ",\"output\":" + std::to_string(values) +
          "}],\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":"
          "\"translation\"}}]}],";
  const Scene s = load(g);
  EXPECT_TRUE(has_warning(s, "1 animation is ignored; the scene is drawn as the nodes place it"));
}

TEST_F(LoaderTest, GlbBadMagic) {
  std::vector<unsigned char> b = basic().glb();
  b[0] = 'x';
  expect_error(write("bad.glb", b), "malformed glTF: bad GLB magic");
}

TEST_F(LoaderTest, GlbTruncatedChunk) {
  std::vector<unsigned char> b = basic().glb();
  b.resize(b.size() - 8);
  expect_error(write("cut.glb", b), "malformed glTF: truncated GLB");
  // Header length adjusted to the cut: the BIN chunk itself now overruns the file.
  const uint32_t n = uint32_t(b.size());
  std::memcpy(b.data() + 8, &n, 4);
  expect_error(write("cut2.glb", b), "malformed glTF: the GLB BIN chunk");
  expect_error(write("tiny.glb", std::vector<unsigned char>{'g', 'l', 'T', 'F', 2}),
               "truncated GLB header");
}

TEST_F(LoaderTest, ExternalBufferMissing) {
  Gltf g = basic();
  g.buffer_uri = "missing.bin";
  // In its own words, naming the file that is missing, and only once (not "malformed").
  expect_error(g, ": the buffer file 'missing.bin' it refers to cannot be opened");
}

TEST_F(LoaderTest, ExternalBufferWrongSize) {
  Gltf g = basic();
  g.buffer_uri = "short.bin";
  write("short.bin", std::vector<unsigned char>(g.bin.begin(), g.bin.end() - 4));
  expect_error(g, "malformed glTF: File size mismatch");
}

TEST_F(LoaderTest, SmokeLoadsShippedScenes) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(PHOTONBOUND_SCENES, ec))
    if (e.path().extension() == ".gltf" || e.path().extension() == ".glb")
      files.push_back(e.path());
  if (files.empty()) GTEST_SKIP() << "no scenes in " << PHOTONBOUND_SCENES;
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    Scene s = load_gltf(f.string());
    EXPECT_GT(s.triangle_count(), 0u);
    EXPECT_FALSE(s.bounds.empty());
    // Lit and seen once the render has added what the file lacks (the default sky and view).
    pb::RenderOptions o;
    pb::complete_scene(s, o);
    EXPECT_TRUE(pb::has_light(s));
    const pb::World world(std::move(s));
    EXPECT_NO_THROW(pb::choose_camera(world.scene(), o));
  }
}

// Every byte of a message is printable ASCII or part of valid UTF-8: no control characters.
bool printable_utf8(const std::string& m) {
  for (size_t i = 0; i < m.size();) {
    const auto b = (unsigned char)m[i];
    if (b < 0x20 || b == 0x7f) return false;
    size_t n = b < 0x80 ? 1 : b >= 0xf0 ? 4 : b >= 0xe0 ? 3 : b >= 0xc2 ? 2 : 0;
    if (n == 0 || i + n > m.size()) return false;
    for (size_t k = 1; k < n; ++k)
      if (((unsigned char)m[i + k] & 0xc0) != 0x80) return false;
    i += n;
  }
  return true;
}

TEST_F(LoaderTest, MessagesQuotingHostileBytesStayOneLineOfText) {
  // A node name with invalid UTF-8, a control character and a line break, and a JSON syntax
  // error right after a stray high byte (the parser quotes the last bytes it read).
  Gltf g = basic();
  g.nodes.push_back("{\"name\":\"bad\\u0001\\n\xd6\xff name\",\"mesh\":7}");
  const std::string named = write("named.gltf", g.json());
  const std::string broken = write("broken.gltf", std::string("{\"asset\": \xd6\x01\n}"));
  for (const std::string& path : {named, broken}) {
    try {
      load_gltf(path);
      ADD_FAILURE() << path << " loaded";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
      EXPECT_TRUE(printable_utf8(m)) << m;
    }
  }
}

// Inputs kept from the libFuzzer runs of the loader (tools/fuzz.sh; tests/data/fuzz/README.md):
// each must load into a scene the renderer can prepare, or be refused with one line of text
// that names the file. Under tools/sanitize.sh this replays them with ASan and UBSan.
TEST(LoaderFuzzRegressions, LoadOrRefuseWithOneLine) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(PHOTONBOUND_TEST_DATA "/fuzz"))
    if (e.path().extension() == ".gltf" || e.path().extension() == ".glb")
      files.push_back(e.path());
  ASSERT_GE(files.size(), 7u) << "the fuzz regression inputs are missing";
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    try {
      Scene s = load_gltf(f.string());
      pb::complete_scene(s, pb::RenderOptions{});  // the default sky when it has no light
      const pb::World world(s);
      EXPECT_GT(world.scene_size(), 0.0f);
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(f.string() + ": ", 0), 0u) << m;
      EXPECT_TRUE(printable_utf8(m)) << m;
    }
  }
}

}  // namespace
