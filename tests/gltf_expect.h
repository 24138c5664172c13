// Expectations shared by the decode tests: the world transform of gltf_fixture.h's mesh_trs(),
// loading, one-line errors, and comparing a loaded mesh with the grid it was made from. The
// loader tests (test_gltf_loader_*.cpp) add a one-triangle document and a table of cases: an
// edit of that document and the outcome expected (a one-line SceneError, or checks on the Scene).
#pragma once

#include "gltf_fixture.h"
#include "process_fixture.h"

#include "gltf/gltf_loader.h"
#include "io/image_io.h"

#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

namespace pb::test {

// T * R * S of mesh_trs(), in double.
inline glm::dmat4 trs_matrix() {
  const json t = mesh_trs();
  const auto v = [&](const char* k, int i) { return t[k][size_t(i)].get<double>(); };
  const double x = v("rotation", 0), y = v("rotation", 1), z = v("rotation", 2),
               w = v("rotation", 3);
  const glm::dmat3 r(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
                     2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                     2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y));
  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) m[c] = glm::dvec4(r[c] * v("scale", c), 0.0);
  m[3] = glm::dvec4(v("translation", 0), v("translation", 1), v("translation", 2), 1.0);
  return m;
}
inline glm::dvec3 world_point(const glm::dvec3& p) {
  return glm::dvec3(trs_matrix() * glm::dvec4(p, 1.0));
}
inline glm::dvec3 world_normal(const glm::dvec3& n) {
  return glm::normalize(glm::transpose(glm::inverse(glm::dmat3(trs_matrix()))) * n);
}
// The largest factor by which the normal transform can stretch an error: max / min scale.
constexpr double kNormalGain = 2.0 / 0.5;
constexpr double kPositionGain = 2.0;  // the largest scale of mesh_trs()

class DecodeTest : public TempDirTest {
 protected:
  // A copy of the one mesh a test scene holds (so that it outlives a temporary Scene).
  static Mesh only_mesh(const Scene& s) {
    EXPECT_EQ(s.meshes.size(), 1u);
    return s.meshes.at(0);
  }
  void expect_error(const std::string& file, const std::string& phrase,
                    const LoadPolicy& policy = {}) {
    try {
      load_gltf(file, policy);
      ADD_FAILURE() << "expected a SceneError containing \"" << phrase << "\"";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(file + ": ", 0), 0u) << m;
      EXPECT_NE(m.find(phrase), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
};

struct Tolerance {
  double position = 1e-5, normal = 1e-5, uv0 = 1e-6, uv1 = 1e-6;
};

// Compares a loaded mesh with the grid: every loaded vertex is matched to the grid vertex nearest
// in world space (identity when `same_order`), which must be within the tolerances in position,
// normal and both texture coordinate sets; the triangles must be the grid's, each with the same
// winding (a rotation of its corners allowed when the order may change).
inline void expect_grid(const Mesh& m, const Grid& g, const Tolerance& tol, bool same_order) {
  ASSERT_EQ(m.positions.size(), g.vertices());
  ASSERT_EQ(m.normals.size(), g.vertices());
  ASSERT_EQ(m.texcoords[0].size(), g.vertices());
  ASSERT_EQ(m.texcoords[1].size(), g.vertices());
  const auto p3 = [](const std::vector<float>& v, size_t k) {
    return glm::dvec3(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
  };
  std::vector<glm::dvec3> want(g.vertices());
  for (size_t k = 0; k < want.size(); ++k) want[k] = world_point(p3(g.positions, k));
  std::vector<uint32_t> map(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const glm::dvec3 p(m.positions[i]);
    size_t best = i;
    if (!same_order)
      for (size_t k = 0; k < want.size(); ++k)
        if (glm::length(p - want[k]) < glm::length(p - want[best])) best = k;
    map[i] = uint32_t(best);
    ASSERT_LE(glm::length(p - want[best]), tol.position) << "vertex " << i;
    EXPECT_LE(glm::length(glm::dvec3(m.normals[i]) - world_normal(p3(g.normals, best))), tol.normal)
        << "vertex " << i;
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(m.texcoords[0][i][c], g.uv0[2 * best + size_t(c)], tol.uv0) << "vertex " << i;
      EXPECT_NEAR(m.texcoords[1][i][c], g.uv1[2 * best + size_t(c)], tol.uv1) << "vertex " << i;
    }
  }
  // Triangles as their corners rotated to put the smallest first (the winding kept): in order
  // when the order is kept (meshoptimizer's index codec may still rotate corners), as sets
  // otherwise.
  auto canonical = [](std::array<uint32_t, 3> t) {
    while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
    return t;
  };
  std::vector<std::array<uint32_t, 3>> grid, loaded;
  for (size_t t = 0; t < g.indices.size(); t += 3)
    grid.push_back(canonical({g.indices[t], g.indices[t + 1], g.indices[t + 2]}));
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3)
    loaded.push_back(canonical({map[m.indices[t]], map[m.indices[t + 1]], map[m.indices[t + 2]]}));
  EXPECT_EQ(m.indices.size(), g.indices.size());
  if (!same_order) {
    std::sort(grid.begin(), grid.end());
    std::sort(loaded.begin(), loaded.end());
  }
  EXPECT_EQ(loaded, grid);
}

// ---- The loader tests ----

inline json light_ext(int light) { return json{{"KHR_lights_punctual", json{{"light", light}}}}; }

// One triangle (0,0,0) (1,0,0) (0,1,0) facing +z with material 0 'grey' (base colour
// (0.5, 0.6, 0.7), metallic 0) under root node 0 'geometry'; perspective camera 0 (yfov 0.7,
// aspect 1.5) at z = 5 under node 1 'eye'; the point light 'bulb' (colour (1, 0.5, 0.25),
// intensity 8) at (0, 2, 0) under node 2 'lamp'. Accessors 0, 1, 2 are POSITION, NORMAL and the
// UNSIGNED_SHORT indices in bufferViews 0, 1, 2 (78 bytes); no extensionsUsed.
inline Doc triangle_doc() {
  Doc d;
  d.j.erase("extensionsUsed");
  const int pos = d.vec3s({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int nor = d.vec3s({0, 0, 1, 0, 0, 1, 0, 0, 1});
  const int ind = d.indices({0, 1, 2});
  const json pbr = json{{"baseColorFactor", {0.5, 0.6, 0.7, 1}}, {"metallicFactor", 0}};
  d.j["materials"] = json::array({json{{"name", "grey"}, {"pbrMetallicRoughness", pbr}}});
  const json prim = json{
      {"attributes", json{{"POSITION", pos}, {"NORMAL", nor}}}, {"indices", ind}, {"material", 0}};
  d.j["meshes"] = json::array({json{{"name", "tri"}, {"primitives", json::array({prim})}}});
  const json persp = json{{"yfov", 0.7}, {"znear", 0.01}, {"aspectRatio", 1.5}};
  d.j["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", persp}}});
  d.j["nodes"] = json::array(
      {json{{"name", "geometry"}, {"mesh", 0}},
       json{{"name", "eye"}, {"camera", 0}, {"translation", {0, 0, 5}}},
       json{{"name", "lamp"}, {"translation", {0, 2, 0}}, {"extensions", light_ext(0)}}});
  const json bulb =
      json{{"name", "bulb"}, {"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 8}};
  d.j["extensions"]["KHR_lights_punctual"]["lights"] = json::array({bulb});
  d.j["scenes"][0]["nodes"] = json::array({0, 1, 2});
  return d;
}

inline json& material0(Doc& d) { return d.j["materials"][0]; }
inline json& light0(Doc& d) { return d.j["extensions"]["KHR_lights_punctual"]["lights"][0]; }
inline void set_roots(Doc& d, const std::vector<int>& roots) { d.j["scenes"][0]["nodes"] = roots; }
// Adds `node` as a new root node; returns its index.
inline int add_root(Doc& d, json node) {
  const int n = d.add("nodes", std::move(node));
  d.j["scenes"][0]["nodes"].push_back(n);
  return n;
}
// A mesh `name` with one primitive over POSITION accessor `position`, `indices` and `material`
// when not -1; `extra` is merged into the primitive (more attributes, mode). Returns its index.
inline int add_mesh(Doc& d, const std::string& name, int position, int indices = -1,
                    int material = -1, const json& extra = json::object()) {
  json p = json{{"attributes", json{{"POSITION", position}}}};
  if (indices >= 0) p["indices"] = indices;
  if (material >= 0) p["material"] = material;
  p.merge_patch(extra);
  return d.add("meshes", json{{"name", name}, {"primitives", json::array({p})}});
}
// add_mesh() under a new root node.
inline int add_mesh_root(Doc& d, const std::string& name, int position, int indices = -1,
                         int material = -1, const json& extra = json::object()) {
  const int m = add_mesh(d, name, position, indices, material, extra);
  add_root(d, json{{"mesh", m}});
  return m;
}

// The bytes of an 8-bit RGB PNG of w x h texels (texel k has R = 40 k + seed mod 256,
// G = 255 - k, B = 7), written by image_io.h.
inline std::vector<unsigned char> png_bytes(int w, int h, int seed = 0) {
  std::vector<unsigned char> rgb;
  for (int k = 0; k < w * h; ++k)
    rgb.insert(rgb.end(), {uint8_t(40 * k + seed), uint8_t(255 - k), 7});
  const std::filesystem::path p = unique_temp_path("png_" + std::to_string(seed)) += ".png";
  write_png(p.string(), w, h, rgb);
  std::ifstream f(p, std::ios::binary);
  std::vector<unsigned char> out{std::istreambuf_iterator<char>(f), {}};
  std::filesystem::remove(p);
  return out;
}
inline json png_image(const std::vector<unsigned char>& png) {
  return json{{"uri", "data:image/png;base64," + base64(png)}};
}
// Top-level members: `extension` used (when given), one 2 x 2 PNG image and texture 0 over it.
inline json one_texture(const char* extension = nullptr) {
  json top = json{{"images", json::array({png_image(png_bytes(2, 2))})},
                  {"textures", json::array({json{{"source", 0}}})}};
  if (extension) top["extensionsUsed"] = json::array({extension});
  return top;
}

// triangle_doc() with TEXCOORD_0 (0,0) (1,0) (0,1) and TEXCOORD_1 (0.5,0.5) (1,0.5) (0.5,1),
// material 0 replaced by {"name": "tex"} and the members of `material`, and the top-level
// members of `top` (images, samplers, textures, extensionsUsed).
inline Doc textured(const json& top, const json& material) {
  Doc d = triangle_doc();
  const int uv0 = d.accessor(d.view(std::vector<float>{0, 0, 1, 0, 0, 1}), kFloat, 3, "VEC2");
  const int uv1 =
      d.accessor(d.view(std::vector<float>{0.5f, 0.5f, 1, 0.5f, 0.5f, 1}), kFloat, 3, "VEC2");
  json& attributes = d.j["meshes"][0]["primitives"][0]["attributes"];
  attributes["TEXCOORD_0"] = uv0;
  attributes["TEXCOORD_1"] = uv1;
  json m = json{{"name", "tex"}};
  m.update(material);
  material0(d) = m;
  d.j.update(top);
  return d;
}

inline bool has_warning(const Scene& s, const std::string& phrase) {
  for (const std::string& w : s.warnings)
    if (w.find(phrase) != std::string::npos) return true;
  return false;
}
inline void expect_vec(const vec3& a, const vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}
inline vec3 face_normal(const Mesh& m, size_t t) {
  const vec3 p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]],
             p2 = m.positions[m.indices[3 * t + 2]];
  return glm::normalize(glm::cross(p1 - p0, p2 - p0));
}
// Every byte of a message is printable ASCII or part of valid UTF-8: no control characters.
inline bool printable_utf8(const std::string& m) {
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

class LoaderTest : public DecodeTest {
 protected:
  // The temporary folder of TempDirTest, its name flattened for parameterised tests
  // ("Table/LoaderNodes.Row/NodeCycle").
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    dir_ = unique_temp_path(name);
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  std::string write(const std::string& name, const std::vector<unsigned char>& bytes) {
    std::ofstream(dir_ / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return path(name);
  }
  std::string write(const std::string& name, const std::string& text) {
    return write(name, std::vector<unsigned char>(text.begin(), text.end()));
  }
  Scene load(const Doc& d) { return load_gltf(write("scene.gltf", d.gltf())); }
  using DecodeTest::expect_error;
  void expect_error(const Doc& d, const std::string& phrase) {
    expect_error(write("scene.gltf", d.gltf()), phrase);
  }
};

// One row of a loader table: `edit` changes triangle_doc() (or replaces it), which is written to
// `file` (as a GLB when `glb`, whatever the name) and loaded. With `error`, loading must throw a
// one-line SceneError that starts with the file's path and holds every phrase; otherwise the
// Scene's source must be the path and `check` passes.
struct LoaderCase {
  std::string name;  // the test's name: letters, digits and underscores
  std::function<void(Doc&)> edit;
  std::vector<std::string> error = {};
  std::function<void(const Scene&)> check = {};
  std::string file = "scene.gltf";
  bool glb = false;
};
inline void PrintTo(const LoaderCase& c, std::ostream* os) { *os << c.name; }
inline std::string case_name(const ::testing::TestParamInfo<LoaderCase>& info) {
  return info.param.name;
}

// Each test file declares its suite as an alias, TEST_P(Alias, Row) { run(); }, and instantiates
// it over its rows with case_name.
class LoaderCaseTest : public LoaderTest, public ::testing::WithParamInterface<LoaderCase> {
 protected:
  void run() {
    const LoaderCase& c = GetParam();
    Doc d = triangle_doc();
    if (c.edit) c.edit(d);
    const std::string file = c.glb ? write(c.file, d.glb()) : write(c.file, d.gltf());
    for (const std::string& phrase : c.error) expect_error(file, phrase);
    if (!c.error.empty()) return;
    const Scene s = load_gltf(file);
    EXPECT_EQ(s.source, file);
    if (c.check) c.check(s);
  }
};

}  // namespace pb::test
