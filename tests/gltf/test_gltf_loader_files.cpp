// glTF loader tests: files, buffers and their URIs, GLB containers, malformed bytes, extensions
// and animations, the shipped scenes and the fuzz regression inputs. Each row edits
// gltf_expect.h's triangle_doc() and expects a one-line SceneError or a loaded Scene; byte-level
// edits of the written file are a second table; the rest are TESTs. Only SmokeLoadsShippedScenes
// reads scenes/ (and skips when it is empty).
#include "gltf_expect.h"

#include "lights/lights.h"
#include "render/camera_choice.h"
#include "render/scene_defaults.h"
#include "world/world.h"

#include <algorithm>
#include <cstring>

namespace pb::test {
namespace {

namespace fs = std::filesystem;

// The timeline accessor (0 s, 1 s) of an animation sampler; returns its index.
int times(Doc& d) {
  return d.accessor(d.view(std::vector<float>{0, 1}), kFloat, 2, "SCALAR",
                    json{{"min", {0}}, {"max", {1}}});
}

LoaderCase glb_named(const std::string& name, const std::string& file) {
  return {.name = name,
          .edit = {},
          .check = [](const Scene& s) { EXPECT_EQ(s.triangle_count(), 1u); },
          .file = file,
          .glb = true};
}

const std::vector<LoaderCase> kRows = {
    {.name = "LoadsBinaryGlb",
     .edit = {},
     .check =
         [](const Scene& s) {
           EXPECT_EQ(s.triangle_count(), 1u);
           EXPECT_EQ(s.cameras.size(), 1u);
           EXPECT_EQ(s.lights.size(), 1u);
         },
     .file = "scene.glb",
     .glb = true},
    // A GLB is known by its magic, whatever its name says: BOX.GLB, or a binary file named .gltf.
    glb_named("AGlbNamedInCapitalsIsKnownByItsMagic", "BOX.GLB"),
    glb_named("AGlbNamedGltfIsKnownByItsMagic", "binary.gltf"),
    glb_named("AGlbNamedBinIsKnownByItsMagic", "model.bin"),
    // In its own words, naming the file that is missing, and only once (not "malformed").
    {.name = "ExternalBufferMissing",
     .edit = [](Doc& d) { d.buffer_uri = "missing.bin"; },
     .error = {": the buffer file 'missing.bin' it refers to cannot be opened"}},
    // KHR_animation_pointer's channels target a JSON pointer, not a node; tinygltf 2.7 refused
    // the whole file ("'node' property is missing"). Animations are ignored, with their warning.
    {.name = "AnimationPointerChannelsDoNotRefuseTheFile",
     .edit =
         [](Doc& d) {
           const int in = times(d);
           const int out = d.accessor(d.view(std::vector<float>{0, 1}), kFloat, 2, "SCALAR");
           d.j["extensionsUsed"] = json::array({"KHR_animation_pointer"});
           const json pointer =
               json{{"KHR_animation_pointer", json{{"pointer", "/materials/0/emissiveStrength"}}}};
           d.j["animations"] = json::array({json{
               {"samplers", json::array({json{{"input", in}, {"output", out}}})},
               {"channels",
                json::array({json{{"sampler", 0},
                                  {"target", json{{"path", "pointer"}, {"extensions", pointer}}}},
                             json{{"sampler", 0},
                                  {"target", json{{"node", 0}, {"path", "translation"}}}}})}}});
         },
     .check =
         [](const Scene& s) {
           EXPECT_EQ(s.triangle_count(), 1u);
           EXPECT_TRUE(has_warning(s, "1 animation is ignored"));
         }},
    {.name = "AnimationsAreIgnoredWithAWarning",
     .edit =
         [](Doc& d) {
           const int in = times(d), out = d.vec3s({0, 0, 0, 1, 0, 0});
           d.j["animations"] = json::array({json{
               {"samplers", json::array({json{{"input", in}, {"output", out}}})},
               {"channels",
                json::array({json{{"sampler", 0},
                                  {"target", json{{"node", 0}, {"path", "translation"}}}}})}}});
         },
     .check =
         [](const Scene& s) {
           EXPECT_TRUE(
               has_warning(s, "1 animation is ignored; the scene is drawn as the nodes place it"));
         }},
    // What is not implemented is warned about, not refused: unknown extensions (required ones
    // too), animations.
    {.name = "UnsupportedRequiredExtension",
     .edit =
         [](Doc& d) {
           d.j["extensionsUsed"] = json::array({"EXT_lights_image_based", "EXT_lights_ies"});
           d.j["extensionsRequired"] = json::array({"EXT_lights_image_based"});
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.warnings.size(), 2u);
           EXPECT_EQ(s.warnings[0],
                     "extension 'EXT_lights_image_based' is required but not implemented; "
                     "rendered without it");
           EXPECT_EQ(s.warnings[1], "extension 'EXT_lights_ies' is ignored");
         }},
    // Metadata, the variants' default materials and MSFT_lod's finest level are what photonbound
    // draws anyway; unlit materials are read (painted: docs/materials.md "Unlit").
    {.name = "ExtensionsWithoutWhichTheImageIsTheSameAreNotWarned",
     .edit =
         [](Doc& d) {
           d.j["extensionsUsed"] = json::array(
               {"KHR_xmp_json_ld", "KHR_materials_variants", "MSFT_lod", "KHR_materials_unlit"});
         },
     .check = [](const Scene& s) { EXPECT_EQ(s.warnings.size(), 0u); }},
};

using LoaderFiles = LoaderCaseTest;
TEST_P(LoaderFiles, Row) { run(); }
INSTANTIATE_TEST_SUITE_P(Table, LoaderFiles, ::testing::ValuesIn(kRows), case_name);

// Bytes written as `file` that loading must refuse with one line holding `error`: made from
// triangle_doc()'s .gltf text or GLB bytes.
struct BytesCase {
  std::string name, file;
  std::function<std::vector<unsigned char>()> bytes;
  std::string error;
};
void PrintTo(const BytesCase& c, std::ostream* os) { *os << c.name; }

std::vector<unsigned char> text(const std::string& s) { return {s.begin(), s.end()}; }
std::vector<unsigned char> glb_cut_by_8() {
  std::vector<unsigned char> b = triangle_doc().glb();
  b.resize(b.size() - 8);
  return b;
}

const std::vector<BytesCase> kBytes = {
    {"MalformedJson", "bad.gltf", [] { return text("{ this is not json ]"); }, "malformed glTF: "},
    {"TruncatedJson", "cut.gltf",
     [] {
       const std::string j = triangle_doc().gltf();
       return text(j.substr(0, j.size() / 2));
     },
     "malformed glTF: "},
    {"GlbBadMagic", "bad.glb",
     [] {
       std::vector<unsigned char> b = triangle_doc().glb();
       b[0] = 'x';
       return b;
     },
     "malformed glTF: bad GLB magic"},
    {"GlbTruncatedChunk", "cut.glb", glb_cut_by_8, "malformed glTF: truncated GLB"},
    // Header length adjusted to the cut: the BIN chunk itself now overruns the file.
    {"GlbBinChunkOverrunsTheFile", "cut2.glb",
     [] {
       std::vector<unsigned char> b = glb_cut_by_8();
       const uint32_t n = uint32_t(b.size());
       std::memcpy(b.data() + 8, &n, 4);
       return b;
     },
     "malformed glTF: the GLB BIN chunk"},
    {"GlbTruncatedHeader", "tiny.glb",
     [] {
       return std::vector<unsigned char>{'g', 'l', 'T', 'F', 2};
     },
     "truncated GLB header"},
};

class LoaderBytes : public LoaderTest, public ::testing::WithParamInterface<BytesCase> {};
TEST_P(LoaderBytes, Row) {
  expect_error(write(GetParam().file, GetParam().bytes()), GetParam().error);
}
INSTANTIATE_TEST_SUITE_P(Table, LoaderBytes, ::testing::ValuesIn(kBytes),
                         [](const ::testing::TestParamInfo<BytesCase>& i) { return i.param.name; });

TEST_F(LoaderTest, MissingFile) {
  expect_error(path("nope.gltf"), "cannot open (No such file or directory)");
}

TEST_F(LoaderTest, LoadsExternalBuffer) {
  Doc d = triangle_doc();
  d.buffer_uri = "data.bin";
  write("data.bin", d.bin);
  EXPECT_EQ(load(d).triangle_count(), 1u);
}

TEST_F(LoaderTest, ExternalBufferWrongSize) {
  Doc d = triangle_doc();
  d.buffer_uri = "short.bin";
  write("short.bin", std::vector<unsigned char>(d.bin.begin(), d.bin.end() - 4));
  expect_error(d, "malformed glTF: File size mismatch");
}

// glTF pads every GLB chunk to 4 bytes and tinygltf 2.7 refuses a BIN chunk that is not ("BIN
// Chunk end does not aligned"); FME 2018 wrote one. The loader pads it: the same triangle loads.
TEST_F(LoaderTest, AnUnpaddedBinChunkIsPadded) {
  const Doc d = triangle_doc();
  ASSERT_NE(d.bin.size() % 4, 0u);  // 3 uint16 indices end the buffer two bytes past a boundary
  std::vector<unsigned char> glb = d.glb();
  const uint32_t json = uint32_t(glb[12]) | uint32_t(glb[13]) << 8 | uint32_t(glb[14]) << 16 |
                        uint32_t(glb[15]) << 24;
  const size_t bin_at = 20 + json, unpadded = d.bin.size();
  glb.resize(bin_at + 8 + unpadded);
  for (int k = 0; k < 4; ++k) {
    glb[bin_at + size_t(k)] = uint8_t(unpadded >> (8 * k));
    glb[8 + size_t(k)] = uint8_t(glb.size() >> (8 * k));
  }
  const Scene s = load_gltf(write("unpadded.glb", glb));
  EXPECT_EQ(s.triangle_count(), 1u);
  expect_vec(s.meshes[0].positions[1], vec3(1, 0, 0));
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
    RenderOptions o;
    complete_scene(s, o);
    EXPECT_TRUE(has_light(s));
    const World world(std::move(s));
    EXPECT_NO_THROW(choose_camera(world.scene(), o));
  }
}

TEST_F(LoaderTest, MessagesQuotingHostileBytesStayOneLineOfText) {
  // A node name with invalid UTF-8, a control character and a line break, and a JSON syntax
  // error right after a stray high byte (the parser quotes the last bytes it read). nlohmann
  // does not write invalid UTF-8: the name goes into the text afterwards.
  Doc d = triangle_doc();
  d.add("nodes", json{{"name", "@NAME@"}, {"mesh", 7}});
  set_roots(d, {0, 1, 2, 3});
  std::string named_text = d.gltf();
  named_text.replace(named_text.find("@NAME@"), 6, "bad\\u0001\\n\xd6\xff name");
  const std::string named = write("named.gltf", named_text);
  const std::string broken = write("broken.gltf", std::string("{\"asset\": \xd6\x01\n}"));
  for (const std::string& file : {named, broken}) {
    try {
      load_gltf(file);
      ADD_FAILURE() << file << " loaded";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(file + ": ", 0), 0u) << m;
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
      complete_scene(s, RenderOptions{});  // the default sky when it has no light
      const World world(s);
      EXPECT_GT(world.scene_size(), 0.0f);
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(f.string() + ": ", 0), 0u) << m;
      EXPECT_TRUE(printable_utf8(m)) << m;
    }
  }
}

}  // namespace
}  // namespace pb::test
