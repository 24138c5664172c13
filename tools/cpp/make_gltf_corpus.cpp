// Writes a small corpus of glTF files that use the features the loader decodes, built by
// gltf_fixture.h: Draco (.glb, .gltf), meshoptimizer with a fallback buffer (.glb, .gltf),
// KHR_mesh_quantization, sparse accessors (also an indices accessor without bufferView) and a
// skin without inverseBindMatrices. Every file loads. The .glb files have neither camera nor light,
// as Blender and gltfpack often write them (the render adds the default view and sky); the
// .gltf files keep gltf_fixture.h's camera and point light. tools/fuzz.sh seeds the fuzzer with
// them; tests/gltf/test_corpus.cpp renders them with tools/make_scenes.py --corpus's files.
//   make_gltf_corpus OUTPUT_FOLDER
#include "gltf_fixture.h"

#include <cstdio>
#include <filesystem>

namespace {

using namespace pb::test;

// The scene lists only the mesh nodes: the fixture's camera (node 0) and light (node 1) stay in
// the file, unreferenced, as an exporter leaves unused objects out of the scene.
void without_camera_and_light(Doc& d) {
  json& roots = d.j["scenes"][0]["nodes"];
  roots.erase(roots.begin(), roots.begin() + 2);
}

bool is_glb(const char* name) { return std::string(name).find(".glb") != std::string::npos; }

void quantised(const std::string& file) {
  Doc d;
  d.require({"KHR_mesh_quantization"});
  const std::vector<int16_t> pos = {-32768, -32768, 0, 0, 32767,  -32768, 0, 0,
                                    32767,  32767,  0, 0, -32768, 32767,  0, 0};
  const std::vector<int8_t> nor = {0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0};
  const std::vector<uint16_t> uv = {0, 0, 65535, 0, 65535, 65535, 0, 65535};
  const std::vector<uint8_t> idx = {0, 1, 2, 0, 2, 3};
  const json norm = json{{"normalized", true}};
  d.mesh_node(
      json{
          {"attributes",
           json{{"POSITION",
                 d.accessor(d.view(pos, json{{"byteStride", 8}}), kShort, 4, "VEC3", norm)},
                {"NORMAL", d.accessor(d.view(nor, json{{"byteStride", 4}}), 5120, 4, "VEC3", norm)},
                {"TEXCOORD_0", d.accessor(d.view(uv), kUShort, 4, "VEC2", norm)}}},
          {"indices", d.accessor(d.view(idx), 5121, 6, "SCALAR")}},
      json{{"matrix", {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, -1, 1}}});
  d.write(file);
}

void sparse(const std::string& file) {
  Doc d;
  const std::vector<float> quad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const auto sp = [&](int count, int iv, int component, int vv) {
    return json{{"sparse", json{{"count", count},
                                {"indices", json{{"bufferView", iv}, {"componentType", component}}},
                                {"values", json{{"bufferView", vv}}}}}};
  };
  const int pos = d.accessor(
      d.view(quad), kFloat, 4, "VEC3",
      sp(1, d.view(std::vector<uint8_t>{2}), 5121, d.view(std::vector<float>{1.5f, 1.5f, 0.25f})));
  const int uv = d.accessor(
      -1, kFloat, 4, "VEC2",
      sp(2, d.view(std::vector<uint16_t>{1, 2}), kUShort, d.view(std::vector<float>{1, 0, 1, 1})));
  const int idx = d.accessor(-1, kUInt, 6, "SCALAR",
                             sp(4, d.view(std::vector<uint32_t>{1, 2, 4, 5}), kUInt,
                                d.view(std::vector<uint32_t>{1, 2, 2, 3})));
  // A skin without inverseBindMatrices, its one joint the mesh's own node: the quad stays where
  // that node puts it.
  const int joints = d.accessor(d.view(std::vector<uint8_t>(16, 0)), 5121, 4, "VEC4");
  const int weights =
      d.accessor(d.view(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}), kFloat,
                 4, "VEC4");
  d.mesh_node(json{
      {"attributes",
       json{{"POSITION", pos}, {"TEXCOORD_0", uv}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}},
      {"indices", idx}});
  d.j["nodes"].back()["skin"] = 0;
  d.j["skins"] = json::array({json{{"joints", json::array({d.j["nodes"].size() - 1})}}});
  d.write(file);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_gltf_corpus OUTPUT_FOLDER\n");
    return 2;
  }
  const std::filesystem::path out(argv[1]);
  std::filesystem::create_directories(out);
  const Grid g = make_grid(9);
  const std::vector<unsigned char> enc = draco_encode(g, DracoIds{}, DracoBits{});
  for (const char* name : {"draco.glb", "draco.gltf"}) {
    Doc d;
    d.require({"KHR_draco_mesh_compression"});
    d.mesh_node(draco_primitive(d, g, d.view(enc), DracoIds{}, g.vertices()));
    if (is_glb(name)) without_camera_and_light(d);
    d.write((out / name).string());
  }
  for (const char* name : {"meshopt.glb", "meshopt.gltf"}) {
    MeshoptGrid mg(g, true);
    mg.d.mesh_node(mg.prim);
    if (is_glb(name)) without_camera_and_light(mg.d);
    mg.d.write((out / name).string());
  }
  quantised((out / "quantised.gltf").string());
  sparse((out / "sparse-skin.gltf").string());
  return 0;
}
