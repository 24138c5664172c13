// Morph targets and skins drawn as a glTF viewer draws them with no animation playing: the
// targets at the file's weights (the node's, else the mesh's), before the node's transform; a
// skinned mesh by its joints' global transforms times their inverse bind matrices, blended by
// the vertex weights, its own node's transform ignored. Expected positions are computed here
// from the TRS values written into the file.
#include "gltf_expect.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace {

using namespace pb::test;
using glm::dmat4;
using glm::dvec3;
using pb::Scene;

constexpr int kUByte = 5121;

const std::vector<float> kQuad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<float> kUp = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};

class Deform : public DecodeTest {
 protected:
  // A quad (POSITION, NORMAL +z) with `targets` and, when `extra` has them, more attributes.
  json quad(Doc& d, const json& targets = json(), const json& extra = json::object()) {
    json attributes = json{{"POSITION", d.accessor(d.view(kQuad), kFloat, 4, "VEC3")},
                           {"NORMAL", d.accessor(d.view(kUp), kFloat, 4, "VEC3")}};
    attributes.update(extra);
    json p = json{{"attributes", attributes},
                  {"indices", d.accessor(d.view(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}), kUShort,
                                         6, "SCALAR")}};
    if (!targets.is_null()) p["targets"] = targets;
    return p;
  }
  static void expect_near(const pb::vec3& got, const dvec3& want, double tol = 1e-6) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], tol) << k;
  }
};

TEST_F(Deform, MorphTargetsAreDrawnAtTheFilesWeightsBeforeTheNodesTransform) {
  // Target 0 lifts every corner by 1 in z and tilts the normals; target 1 moves corner 2 by
  // (0.5, 0.5, 0) through a sparse accessor (as exporters write small targets). The mesh's
  // weights (0.5, 0.25) apply unless the node has its own (0, 1).
  for (bool node_weights : {false, true}) {
    Doc d;
    const int lift = d.accessor(d.view(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}),
                                kFloat, 4, "VEC3");
    const int tilt = d.accessor(d.view(std::vector<float>{1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0}),
                                kFloat, 4, "VEC3");
    const json sparse =
        json{{"count", 1},
             {"indices",
              json{{"bufferView", d.view(std::vector<uint8_t>{2})}, {"componentType", kUByte}}},
             {"values", json{{"bufferView", d.view(std::vector<float>{0.5f, 0.5f, 0.0f})}}}};
    const int corner = d.accessor(-1, kFloat, 4, "VEC3", json{{"sparse", sparse}});
    const json targets =
        json::array({json{{"POSITION", lift}, {"NORMAL", tilt}}, json{{"POSITION", corner}}});
    json node = mesh_trs();
    if (node_weights) node["weights"] = {0.0, 1.0};
    d.mesh_node(quad(d, targets), node);
    d.j["meshes"][0]["weights"] = {0.5, 0.25};
    const Scene s = pb::load_gltf(d.write(path("morph.gltf")));
    EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
    const pb::Mesh m = only_mesh(s);
    const double w0 = node_weights ? 0.0 : 0.5, w1 = node_weights ? 1.0 : 0.25;
    for (size_t i = 0; i < 4; ++i) {
      dvec3 p(kQuad[3 * i], kQuad[3 * i + 1], kQuad[3 * i + 2]);
      p += w0 * dvec3(0, 0, 1) + (i == 2 ? w1 * dvec3(0.5, 0.5, 0) : dvec3(0.0));
      expect_near(m.positions[i], world_point(p), 1e-5);
      expect_near(m.normals[i], world_normal(dvec3(0, 0, 1) + w0 * dvec3(1, 0, 0)), 1e-6);
    }
  }
}

TEST_F(Deform, MorphWeightsThatDoNotMatchTheTargetsWarnAndTheMissingOnesAreZero) {
  Doc d;
  const int lift =
      d.accessor(d.view(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}), kFloat, 4, "VEC3");
  d.mesh_node(quad(d, json::array({json{{"POSITION", lift}}, json{{"POSITION", lift}}})),
              json{{"weights", {0.5}}});
  const Scene s = pb::load_gltf(d.write(path("weights.gltf")));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("2 morph targets but 1 weights (node 'grid node')"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_NEAR(only_mesh(s).positions[0].z, 0.5f, 1e-6f);
}

// A two-joint arm: joint 0 at the origin, joint 1 its child, bound at (1, 0, 0) and posed there
// turned 90 degrees about z. The quad's corners 0 and 3 follow joint 0, corner 1 joint 1, and
// corner 2 both, by unnormalised weights (2, 2) that the loader divides by their sum. The
// skinned mesh's node sits at x = 100: viewers ignore that transform, and so must the loader.
struct Arm {
  Doc d;
  explicit Arm(const json& extra_skin = json::object(), bool ibm = true) {
    const int joints =
        d.accessor(d.view(std::vector<uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0}),
                   kUByte, 4, "VEC4");
    const int weights =
        d.accessor(d.view(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 2, 2, 0, 0, 1, 0, 0, 0}),
                   kFloat, 4, "VEC4");
    json prim = json{{"attributes", json{{"POSITION", d.accessor(d.view(kQuad), kFloat, 4, "VEC3")},
                                         {"NORMAL", d.accessor(d.view(kUp), kFloat, 4, "VEC3")},
                                         {"JOINTS_0", joints},
                                         {"WEIGHTS_0", weights}}},
                     {"indices", d.accessor(d.view(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}),
                                            kUShort, 6, "SCALAR")}};
    d.mesh_node(prim, json{{"translation", {100.0, 0.0, 0.0}}, {"skin", 0}});
    const double s = std::sqrt(0.5);
    const int j0 = d.add("nodes", json{{"name", "shoulder"}});
    d.j["nodes"][size_t(j0)]["children"] = {j0 + 1};
    d.add(
        "nodes",
        json{{"name", "elbow"}, {"translation", {1.0, 0.0, 0.0}}, {"rotation", {0.0, 0.0, s, s}}});
    d.j["scenes"][0]["nodes"].push_back(j0);
    json skin = json{{"joints", {j0, j0 + 1}}};
    if (ibm) {
      // Column-major: identity, and the inverse of the elbow's bind pose, translate(-1, 0, 0).
      const std::vector<float> m = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0,  0, 0, 1,
                                    1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1};
      skin["inverseBindMatrices"] = d.accessor(d.view(m), kFloat, 2, "MAT4");
    }
    skin.update(extra_skin);
    d.j["skins"] = json::array({skin});
  }
};

TEST_F(Deform, ASkinnedMeshIsPlacedByItsJointsNotItsNode) {
  Arm arm;
  const Scene s = pb::load_gltf(arm.d.write(path("arm.gltf")));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const pb::Mesh m = only_mesh(s);
  // elbow = translate(1, 0, 0) rotate_z(90): its joint matrix is that times translate(-1, 0, 0).
  const dmat4 elbow =
      glm::rotate(glm::translate(dmat4(1.0), dvec3(1, 0, 0)), M_PI / 2, dvec3(0, 0, 1)) *
      glm::translate(dmat4(1.0), dvec3(-1, 0, 0));
  const auto at = [](const dmat4& x, const dvec3& p) { return dvec3(x * glm::dvec4(p, 1.0)); };
  expect_near(m.positions[0], dvec3(0, 0, 0));
  expect_near(m.positions[1], at(elbow, dvec3(1, 0, 0)));  // the elbow's pivot: (1, 0, 0)
  expect_near(m.positions[2], 0.5 * (dvec3(1, 1, 0) + at(elbow, dvec3(1, 1, 0))));
  expect_near(m.positions[3], dvec3(0, 1, 0));
  EXPECT_NEAR(m.positions[2].x, 0.5f, 1e-6f);  // (1, 1, 0) and (0, 0, 0): halfway
  for (size_t i = 0; i < 4; ++i) expect_near(m.normals[i], dvec3(0, 0, 1));
  // Without inverse bind matrices (identity) the elbow's matrix is its pose alone.
  const pb::Mesh bare =
      only_mesh(pb::load_gltf(Arm(json::object(), false).d.write(path("b.gltf"))));
  expect_near(bare.positions[1],
              at(glm::rotate(glm::translate(dmat4(1.0), dvec3(1, 0, 0)), M_PI / 2, dvec3(0, 0, 1)),
                 dvec3(1, 0, 0)));
}

TEST_F(Deform, BadSkinsAreRefusedNamingTheFileAndTheirFault) {
  Arm out_of_range;
  out_of_range.d.j["skins"][0]["joints"] = {3};  // one joint: corner 1 names joint 1
  expect_error(out_of_range.d.write(path("range.gltf")),
               "JOINTS_0 vertex 1 names joint 1 of skin 0, which has 1");
  Arm few;
  few.d.j["accessors"][few.d.j["skins"][0]["inverseBindMatrices"].get<size_t>()]["count"] = 1;
  expect_error(few.d.write(path("few.gltf")), "skin 0 has 1 inverse bind matrices for 2 joints");
  Arm missing;
  missing.d.j["nodes"][2]["skin"] = 4;
  expect_error(missing.d.write(path("missing.gltf")), "refers to skin 4, which does not exist");
}

TEST_F(Deform, UnweightedVerticesAndUnboundMeshesFollowTheirNodeWithAWarning) {
  Arm zero;
  const size_t w = zero.d.j["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"];
  const std::vector<float> weights = {1, 0, 0, 0, 0, 0, 0, 0, 2, 2, 0, 0, 1, 0, 0, 0};
  zero.d.j["accessors"][w]["bufferView"] = zero.d.view(weights);
  const Scene s = pb::load_gltf(zero.d.write(path("zero.gltf")));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            "1 skinned vertices have no joint weight (mesh 'grid' primitive 0 vertex 1 the "
            "first): they follow their node's transform");
  expect_near(only_mesh(s).positions[1], dvec3(101, 0, 0));
  Arm unbound;
  auto& attributes = unbound.d.j["meshes"][0]["primitives"][0]["attributes"];
  attributes.erase("JOINTS_0");
  attributes.erase("WEIGHTS_0");
  const Scene u = pb::load_gltf(unbound.d.write(path("unbound.gltf")));
  ASSERT_EQ(u.warnings.size(), 1u);
  EXPECT_EQ(u.warnings[0],
            "mesh 'grid' primitive 0 has no JOINTS_0 and WEIGHTS_0 to bind it to skin 0; it is "
            "drawn by its node's transform");
  expect_near(only_mesh(u).positions[1], dvec3(101, 0, 0));
}

// EXT_mesh_gpu_instancing: the quad under mesh_trs() drawn twice, at node x T R S of each
// instance: the first at the node itself, the second moved by (5, 0, 0), turned 90 degrees about
// z (a quaternion stored as normalised shorts, as gltfpack writes it) and scaled by 2.
TEST_F(Deform, InstancesAreTheMeshAtTheNodeTimesTheirOwnTransforms) {
  Doc d;
  d.mesh_node(quad(d), mesh_trs());
  const int t = d.accessor(d.view(std::vector<float>{0, 0, 0, 5, 0, 0}), kFloat, 2, "VEC3");
  const int r = d.accessor(d.view(std::vector<int16_t>{0, 0, 0, 32767, 0, 0, 23170, 23170}), kShort,
                           2, "VEC4", json{{"normalized", true}});
  const int s = d.accessor(d.view(std::vector<float>{1, 1, 1, 2, 2, 2}), kFloat, 2, "VEC3");
  d.j["nodes"][2]["extensions"] =
      json{{"EXT_mesh_gpu_instancing",
            json{{"attributes", json{{"TRANSLATION", t}, {"ROTATION", r}, {"SCALE", s}}}}}};
  d.require({"EXT_mesh_gpu_instancing", "KHR_mesh_quantization"});
  const Scene scene = pb::load_gltf(d.write(path("instances.gltf")));
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  ASSERT_EQ(scene.meshes.size(), 2u);
  const dmat4 second =
      glm::scale(glm::rotate(glm::translate(dmat4(1.0), dvec3(5, 0, 0)), M_PI / 2, dvec3(0, 0, 1)),
                 dvec3(2.0));
  for (size_t i = 0; i < 4; ++i) {
    const dvec3 p(kQuad[3 * i], kQuad[3 * i + 1], kQuad[3 * i + 2]);
    expect_near(scene.meshes[0].positions[i], world_point(p), 1e-5);
    // 23170 / 32767 is sqrt(1/2) to 1e-5: the turn is 90 degrees to that, renormalised.
    expect_near(scene.meshes[1].positions[i], world_point(dvec3(second * glm::dvec4(p, 1.0))),
                1e-4);
  }
}

TEST_F(Deform, BadInstancesAreRefusedNamingTheFileAndTheirFault) {
  const auto with = [&](const json& attributes, const char* name, uint32_t indices = 6) {
    Doc d;
    json prim = quad(d);
    if (indices != 6)
      prim["indices"] = d.accessor(d.view(std::vector<uint16_t>(6, 0)), kUShort, indices, "SCALAR");
    d.mesh_node(prim, json::object());
    json a = json::object();
    for (const auto& [key, values] : attributes.items()) {
      const std::vector<float> v = values.get<std::vector<float>>();
      const bool rotation = key == "ROTATION";
      a[key] =
          d.accessor(d.view(v), kFloat, v.size() / (rotation ? 4 : 3), rotation ? "VEC4" : "VEC3");
    }
    d.j["nodes"][2]["extensions"] = json{{"EXT_mesh_gpu_instancing", json{{"attributes", a}}}};
    return d.write(path(name));
  };
  expect_error(with(json{{"TRANSLATION", {0, 0, 0, 1, 0, 0}}, {"SCALE", {1, 1, 1}}}, "n.gltf"),
               "EXT_mesh_gpu_instancing has 1 SCALE values and 2 of another attribute");
  expect_error(with(json{{"ROTATION", {0, 0, 0, 0}}}, "q.gltf"),
               "EXT_mesh_gpu_instancing ROTATION 0 is a zero or non-finite quaternion");
  // The copies are counted before any is made (the indices accessor's count is enough).
  expect_error(with(json{{"TRANSLATION", {0, 0, 0, 1, 0, 0, 2, 0, 0}}}, "big.gltf", 3u << 25),
               "asks for 3 copies of mesh 'grid' (33554432 triangles each): instancing would "
               "hold more than 67108864 triangles");
}

}  // namespace
