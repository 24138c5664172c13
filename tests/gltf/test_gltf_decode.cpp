// Compressed glTF geometry: KHR_draco_mesh_compression and EXT_meshopt_compression. Each test
// encodes the grid of gltf_fixture.h with the library's own encoder, writes a .gltf or .glb,
// loads it and compares with the uncompressed grid, within tolerances derived from the
// quantisation it asked for; malformed compressed data must give a one-line SceneError.
#include "gltf_expect.h"

#include <cmath>

namespace {

using namespace pb::test;
using pb::Scene;

double range(const std::vector<float>& v) {  // Draco quantises over the largest extent
  double lo[2] = {1e30, 1e30}, hi[2] = {-1e30, -1e30}, r = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    lo[i % 2] = std::min(lo[i % 2], double(v[i]));
    hi[i % 2] = std::max(hi[i % 2], double(v[i]));
  }
  for (int c = 0; c < 2; ++c) r = std::max(r, hi[c] - lo[c]);
  return r;
}

TEST_F(DecodeTest, DracoRoundTripsTheGrid) {
  const Grid g = make_grid(17);
  const DracoIds ids;
  const DracoBits bits;
  const std::vector<unsigned char> enc = draco_encode(g, ids, bits);
  // Quantisation to q bits over a range r errs by at most r / (2^q - 1) / 2 per component.
  // Octahedral normals (Draco: q bits per octahedron coordinate in [-1, 1]): a coordinate error
  // e moves the unnormalised vector by <= sqrt(6) e and its direction by <= sqrt(3) times that.
  Tolerance tol;
  const auto step = [](double r, int q) { return r / double((1 << q) - 1); };
  tol.position = kPositionGain * std::sqrt(3.0) * 0.5 * step(2.0, bits.position) + 1e-5;
  tol.normal = kNormalGain * std::sqrt(18.0) * 0.5 * step(2.0, bits.normal) + 1e-5;
  tol.uv0 = 0.5 * step(range(g.uv0), bits.texcoord) + 1e-6;
  tol.uv1 = 0.5 * step(range(g.uv1), bits.texcoord) + 1e-6;
  for (const char* name : {"draco.gltf", "draco.glb"}) {
    Doc d;
    d.require({"KHR_draco_mesh_compression"});
    d.mesh_node(draco_primitive(d, g, d.view(enc), ids, g.vertices()));
    const Scene s = pb::load_gltf(d.write(path(name)));
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    expect_grid(only_mesh(s), g, tol, false);
  }
}

TEST_F(DecodeTest, DracoAttributeIdsAreTheExtensionsNotTheOrder) {
  const Grid g = make_grid(5);
  DracoIds swapped;  // the two TEX_COORD attributes named the other way round
  const std::vector<unsigned char> enc = draco_encode(g, DracoIds{}, DracoBits{});
  std::swap(swapped.uv0, swapped.uv1);
  Doc d;
  d.mesh_node(draco_primitive(d, g, d.view(enc), swapped, g.vertices()));
  const pb::Mesh& m = only_mesh(pb::load_gltf(d.write(path("swapped.gltf"))));
  // Vertex i of the loaded mesh is matched by position; its TEXCOORD_0 is the grid's uv1.
  for (size_t i = 0; i < m.positions.size(); ++i)
    for (size_t k = 0; k < g.vertices(); ++k)
      if (glm::length(glm::dvec3(m.positions[i]) -
                      world_point({g.positions[3 * k], g.positions[3 * k + 1],
                                   g.positions[3 * k + 2]})) < 1e-3) {
        EXPECT_NEAR(m.texcoords[0][i].x, g.uv1[2 * k], 2e-3);
        EXPECT_NEAR(m.texcoords[1][i].x, g.uv0[2 * k], 2e-3);
      }
}

TEST_F(DecodeTest, MalformedDracoIsASceneError) {
  const Grid g = make_grid(9);
  std::vector<unsigned char> enc = draco_encode(g, DracoIds{}, DracoBits{});
  {
    Doc d;
    std::vector<unsigned char> half(enc.begin(), enc.begin() + long(enc.size() / 2));
    d.mesh_node(draco_primitive(d, g, d.view(half), DracoIds{}, g.vertices()));
    expect_error(d.write(path("truncated.glb")),
                 "mesh 'grid' primitive 0 KHR_draco_mesh_compression: the Draco data cannot be "
                 "decoded");
  }
  {
    Doc d;
    DracoIds wrong;
    wrong.normal = 42;
    d.mesh_node(draco_primitive(d, g, d.view(enc), wrong, g.vertices()));
    expect_error(d.write(path("id.gltf")), "Draco attribute 42 is not in the compressed data");
  }
}

// Accessor counts that differ from the decoded points (COLLADA2GLTF writes the uncompressed
// count: Cesium's milk truck says 1856 where Draco decodes 1886): the faces index the decoded
// points, so the mesh is the decoded one, equal to the uncompressed grid, with one warning.
TEST_F(DecodeTest, DracoAccessorCountsThatDifferFromTheDecodedDataWarn) {
  const Grid g = make_grid(9);
  const std::vector<unsigned char> enc = draco_encode(g, DracoIds{}, DracoBits{});
  for (size_t declared : {g.vertices() + 1, g.vertices() - 5}) {
    Doc d;
    d.mesh_node(draco_primitive(d, g, d.view(enc), DracoIds{}, declared));
    const Scene s = pb::load_gltf(d.write(path("count.gltf")));
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_EQ(s.warnings[0],
              "4 Draco-compressed accessors' counts differ from the decoded data "
              "(mesh 'grid' primitive 0 POSITION accessor 0 has count " +
                  std::to_string(declared) +
                  ", the Draco data 81 points): the decoded data is used, as "
                  "the faces index it");
    Tolerance tol;  // as DracoRoundTripsTheGrid's, loosely: 14-bit positions, 10-bit normals
    tol.position = 2e-3;
    tol.normal = 2e-2;
    tol.uv0 = tol.uv1 = 2e-3;
    expect_grid(only_mesh(s), g, tol, false);
  }
}

TEST_F(DecodeTest, MeshoptRoundTripsTheGridWithAFallbackBuffer) {
  const Grid g = make_grid(17);
  Tolerance tol;
  // Octahedral: K-bit coordinates (error 0.5 / (2^(K-1) - 1) each, moved <= sqrt(18) times that
  // on the sphere), then stored as 16-bit normalised (0.5 / 32767 per component).
  const double oct = 0.5 / double((1 << (MeshoptGrid::kOctBits - 1)) - 1);
  tol.normal = kNormalGain * (std::sqrt(18.0) * oct + std::sqrt(3.0) * 0.5 / 32767) + 1e-5;
  // Exponential: a shared exponent with a K-bit signed mantissa errs by half its unit, at most
  // max |component| / 2^(K-1).
  tol.uv0 = 1.0 / double(1 << (MeshoptGrid::kExpBits - 1)) + 1e-7;
  for (bool tagged : {true, false})
    for (const char* name : {"meshopt.gltf", "meshopt.glb"}) {
      MeshoptGrid mg(g, tagged);
      mg.d.mesh_node(mg.prim);
      const Scene s = pb::load_gltf(mg.d.write(path(name)));
      EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
      expect_grid(only_mesh(s), g, tol, true);
    }
}

TEST_F(DecodeTest, MeshoptIndexSequenceAndQuaternionFilter) {
  // Unit quaternions as the positions of a point grid (SHORT normalised, stride 8, QUATERNION
  // filter at 12 bits): the loaded POSITION must be their xyz. Indices as a 16-bit INDICES stream.
  const size_t n = 9;
  std::vector<float> q;
  for (size_t k = 0; k < n; ++k) {
    const double a = 0.3 + 0.7 * double(k), b = 0.2 * double(k);
    q.insert(q.end(), {float(std::sin(a) * std::cos(b)), float(std::sin(a) * std::sin(b)),
                       float(std::cos(a) * 0.6), float(std::cos(a) * 0.8)});
  }
  std::vector<int16_t> enc(4 * n);
  meshopt_encodeFilterQuat(enc.data(), n, 8, 12, q.data());
  const std::vector<uint32_t> tri = {0, 1, 4, 1, 2, 5, 3, 4, 7, 4, 5, 8, 0, 4, 3};
  Doc d;
  d.require({"EXT_meshopt_compression"});
  const int pos =
      d.meshopt_view(meshopt_vertices(enc.data(), n, 8), n, 8, "ATTRIBUTES", "QUATERNION");
  const int idx = d.meshopt_view(meshopt_sequence(tri, n), tri.size(), 2, "INDICES", "NONE", false);
  d.mesh_node(
      json{{"attributes",
            json{{"POSITION", d.accessor(pos, kShort, n, "VEC3", json{{"normalized", true}})}}},
           {"indices", d.accessor(idx, kUShort, tri.size(), "SCALAR")}},
      json::object());
  const pb::Mesh& m = only_mesh(pb::load_gltf(d.write(path("quat.glb"))));
  ASSERT_EQ(m.positions.size(), n);
  // The filter stores the three smallest components (12 bits each over [-1/sqrt(2), 1/sqrt(2)]:
  // 0.5 / 2047 / sqrt(2) each) and rebuilds the largest as sqrt(1 - the others squared), which
  // is at least 1/2: its error is at most 3 x 0.00017 / (1/2) = 0.001; 16-bit storage adds
  // 0.5 / 32767. q and -q are one rotation: the filter keeps the sign that makes the largest
  // component positive.
  for (size_t k = 0; k < n; ++k) {
    size_t big = 0;
    for (size_t c = 1; c < 4; ++c)
      if (std::abs(q[4 * k + c]) > std::abs(q[4 * k + big])) big = c;
    const float sign = q[4 * k + big] < 0 ? -1.0f : 1.0f;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.positions[k][c], sign * q[4 * k + size_t(c)], 2e-3);
  }
  EXPECT_EQ(m.indices, tri);
}

TEST_F(DecodeTest, MalformedMeshoptIsASceneError) {
  const Grid g = make_grid(5);
  const auto bad = [&](const char* name, auto&& edit, const std::string& phrase) {
    MeshoptGrid mg(g, true);
    edit(mg);
    mg.d.mesh_node(mg.prim);
    expect_error(mg.d.write(path(name)), phrase);
  };
  bad(
      "count.gltf", [](MeshoptGrid& mg) { mg.ext(0)["count"] = 26; },
      "bufferView 0 (of mesh 'grid' primitive 0 POSITION accessor 0) EXT_meshopt_compression: "
      "count x byteStride (26 x 12) is not the bufferView's byteLength (300)");
  bad(
      "stride.glb", [](MeshoptGrid& mg) { mg.ext(0)["byteStride"] = 16; },
      "has byteStride 12 but its EXT_meshopt_compression byteStride is 16");
  bad(
      "filter-stride.gltf", [](MeshoptGrid& mg) { mg.ext(0)["filter"] = "QUATERNION"; },
      "this filter cannot decode a byteStride of 12");
  bad(
      "truncated.glb",
      [](MeshoptGrid& mg) { mg.ext(0)["byteLength"] = mg.ext(0)["byteLength"].get<int>() - 8; },
      "EXT_meshopt_compression: the compressed data is malformed");
  bad(
      "mode.gltf", [](MeshoptGrid& mg) { mg.ext(4)["mode"] = "STRIPS"; },
      "has mode 'STRIPS'; expected ATTRIBUTES, TRIANGLES or INDICES");
  bad(
      "uncompressed.gltf", [](MeshoptGrid& mg) { mg.d.j["bufferViews"][0].erase("extensions"); },
      "reads buffer 1, which has no data (a fallback buffer), and is not compressed");
  bad(
      "from-fallback.glb", [](MeshoptGrid& mg) { mg.ext(1)["buffer"] = 1; },
      "EXT_meshopt_compression reads buffer 1, which has no data (a fallback buffer)");
}

}  // namespace
