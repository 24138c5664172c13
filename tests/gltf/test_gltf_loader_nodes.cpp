// glTF loader tests: nodes and transforms, scenes, cameras and KHR_lights_punctual lights. Each
// row edits gltf_expect.h's triangle_doc() and expects a one-line SceneError or a loaded Scene.
#include "gltf_expect.h"

#include "lights/lights.h"
#include "render/camera_choice.h"
#include "render/scene_defaults.h"

#include <cmath>

namespace pb::test {
namespace {

const double kH = std::sqrt(0.5);  // cos and sin of 45 degrees: quaternions of 90 degrees

json spot(double inner, double outer) {
  return json{{"type", "spot"},
              {"spot", json{{"innerConeAngle", inner}, {"outerConeAngle", outer}}}};
}

// Camera 1, orthographic, under a new root node (3).
void add_ortho_camera(Doc& d) {
  const json ortho = json{{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}};
  d.add("cameras", json{{"name", "ortho"}, {"type", "orthographic"}, {"orthographic", ortho}});
  add_root(d, json{{"camera", 1}});
}

const std::vector<LoaderCase> kRows = {
    // parent: T(10,0,0) * R(90 deg about z) * S(2); child: matrix T(1,0,0) (column-major).
    {.name = "HierarchyComposesTrsAndMatrix",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"mesh", 0}};
           d.add("nodes", json{{"translation", {10, 0, 0}},
                               {"rotation", {0, 0, kH, kH}},
                               {"scale", {2, 2, 2}},
                               {"children", {4}}});
           d.add("nodes", json{{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1}},
                               {"mesh", 0},
                               {"children", {5}}});
           d.add("nodes", json{{"camera", 0}});
           set_roots(d, {1, 2, 3});
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.meshes.size(), 1u);
           const Mesh& m = s.meshes[0];
           // local (0,0,0) -> (1,0,0) -> (2,0,0) -> (0,2,0) -> (10,2,0); (1,0,0) -> (10,4,0).
           expect_vec(m.positions[0], vec3(10, 2, 0), 1e-4f);
           expect_vec(m.positions[1], vec3(10, 4, 0), 1e-4f);
           expect_vec(m.positions[2], vec3(8, 2, 0), 1e-4f);
           expect_vec(m.normals[0], vec3(0, 0, 1));
           ASSERT_EQ(s.cameras.size(), 2u);
           const Camera& c = s.cameras[1];  // node 5, under the rotated parent
           expect_vec(c.position, vec3(10, 2, 0), 1e-4f);
           expect_vec(c.forward, vec3(0, 0, -1));
           expect_vec(c.up, vec3(-1, 0, 0));
           expect_vec(c.right, vec3(0, 1, 0));
         }},
    // The plane x + y = 1 has normal (1,1,0)/sqrt2; scaling y by 2 makes it (1,0.5,0)/|.|.
    {.name = "NormalsUseTheInverseTranspose",
     .edit =
         [](Doc& d) {
           const int pos = d.vec3s({1, 0, 0, 0, 1, 0, 1, 0, 1});
           const float r = std::sqrt(0.5f);
           const int nor = d.vec3s({r, r, 0, r, r, 0, r, r, 0});
           const json prim = json{{"attributes", json{{"POSITION", pos}, {"NORMAL", nor}}}};
           d.j["meshes"][0] = json{{"name", "slant"}, {"primitives", json::array({prim})}};
           d.j["nodes"][0] = json{{"mesh", 0}, {"scale", {1, 2, 1}}};
         },
     .check =
         [](const Scene& s) {
           expect_vec(s.meshes[0].positions[1], vec3(0, 2, 0));
           expect_vec(s.meshes[0].normals[2], glm::normalize(vec3(1, 0.5f, 0)));
         }},
    {.name = "NegativeDeterminantFlipsWinding",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"mesh", 0}, {"scale", {-1, 1, 1}}};
         },
     .check =
         [](const Scene& s) {
           const Mesh& m = s.meshes[0];
           EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 2, 1}));
           expect_vec(m.positions[1], vec3(-1, 0, 0));
           expect_vec(face_normal(m, 0), vec3(0, 0, 1));  // the front side still faces +z
           expect_vec(m.normals[0], vec3(0, 0, 1));
         }},
    {.name = "AbsurdCoordinateAfterTransform",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"mesh", 0}, {"scale", {1e11, 1e11, 1e11}}};
         },
     .error = {"mesh 'tri' has a vertex coordinate beyond the limit of 1e10"}},
    {.name = "SingularTransform",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"name", "flat"}, {"mesh", 0}, {"scale", {1, 1, 0}}};
         },
     .error = {"node 'flat' has a singular transform"}},
    // Node matrices that are not TRS (glTF 2.0 "Transformations"; issue 36). A mirror given as a
    // matrix (x and y swapped, determinant -1) maps the triangle onto itself with the opposite
    // winding: the corners are swapped back, the front still faces +z.
    {.name = "MatrixMirrorFlipsWinding",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] =
               json{{"mesh", 0}, {"matrix", {0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
         },
     .check =
         [](const Scene& s) {
           const Mesh& m = s.meshes[0];
           EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 2, 1}));
           expect_vec(m.positions[1], vec3(0, 1, 0));
           expect_vec(face_normal(m, 0), vec3(0, 0, 1));
           expect_vec(m.normals[0], vec3(0, 0, 1));
           EXPECT_TRUE(s.warnings.empty());
         }},
    // Shear z' = z + x: (1,0,0) rises to (1,0,1), and the normal is the inverse transpose's,
    // (-1,0,1)/sqrt2, the new plane's. Rendered as given, with a warning (glTF wants TRS).
    {.name = "MatrixShearIsRenderedAsItsAffineMapWithAWarning",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"name", "skew"},
                                  {"mesh", 0},
                                  {"matrix", {1, 0, 1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
         },
     .check =
         [](const Scene& s) {
           const Mesh& m = s.meshes[0];
           expect_vec(m.positions[1], vec3(1, 0, 1));
           expect_vec(m.normals[0], glm::normalize(vec3(-1, 0, 1)));
           expect_vec(face_normal(m, 0), glm::normalize(vec3(-1, 0, 1)));
           ASSERT_EQ(s.warnings.size(), 1u);
           EXPECT_NE(s.warnings[0].find("node 'skew''s matrix shears"), std::string::npos)
               << s.warnings[0];
         }},
    {.name = "MatrixSingular",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"name", "flat"},
                                  {"mesh", 0},
                                  {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}}};
         },
     .error = {"node 'flat' has a singular transform (determinant 0)"}},
    {.name = "MatrixAllZero",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] =
               json{{"name", "gone"}, {"mesh", 0}, {"matrix", std::vector<int>(16, 0)}};
         },
     .error = {"node 'gone' has a matrix whose last row is (0, 0, 0, 0), not (0, 0, 0, 1)"}},
    {.name = "MatrixProjective",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"name", "persp"},
                                  {"mesh", 0},
                                  {"matrix", {1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
         },
     .error = {"node 'persp' has a matrix whose last row is (0.5, 0, 0, 1), not (0, 0, 0, 1)"}},
    // Finite matrices whose product is not: 1e150 x 1e150 overflows (the check squares each
    // column: 1e150 alone passes).
    {.name = "MatrixProductNotFinite",
     .edit =
         [](Doc& d) {
           const json huge = {1e150, 0, 0, 0, 0, 1e150, 0, 0, 0, 0, 1e150, 0, 0, 0, 0, 1};
           d.j["nodes"][0] = json{{"name", "outer"}, {"matrix", huge}, {"children", {3}}};
           d.add("nodes", json{{"name", "inner"}, {"mesh", 0}, {"matrix", huge}});
         },
     .error = {"node 'inner' has a non-finite transform"}},
    {.name = "NodeCycle",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"name", "loop"}, {"mesh", 0}, {"children", {0}}};
         },
     .error = {"node 'loop' is reached twice"}},
    {.name = "NoScenesUsesEveryRootNode",
     .edit =
         [](Doc& d) {
           d.j.erase("scene");
           d.j.erase("scenes");
           d.add("nodes", json{{"translation", {0, 0, 1}}, {"children", {0}}});  // 0 is a child
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.meshes.size(), 1u);
           expect_vec(s.meshes[0].positions[1], vec3(1, 0, 1));
           EXPECT_EQ(s.cameras.size(), 1u);
           EXPECT_EQ(s.lights.size(), 1u);
         }},
    {.name = "ExcessiveDepth",
     .edit =
         [](Doc& d) {
           const int first = int(d.j["nodes"].size());
           for (int i = 0; i < 1100; ++i) add_root(d, json{{"children", {first + i + 1}}});
           add_root(d, json{{"mesh", 0}});
         },
     .error = {"the node hierarchy is deeper than 1000 levels"}},
    {.name = "MeshIndexOutOfRange",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"name", "geometry"}, {"mesh", 4}};
         },
     .error = {"node 'geometry' refers to mesh 4, which does not exist (the file has 1 mesh)"}},
    {.name = "MeshIndexOutOfRangeCountsTheMeshes",
     .edit =
         [](Doc& d) {
           d.j["nodes"][0] = json{{"name", "geometry"}, {"mesh", 4}};
           add_mesh(d, "second", 0);
         },
     .error = {"(the file has 2 meshes)"}},
    // No camera is not an error: the render frames the bounds (camera_choice.h).
    {.name = "NoCamera",
     .edit =
         [](Doc& d) {
           set_roots(d, {0, 2});
         },
     .check =
         [](const Scene& s) {
           EXPECT_TRUE(s.cameras.empty());
           EXPECT_EQ(s.lights.size(), 1u);
         }},
    {.name = "OrthographicCameraIsSkipped",
     .edit = [](Doc& d) { add_ortho_camera(d); },
     .check =
         [](const Scene& s) {
           EXPECT_EQ(s.cameras.size(), 1u);
           EXPECT_TRUE(has_warning(s, "camera 'ortho' is orthographic and is skipped"));
         }},
    {.name = "OrthographicCameraAloneIsNoCamera",
     .edit =
         [](Doc& d) {
           add_ortho_camera(d);
           set_roots(d, {0, 2, 3});
         },
     .check = [](const Scene& s) { EXPECT_TRUE(s.cameras.empty()); }},
    {.name = "InvalidYfov",
     .edit =
         [](Doc& d) {
           d.j["cameras"][0] =
               json{{"type", "perspective"}, {"perspective", json{{"yfov", 3.5}, {"znear", 0.1}}}};
         },
     .error = {"camera 0: yfov 3.5 must be in (0, pi)"}},
    {.name = "SpotLightDirectionAndCones",
     .edit =
         [](Doc& d) {
           light0(d) = spot(0.2, 0.5);
           light0(d)["intensity"] = 3;
           // 90 degrees about x: local -z becomes world +y
           d.j["nodes"][2] = json{{"rotation", {kH, 0, 0, kH}}, {"extensions", light_ext(0)}};
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.lights.size(), 1u);
           const PunctualLight& l = s.lights[0];
           EXPECT_EQ(l.kind, PunctualKind::Spot);
           EXPECT_EQ(l.name, "light 0");
           expect_vec(l.direction, vec3(0, 1, 0));
           expect_vec(l.intensity, vec3(3));
           EXPECT_NEAR(l.cos_inner, std::cos(0.2f), 1e-6f);
           EXPECT_NEAR(l.cos_outer, std::cos(0.5f), 1e-6f);
         }},
    {.name = "EmissiveTrianglesAloneLightTheScene",
     .edit =
         [](Doc& d) {
           material0(d) = json{{"emissiveFactor", {1, 1, 1}},
                               {"pbrMetallicRoughness", json{{"metallicFactor", 0}}}};
           set_roots(d, {0, 1});
         },
     .check =
         [](const Scene& s) {
           EXPECT_TRUE(s.lights.empty());
           EXPECT_TRUE(s.materials[s.meshes[0].material].emits());
         }},
    // No light is not an error either: the render adds the default sky (scene_defaults.h).
    {.name = "NoLight",
     .edit =
         [](Doc& d) {
           set_roots(d, {0, 1});
         },
     .check =
         [](const Scene& s) {
           EXPECT_TRUE(s.lights.empty());
           EXPECT_FALSE(has_light(s));
         }},
    {.name = "ZeroIntensityLightIsNoLight",
     .edit =
         [](Doc& d) {
           light0(d) = json{{"type", "point"}, {"intensity", 0}};
         },
     .check =
         [](const Scene& s) {
           EXPECT_EQ(s.lights.size(), 1u);
           EXPECT_FALSE(has_light(s));
         }},
    // Directional: light travels along the node's -Z; color x intensity is the irradiance on a
    // surface facing it; position and range do not apply. Rotated 90 degrees about +X: local -Z
    // becomes world -Y (straight down).
    {.name = "DirectionalLight",
     .edit =
         [](Doc& d) {
           light0(d) = json{{"name", "sun"},
                            {"type", "directional"},
                            {"color", {1, 0.5, 0.25}},
                            {"intensity", 4}};
           d.j["nodes"][2] = json{{"name", "lamp"},
                                  {"translation", {5, 6, 7}},
                                  {"rotation", {-0.7071067811865476, 0, 0, 0.7071067811865476}},
                                  {"extensions", light_ext(0)}};
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.lights.size(), 1u);
           EXPECT_EQ(s.lights[0].kind, PunctualKind::Directional);
           expect_vec(s.lights[0].direction, vec3(0, -1, 0));
           expect_vec(s.lights[0].intensity, vec3(4, 2, 1));
           EXPECT_TRUE(s.warnings.empty());
         }},
    {.name = "NegativeIntensity",
     .edit =
         [](Doc& d) {
           light0(d) = json{{"name", "dark"}, {"type", "point"}, {"intensity", -1}};
         },
     .error = {"light 'dark': intensity and color must be finite and >= 0"}},
    // Each intensity fits in a float; their total power (4 pi I per light) does not.
    {.name = "PowerBeyondFloatRange",
     .edit =
         [](Doc& d) {
           light0(d) = json{{"name", "flood"}, {"type", "point"}, {"intensity", 3e38}};
         },
     .error = {"the lights emit", "beyond the float range"}},
    // 1e30, the extremes suite's brightest emitter, still loads.
    {.name = "PowerOfTheBrightestExtremeLoads",
     .edit =
         [](Doc& d) {
           light0(d) = json{{"name", "bright"}, {"type", "point"}, {"intensity", 1e30}};
         },
     .check = [](const Scene& s) { EXPECT_EQ(s.lights.size(), 1u); }},
    {.name = "LightIndexOutOfRange",
     .edit =
         [](Doc& d) {
           d.j["nodes"][2] = json{{"name", "lamp"}, {"extensions", light_ext(3)}};
         },
     .error = {"node 'lamp' refers to light 3, which does not exist"}},
    {.name = "SpotInnerConeBeyondOuterIsRefused",
     .edit = [](Doc& d) { light0(d) = spot(0.6, 0.5); },
     .error = {"spot cone angles inner 0.6, outer 0.5 must satisfy 0 <= inner < outer <= pi/2"}},
    {.name = "SpotOuterConeBeyondHalfPiIsRefused",
     .edit =
         [](Doc& d) {
           light0(d) = json{{"type", "spot"}, {"spot", json{{"outerConeAngle", 2}}}};
         },
     .error = {"must satisfy 0 <= inner < outer <= pi/2"}},
};

using LoaderNodes = LoaderCaseTest;
TEST_P(LoaderNodes, Row) { run(); }
INSTANTIATE_TEST_SUITE_P(Table, LoaderNodes, ::testing::ValuesIn(kRows), case_name);

// Geo-referenced content lies millions of units from the origin (3D Tiles in ECEF: 4e6 m) where a
// float's step is 0.25-0.5: a 0.1-unit triangle there collapses. The loader centres such a model
// in double precision (Scene::origin), cameras, lights and --look-from / --look-at with it.
TEST_F(LoaderTest, AModelFarFromTheOriginIsCentredBeforeItIsRoundedToFloat) {
  // triangle_doc() with a 0.1-unit triangle (and the min / max glTF requires of POSITION) under a
  // parent node translated by t.
  auto placed = [](const glm::dvec3& t) {
    Doc d = triangle_doc();
    d.j["accessors"][0] =
        json{{"bufferView", d.view(std::vector<float>{0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0})},
             {"componentType", kFloat},
             {"count", 3},
             {"type", "VEC3"},
             {"min", {0, 0, 0}},
             {"max", {0.1, 0.1, 0}}};
    d.add("nodes", json{{"translation", {t.x, t.y, t.z}}, {"children", {0, 1, 2}}});
    set_roots(d, {3});
    return d;
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
  RenderOptions o;
  o.look_from = std::array<double, 3>{shift.x, shift.y, shift.z + 3};
  o.look_at = std::array<double, 3>{shift.x + 0.05, shift.y + 0.05, shift.z};
  const PinholeCamera cam = choose_camera(s, o);
  EXPECT_LT(glm::length(glm::dvec3(cam.origin()) + s.origin - (shift + glm::dvec3(0, 0, 3))), 1e-6);
  expect_vec(cam.camera().forward, vec3(0.05f, 0.05f, -3.0f) / std::sqrt(9.005f), 1e-6f);
  // At 64 sizes from the origin or closer nothing moves: ordinary files keep their coordinates.
  EXPECT_EQ(load(placed(glm::dvec3(5, 2, 0))).origin, glm::dvec3(0.0));
}

}  // namespace
}  // namespace pb::test
