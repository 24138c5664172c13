// glTF loader tests: accessors, bufferViews, indices, primitive modes and vertex data. Each row
// edits gltf_expect.h's triangle_doc() and expects a one-line SceneError or a loaded Scene.
#include "gltf_expect.h"

#include <cmath>
#include <limits>

namespace pb::test {
namespace {

json accessor(int view, int component, int count, const char* type) {
  return json{{"bufferView", view}, {"componentType", component}, {"count", count}, {"type", type}};
}
json primitive(int position, const json& extra = json::object()) {
  json p = json{{"attributes", json{{"POSITION", position}}}};
  p.update(extra);
  return p;
}
void set_mesh0(Doc& d, const std::string& name, const json& prim) {
  d.j["meshes"][0] = json{{"name", name}, {"primitives", json::array({prim})}};
}
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A strip or a fan over five vertices gives the triangles glTF 2.0 section 3.7.2.1 defines, in
// order and each with the winding of the first (all counter-clockwise seen from +z here).
LoaderCase unrolled(const std::string& name, int mode, const std::vector<float>& xyz,
                    const std::vector<uint16_t>& order, const std::vector<uint32_t>& expected) {
  return {.name = name,
          .edit =
              [=](Doc& d) {
                const int pos = d.vec3s(xyz), ind = d.indices(order);
                set_mesh0(d, "m", primitive(pos, {{"indices", ind}, {"mode", mode}}));
              },
          .check =
              [=](const Scene& s) {
                ASSERT_EQ(s.meshes.size(), 1u);
                EXPECT_EQ(s.meshes[0].indices, expected);
                for (size_t t = 0; t < 3; ++t) {
                  const vec3 a = s.meshes[0].positions[expected[3 * t]],
                             b = s.meshes[0].positions[expected[3 * t + 1]],
                             c = s.meshes[0].positions[expected[3 * t + 2]];
                  EXPECT_GT(glm::cross(b - a, c - a).z, 0.0f) << "triangle " << t;
                }
              }};
}

const std::vector<LoaderCase> kRows = {
    {.name = "LoadsMinimalScene",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"mesh", 0}, {"translation", {1, 2, 3}}};
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.meshes.size(), 1u);
           const Mesh& m = s.meshes[0];
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
           EXPECT_EQ(s.lights[0].kind, PunctualKind::Point);
           expect_vec(s.lights[0].position, vec3(0, 2, 0));
           expect_vec(s.lights[0].intensity, vec3(8, 4, 2));
           ASSERT_EQ(s.cameras.size(), 1u);
           const Camera& c = s.cameras[0];
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
         }},
    {.name = "AccessorIndexOutOfRange",
     .edit = [](Doc& d) { set_mesh0(d, "tri", primitive(99)); },
     .error = {"mesh 'tri' primitive 0 POSITION refers to accessor 99, which does not exist"}},
    {.name = "BufferViewOutOfRange",
     .edit = [](Doc& d) { d.j["accessors"][0] = accessor(42, kFloat, 3, "VEC3"); },
     .error = {"POSITION accessor 0 refers to bufferView 42, which does not exist"}},
    {.name = "AccessorReadsPastTheBufferView",
     .edit = [](Doc& d) { d.j["accessors"][0] = accessor(0, kFloat, 4, "VEC3"); },
     .error = {"mesh 'tri' primitive 0 POSITION accessor 0 reads past the end of bufferView 0"}},
    {.name = "AccessorOffsetPastTheBufferView",
     .edit =
         [](Doc& d) {
           d.j["accessors"][0] = accessor(0, kFloat, 3, "VEC3");
           d.j["accessors"][0]["byteOffset"] = 4;
         },
     .error = {"reads past the end of bufferView 0"}},
    {.name = "BufferViewPastTheBufferEnd",
     .edit =
         [](Doc& d) {
           d.j["bufferViews"][0] = json{{"buffer", 0}, {"byteOffset", 80}, {"byteLength", 36}};
         },
     .error = {"extends past the end of buffer 0"}},
    {.name = "IndexValueOutOfRange",
     .edit =
         [](Doc& d) {
           add_mesh_root(d, "bad", 0, d.indices({0, 1, 7}), 0);
         },
     .error = {"mesh 'bad' primitive 0 indices accessor 3: index 2 has value 7, out of range for "
               "3 vertices"}},
    {.name = "IndexCountNotMultipleOfThree",
     .edit =
         [](Doc& d) {
           add_mesh_root(d, "bad", 0, d.indices({0, 1, 2, 0}), 0);
         },
     .error = {"has 4 indices, not a multiple of 3"}},
    {.name = "WrongComponentTypeForPosition",
     .edit =
         [](Doc& d) {
           const int v = d.view(std::vector<uint32_t>{0, 0, 0, 1, 0, 0, 0, 1, 0});
           add_mesh_root(d, "ints", d.accessor(v, kUInt, 3, "VEC3"));
         },
     .error = {"POSITION accessor 3 has componentType UNSIGNED_INT; expected FLOAT or BYTE or "
               "UNSIGNED_BYTE or SHORT or UNSIGNED_SHORT"}},
    {.name = "WrongTypeForPosition",
     .edit = [](Doc& d) { d.j["accessors"][0] = accessor(0, kFloat, 4, "VEC2"); },
     .error = {"POSITION accessor 0 has type VEC2; expected VEC3"}},
    {.name = "PointsBesideSurfacesAreSkippedWithAWarning",
     .edit =
         [](Doc& d) {
           add_mesh(d, "dots", 0, -1, 0, {{"mode", 0}});
           add_root(d, json{{"mesh", 1}});
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.meshes.size(), 1u);  // the triangle alone
           EXPECT_EQ(s.meshes[0].indices.size(), 3u);
           EXPECT_TRUE(has_warning(s,
                                   "mesh 'dots' primitive 0 uses mode POINTS: points and lines "
                                   "have no area and are not drawn"));
         }},
    // Lines alone leave the file nothing to draw; a mode glTF does not define is refused.
    {.name = "LinesAloneLeaveNoTriangles",
     .edit =
         [](Doc& d) {
           set_mesh0(d, "tri", primitive(0, {{"mode", 1}}));
         },
     .error = {"no triangles to render: the scene's nodes reference no mesh with a "
               "non-degenerate triangle (1 primitive is points or lines, which have no area)"}},
    {.name = "UndefinedModesAreRefused",
     .edit =
         [](Doc& d) {
           set_mesh0(d, "tri", primitive(0, {{"mode", 9}}));
         },
     .error = {"mesh 'tri' primitive 0 uses mode 9, which glTF 2.0 does not define"}},
    // Strip 0 1 2 3 4 over a zigzag: (0 1 2) (1 3 2) (2 3 4). Fan 0 1 3 2 4 around vertex 0:
    // (1 3 0) (3 2 0) (2 4 0).
    unrolled("StripUnrollsIntoItsTriangles", 5, {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0},
             {0, 1, 2, 3, 4}, {0, 1, 2, 1, 3, 2, 2, 3, 4}),
    unrolled("FanUnrollsIntoItsTriangles", 6, {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, -1, 1, 0},
             {0, 1, 3, 2, 4}, {1, 3, 0, 3, 2, 0, 2, 4, 0}),
    // test_gltf_accessors.cpp has the valid sparse cases.
    {.name = "SparseIndicesMustIncrease",
     .edit =
         [](Doc& d) {
           const int iv = d.view(std::vector<uint16_t>{1, 0});
           const int vv = d.view(std::vector<float>{5, 5, 5, 6, 6, 6});
           d.j["accessors"][0] = accessor(0, kFloat, 3, "VEC3");
           d.j["accessors"][0]["sparse"] =
               json{{"count", 2},
                    {"indices", json{{"bufferView", iv}, {"componentType", kUShort}}},
                    {"values", json{{"bufferView", vv}}}};
         },
     .error = {"POSITION accessor 0 sparse indices are not strictly increasing (index 1 is 0 "
               "after 1)"}},
    {.name = "NanCoordinate",
     .edit =
         [](Doc& d) {
           add_mesh_root(d, "nan", d.vec3s({0, 0, 0, kNan, 0, 0, 0, 1, 0}));
         },
     .error = {"mesh 'nan' has a non-finite vertex coordinate"}},
    {.name = "InfCoordinate",
     .edit =
         [](Doc& d) {
           add_mesh_root(d, "inf", d.vec3s({0, 0, 0, 1, 0, 0, 0, kInf, 0}));
         },
     .error = {"mesh 'inf' has a non-finite vertex coordinate"}},
    {.name = "NanNormal",
     .edit =
         [](Doc& d) {
           const int nor = d.vec3s({0, 0, 1, 0, 0, kNan, 0, 0, 1});
           add_mesh_root(d, "nn", 0, -1, 0, {{"attributes", {{"NORMAL", nor}}}});
         },
     .error = {"mesh 'nn' has a non-finite vertex coordinate"}},
    {.name = "ZeroNormalsAreDroppedWithAWarning",
     .edit =
         [](Doc& d) {
           const int nor = d.vec3s({0, 0, 1, 0, 0, 0, 0, 0, 1});
           add_mesh_root(d, "zn", 0, -1, 0, {{"attributes", {{"NORMAL", nor}}}});
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.meshes.size(), 2u);
           EXPECT_FALSE(s.meshes[0].normals.empty());
           EXPECT_TRUE(s.meshes[1].normals.empty());
           EXPECT_TRUE(has_warning(s, "mesh 'zn': zero or non-finite normals"));
         }},
    {.name = "AbsurdCoordinate",
     .edit =
         [](Doc& d) {
           add_mesh_root(d, "huge", d.vec3s({0, 0, 0, 1e12f, 0, 0, 0, 1, 0}));
         },
     .error = {"mesh 'huge' has a vertex coordinate beyond the limit of 1e10"}},
    {.name = "DegenerateTrianglesAreSkippedAndCounted",
     .edit =
         [](Doc& d) {
           const int pos = d.vec3s({0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 1e-20f, 1e-20f, 0});
           // good, repeated index, collinear, area underflow
           const int ind = d.indices({0, 1, 2, 0, 0, 1, 0, 1, 3, 0, 4, 1});
           set_mesh0(d, "tri", primitive(pos, {{"indices", ind}}));
         },
     .check =
         [](const Scene& s) {
           EXPECT_EQ(s.degenerate_triangles, 3u);
           EXPECT_EQ(s.triangle_count(), 1u);
           EXPECT_TRUE(has_warning(s, "3 degenerate triangles skipped"));
         }},
    {.name = "OnlyDegenerateTrianglesMeansNoTriangles",
     .edit =
         [](Doc& d) {
           set_mesh0(d, "tri", primitive(0, {{"indices", d.indices({0, 0, 1, 2, 2, 2})}}));
         },
     .error = {": no triangles"}},
    // Interleaved POSITION + NORMAL (byteStride 24, two triangles, non-indexed); UNSIGNED_BYTE
    // and UNSIGNED_INT indices.
    {.name = "NonIndexedAndInterleavedAndIndexTypes",
     .edit =
         [](Doc& d) {
           const std::vector<float> data = {0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1,
                                            0, 0, 1, 0, 0, 1, 1, 0, 1, 0, 0, 1, 0, 1, 1, 0, 0, 1};
           const int v = d.view(data, {{"byteStride", 24}});
           const int pos = d.accessor(v, kFloat, 6, "VEC3");
           const int nor = d.accessor(v, kFloat, 6, "VEC3", {{"byteOffset", 12}});
           add_mesh_root(d, "flat", pos, -1, 0, {{"attributes", {{"NORMAL", nor}}}});
           const int i8 = d.accessor(d.view(std::vector<uint8_t>{0, 1, 2}), 5121, 3, "SCALAR");
           add_mesh_root(d, "u8", 0, i8, 0);
           const int i32 = d.accessor(d.view(std::vector<uint32_t>{2, 0, 1}), kUInt, 3, "SCALAR");
           add_mesh_root(d, "u32", 0, i32, 0);
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.meshes.size(), 4u);
           EXPECT_EQ(s.meshes[1].indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
           expect_vec(s.meshes[1].positions[4], vec3(1, 0, 1));
           expect_vec(s.meshes[1].normals[4], vec3(0, 0, 1));
           EXPECT_EQ(s.meshes[2].indices, (std::vector<uint32_t>{0, 1, 2}));
           EXPECT_EQ(s.meshes[3].indices, (std::vector<uint32_t>{2, 0, 1}));
         }},
    // As viewers draw the mesh with no animation playing: weight 1 lifts it by the target's 1
    // (test_gltf_deform.cpp has the rest).
    {.name = "MorphTargetsAreDrawnAtTheMeshsWeights",
     .edit =
         [](Doc& d) {
           const int delta = d.vec3s({0, 0, 1, 0, 0, 1, 0, 0, 1});
           set_mesh0(d, "tri",
                     primitive(0, {{"indices", 2},
                                   {"material", 0},
                                   {"targets", json::array({json{{"POSITION", delta}}})}}));
           d.j["meshes"][0]["weights"] = json::array({1});
         },
     .check =
         [](const Scene& s) {
           EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
           EXPECT_EQ(s.meshes[0].positions[0].z, 1.0f);
         }},
};

using LoaderGeometry = LoaderCaseTest;
TEST_P(LoaderGeometry, Row) { run(); }
INSTANTIATE_TEST_SUITE_P(Table, LoaderGeometry, ::testing::ValuesIn(kRows), case_name);

}  // namespace
}  // namespace pb::test
