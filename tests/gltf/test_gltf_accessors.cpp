// Core accessor features real exporters use: KHR_mesh_quantization (integer POSITION, NORMAL and
// TEXCOORD_n, normalised or not), sparse accessors (with and without a bufferView, also for
// indices), and a skin without inverseBindMatrices (tests/gltf/test_gltf_deform.cpp: skins and
// morph targets).
#include "gltf_expect.h"

#include <cmath>
#include <cstring>

namespace {

using namespace pb::test;
using pb::Scene;

constexpr int kByte = 5120, kUByte = 5121;  // the others are in gltf_fixture.h

// The glTF 2.0 dequantisation of component type `c` (normalised or not).
double dequantise(int c, bool normalized, int64_t v) {
  if (!normalized) return double(v);
  switch (c) {
    case kByte:
      return std::max(double(v) / 127.0, -1.0);
    case kUByte:
      return double(v) / 255.0;
    case kShort:
      return std::max(double(v) / 32767.0, -1.0);
    default:
      return double(v) / 65535.0;
  }
}

int64_t lowest(int c) { return c == kByte ? -128 : c == kShort ? -32768 : 0; }
int64_t highest(int c) {
  return c == kByte ? 127 : c == kUByte ? 255 : c == kShort ? 32767 : 65535;
}
size_t size_of(int c) { return c == kByte || c == kUByte ? 1 : 2; }

// `v` (n elements of `comps` components) stored as component type c, each element padded to a
// multiple of 4 bytes (the accessor alignment rule KHR_mesh_quantization repeats).
std::vector<unsigned char> pack(int c, const std::vector<int64_t>& v, int comps, size_t& stride) {
  stride = (size_of(c) * size_t(comps) + 3) / 4 * 4;
  std::vector<unsigned char> out(v.size() / size_t(comps) * stride, 0);
  for (size_t i = 0; i < v.size(); ++i) {
    const size_t at = i / size_t(comps) * stride + i % size_t(comps) * size_of(c);
    const int16_t s = int16_t(v[i]);
    const uint16_t u = uint16_t(v[i]);
    if (size_of(c) == 1) out[at] = uint8_t(v[i] & 0xff);
    if (size_of(c) == 2) std::memcpy(&out[at], c == kShort ? (const void*)&s : (const void*)&u, 2);
  }
  return out;
}

TEST_F(DecodeTest, QuantisedAttributesAreDequantisedThenTransformed) {
  // A quad whose corners sit at the ends of each type's range, placed by a node matrix that
  // carries the dequantisation scale and offset, as quantising exporters write it.
  const double frac[4][3] = {{0, 0, 0.5}, {1, 0, 0.5}, {1, 1, 0}, {0, 1, 1}};
  const std::vector<double> matrix = {0.5, 0, 0, 0, 0, 0.25, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1};
  glm::dmat4 m4;
  for (int k = 0; k < 16; ++k) m4[k / 4][k % 4] = matrix[size_t(k)];
  const glm::dmat3 nm = glm::transpose(glm::inverse(glm::dmat3(m4)));
  for (int c : {kByte, kUByte, kShort, kUShort})
    for (bool normalized : {false, true}) {
      Doc d;
      d.require({"KHR_mesh_quantization"});
      std::vector<int64_t> pos, uv;
      for (const auto& f : frac)
        for (int k = 0; k < 3; ++k)
          pos.push_back(lowest(c) + int64_t(std::lround(f[k] * double(highest(c) - lowest(c)))));
      for (size_t i = 0; i < 4; ++i) uv.insert(uv.end(), {pos[3 * i], pos[3 * i + 1]});
      const int nc = size_of(c) == 1 ? kByte : kShort;  // NORMAL: signed normalised only
      const int64_t top = highest(nc);
      const std::vector<int64_t> nor = {lowest(nc), 3, 20, 10, top, -4, 0, 0, top, 50, -60, 70};
      const auto packed = [&](int type, const std::vector<int64_t>& v, int comps) {
        size_t stride = 0;
        const std::vector<unsigned char> bytes = pack(type, v, comps, stride);
        return d.view(bytes, json{{"byteStride", stride}});
      };
      const json norm = json{{"normalized", true}}, flag = json{{"normalized", normalized}};
      const int pa = d.accessor(packed(c, pos, 3), c, 4, "VEC3", flag);
      const int na = d.accessor(packed(nc, nor, 3), nc, 4, "VEC3", norm);
      const int t0 = d.accessor(packed(c, uv, 2), c, 4, "VEC2", flag);
      const int t1 = d.accessor(packed(c, uv, 2), c, 4, "VEC2", json{{"normalized", !normalized}});
      const std::vector<uint16_t> idx = {0, 1, 2, 0, 2, 3};
      const int ia = d.accessor(d.view(idx), kUShort, 6, "SCALAR");
      d.mesh_node(
          json{{"attributes",
                json{{"POSITION", pa}, {"NORMAL", na}, {"TEXCOORD_0", t0}, {"TEXCOORD_1", t1}}},
               {"indices", ia}},
          json{{"matrix", matrix}});
      SCOPED_TRACE("componentType " + std::to_string(c) + (normalized ? " normalized" : ""));
      const pb::Mesh& m = only_mesh(pb::load_gltf(d.write(path("quantised.gltf"))));
      ASSERT_EQ(m.positions.size(), 4u);
      ASSERT_EQ(m.indices.size(), 6u);
      for (size_t i = 0; i < 4; ++i) {
        const auto v = [&](const std::vector<int64_t>& src, int type, bool nz, size_t k) {
          return dequantise(type, nz, src[k]);
        };
        const glm::dvec3 p(v(pos, c, normalized, 3 * i), v(pos, c, normalized, 3 * i + 1),
                           v(pos, c, normalized, 3 * i + 2));
        const glm::dvec3 w = glm::dvec3(m4 * glm::dvec4(p, 1.0));
        for (int k = 0; k < 3; ++k)
          EXPECT_NEAR(m.positions[i][k], w[k], 1e-6 * (1 + std::abs(w[k])));
        const glm::dvec3 n =
            glm::normalize(nm * glm::dvec3(v(nor, nc, true, 3 * i), v(nor, nc, true, 3 * i + 1),
                                           v(nor, nc, true, 3 * i + 2)));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.normals[i][k], n[k], 1e-6);
        for (int k = 0; k < 2; ++k) {
          const double u0 = v(uv, c, normalized, 2 * i + size_t(k));
          const double u1 = v(uv, c, !normalized, 2 * i + size_t(k));
          EXPECT_NEAR(m.texcoords[0][i][k], u0, 1e-6 * (1 + std::abs(u0)));
          EXPECT_NEAR(m.texcoords[1][i][k], u1, 1e-6 * (1 + std::abs(u1)));
        }
      }
    }
}

// A quad of four FLOAT positions; `position` is the POSITION accessor JSON without
// componentType/type/count (added here).
std::string quad_file(Doc& d, json position, const std::string& file, int indices = -1) {
  position.update(json{{"componentType", kFloat}, {"type", "VEC3"}, {"count", 4}});
  const int pa = d.add("accessors", position);
  if (indices < 0) {
    const std::vector<uint16_t> idx = {0, 1, 2, 0, 2, 3};
    indices = d.accessor(d.view(idx), kUShort, 6, "SCALAR");
  }
  d.mesh_node(json{{"attributes", json{{"POSITION", pa}}}, {"indices", indices}}, json::object());
  return d.write(file);
}

json sparse(int count, int index_view, int component, int value_view) {
  return json{{"count", count},
              {"indices", json{{"bufferView", index_view}, {"componentType", component}}},
              {"values", json{{"bufferView", value_view}}}};
}

const std::vector<float> kQuad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

TEST_F(DecodeTest, SparseValuesReplaceTheBufferViewsElements) {
  Doc d;
  const int base = d.view(kQuad);
  const int iv = d.view(std::vector<uint8_t>{1, 3});
  const int vv = d.view(std::vector<float>{2, 0, 0.5f, 0, 3, 0.25f});
  const pb::Mesh& m = only_mesh(pb::load_gltf(quad_file(
      d, json{{"bufferView", base}, {"sparse", sparse(2, iv, kUByte, vv)}}, path("s.gltf"))));
  const std::vector<pb::vec3> want = {{0, 0, 0}, {2, 0, 0.5f}, {1, 1, 0}, {0, 3, 0.25f}};
  EXPECT_EQ(m.positions, want);
}

TEST_F(DecodeTest, SparseWithoutBufferViewStartsFromZeros) {
  Doc d;
  const int iv = d.view(std::vector<uint16_t>{1, 2, 3});
  const int vv = d.view(std::vector<float>{1, 0, 0, 1, 1, 0, 0, 1, 0});
  const pb::Mesh& m = only_mesh(pb::load_gltf(
      quad_file(d, json{{"sparse", sparse(3, iv, kUShort, vv)}}, path("zeros.gltf"))));
  const std::vector<pb::vec3> want = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  EXPECT_EQ(m.positions, want);
}

TEST_F(DecodeTest, SparseIndicesAccessorWithoutBufferView) {
  // tinygltf 2.7 refuses an indices accessor without bufferView; the prepass hands it over.
  for (const char* name : {"idx.gltf", "idx.glb"}) {
    Doc d;
    const int iv = d.view(std::vector<uint32_t>{1, 2, 4, 5});
    const int vv = d.view(std::vector<uint32_t>{1, 2, 2, 3});
    const int ia = d.accessor(-1, kUInt, 6, "SCALAR", json{{"sparse", sparse(4, iv, kUInt, vv)}});
    const pb::Mesh& m =
        only_mesh(pb::load_gltf(quad_file(d, json{{"bufferView", d.view(kQuad)}}, path(name), ia)));
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  }
}

TEST_F(DecodeTest, MalformedSparseIsASceneError) {
  const auto bad = [&](const char* name, int count, std::vector<uint16_t> idx, size_t values,
                       int component, const std::string& phrase) {
    Doc d;
    const int iv = d.view(idx);
    const int vv = d.view(std::vector<float>(values, 0.5f));
    expect_error(quad_file(d, json{{"sparse", sparse(count, iv, component, vv)}}, path(name)),
                 "mesh 'grid' primitive 0 POSITION accessor 0 sparse " + phrase);
  };
  bad("range.gltf", 2, {1, 4}, 6, kUShort, "index 1 is 4, out of range for 4 elements");
  bad("order.gltf", 2, {2, 2}, 6, kUShort, "indices are not strictly increasing");
  bad("values.gltf", 2, {1, 2}, 5, kUShort, "values read past the end of bufferView 1");
  bad("indices.gltf", 3, {1, 2}, 9, kUShort, "indices read past the end of bufferView 0");
  bad("count.gltf", 5, {0, 1, 2, 3, 3}, 15, kUShort, "count 5 is not within 1 .. 4");
  bad("zero.gltf", 0, {0}, 3, kUShort, "count 0 is not within 1 .. 4");
  bad("type.gltf", 1, {1}, 3, kFloat, "indices have componentType FLOAT");
  Doc d;  // zeros the JSON alone asks for are capped
  d.view(kQuad);
  const int huge = d.accessor(-1, kFloat, size_t(1) << 27, "VEC3");
  d.mesh_node(json{{"attributes", json{{"POSITION", huge}}}}, json::object());
  expect_error(d.write(path("huge.gltf")),
               "POSITION accessor 0 has no bufferView and 134217728 "
               "elements of 12 bytes, more than the 256 MiB");
}

// COLOR_0 as exporters write it: RGB float, RGBA normalised unsigned bytes and shorts (alpha 1
// for RGB), read into [0, 1]; signed types refused; integers not marked normalised read as
// normalised and floats outside [0, 1] clamped, each with one warning.
TEST_F(DecodeTest, VertexColoursAreReadAsGltfDefinesThem) {
  const auto load = [&](int component, const char* type, const std::vector<unsigned char>& bytes,
                        bool normalized, const char* name) {
    Doc d;
    const int ca = d.accessor(d.view(bytes), component, 4, type,
                              normalized ? json{{"normalized", true}} : json::object());
    const int pa = d.accessor(d.view(kQuad), kFloat, 4, "VEC3");
    const int ia =
        d.accessor(d.view(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}), kUShort, 6, "SCALAR");
    d.mesh_node(json{{"attributes", json{{"POSITION", pa}, {"COLOR_0", ca}}}, {"indices", ia}});
    return d.write(path(name));
  };
  const auto bytes = [](const auto& v) {
    std::vector<unsigned char> out(v.size() * sizeof(v[0]));
    std::memcpy(out.data(), v.data(), out.size());
    return out;
  };
  const Scene rgb = pb::load_gltf(load(
      kFloat, "VEC3", bytes(std::vector<float>{1, 0.5f, 0, 0, 0, 0, 0.25f, 0.25f, 0.25f, 1, 1, 1}),
      false, "rgb.gltf"));
  EXPECT_TRUE(rgb.warnings.empty()) << rgb.warnings[0];
  EXPECT_EQ(only_mesh(rgb).colors[0], glm::vec4(1, 0.5f, 0, 1));
  EXPECT_EQ(only_mesh(rgb).colors[2], glm::vec4(0.25f, 0.25f, 0.25f, 1));
  const std::vector<uint8_t> u8 = {255, 0, 51, 102, 0, 0, 0, 0, 255, 255, 255, 255, 1, 2, 3, 4};
  const pb::Mesh b = only_mesh(pb::load_gltf(load(kUByte, "VEC4", bytes(u8), true, "u8.gltf")));
  EXPECT_EQ(b.colors[0], glm::vec4(1, 0, 0.2f, 0.4f));
  EXPECT_EQ(b.colors[2], glm::vec4(1));
  const std::vector<uint16_t> u16 = {65535, 0, 13107, 26214, 0, 0, 0, 0,
                                     1,     1, 1,     1,     0, 0, 0, 65535};
  const pb::Mesh c = only_mesh(pb::load_gltf(load(kUShort, "VEC4", bytes(u16), true, "u16.gltf")));
  EXPECT_EQ(c.colors[0], glm::vec4(1, 0, 0.2f, 0.4f));
  EXPECT_EQ(c.colors[3], glm::vec4(0, 0, 0, 1));
  const Scene plain = pb::load_gltf(load(kUByte, "VEC4", bytes(u8), false, "plain.gltf"));
  EXPECT_EQ(plain.warnings,
            std::vector<std::string>{"mesh 'grid' primitive 0: COLOR_0 is not marked normalized; "
                                     "read as normalised, as glTF requires"});
  EXPECT_EQ(only_mesh(plain).colors[0], glm::vec4(1, 0, 0.2f, 0.4f));
  const Scene hot = pb::load_gltf(
      load(kFloat, "VEC3", bytes(std::vector<float>{2, 0.5f, -1, 0, 0, 0, 0, 0, 0, 0, 0, 0}), false,
           "hot.gltf"));
  EXPECT_EQ(hot.warnings, std::vector<std::string>{"mesh 'grid' primitive 0: COLOR_0 values "
                                                   "outside [0, 1] are clamped to it"});
  EXPECT_EQ(only_mesh(hot).colors[0], glm::vec4(1, 0.5f, 0, 1));
  expect_error(load(kShort, "VEC4", bytes(std::vector<int16_t>(16, 0)), true, "s16.gltf"),
               "COLOR_0 has componentType SHORT; expected FLOAT, UNSIGNED_BYTE or UNSIGNED_SHORT");
  expect_error(load(kFloat, "VEC2", bytes(std::vector<float>(8, 0)), false, "vec2.gltf"),
               "has type VEC2; expected VEC3 or VEC4");
}

TEST_F(DecodeTest, SkinWithoutInverseBindMatricesLoads) {
  // tinygltf 2.7 reports "'inverseBindMatrices' property is missing in Skin." as an error
  // although glTF makes it optional (identity matrices); the loader drops that one line. The
  // one joint is the mesh's own node, so the skin places the quad where the node does.
  Doc d;
  const std::vector<uint8_t> joints(16, 0);
  const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  const int pa = d.accessor(d.view(kQuad), kFloat, 4, "VEC3");
  const int ja = d.accessor(d.view(joints), kUByte, 4, "VEC4");
  const int wa = d.accessor(d.view(weights), kFloat, 4, "VEC4");
  const int ia = d.accessor(d.view(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}), kUShort, 6, "SCALAR");
  d.mesh_node(json{{"attributes", json{{"POSITION", pa}, {"JOINTS_0", ja}, {"WEIGHTS_0", wa}}},
                   {"indices", ia}});
  d.j["nodes"].back()["skin"] = 0;
  d.j["skins"] = json::array({json{{"joints", json::array({2})}}});
  const Scene s = pb::load_gltf(d.write(path("skin.gltf")));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const pb::Mesh m = only_mesh(s);
  for (size_t i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(m.positions[i][k],
                  world_point(glm::dvec3(kQuad[3 * i], kQuad[3 * i + 1], kQuad[3 * i + 2]))[k],
                  1e-5);
}

// A rig skins dozens of nodes (SharpGLTF's InfiniteSkinnedTentacle: 85): a mesh that cannot be
// bound (no JOINTS_0 and WEIGHTS_0) gives one line for all of them.
TEST_F(DecodeTest, ManySkinnedNodesGiveOneWarning) {
  Doc d;
  quad_file(d, json{{"bufferView", d.view(kQuad)}}, path("unused.gltf"));
  json node = d.j["nodes"].back();
  node["skin"] = 0;
  d.j["nodes"].back() = node;
  for (int k = 0; k < 3; ++k) {
    node["name"] = "copy " + std::to_string(k);
    node["translation"] = json::array({2.0 * (k + 1), 0.0, 0.0});
    d.j["nodes"].push_back(node);
    d.j["scenes"][0]["nodes"].push_back(d.j["nodes"].size() - 1);
  }
  d.j["skins"] = json::array({json{{"joints", json::array({0})}}});
  const Scene s = pb::load_gltf(d.write(path("skins.gltf")));
  EXPECT_EQ(s.warnings, std::vector<std::string>{"mesh 'grid' primitive 0 has no JOINTS_0 and "
                                                 "WEIGHTS_0 to bind it to skin 0; it is drawn by "
                                                 "its node's transform"});
  EXPECT_EQ(s.meshes.size(), 4u);
}

}  // namespace
