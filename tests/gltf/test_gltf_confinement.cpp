// Which files a scene may read (docs/gltf.md "Which files a scene may read", issue 36): buffer
// and image URIs resolve inside the scene's folder or an --asset-dir folder, to regular files,
// or the load is refused before anything is opened, with a message that says nothing about the
// file refused; images are decoded only from the bytes read; JSON nesting is limited before any
// parser recurses; strings where glTF requires numbers are refused. Everything is generated in
// temporary folders.
#include "gltf_expect.h"

#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>

namespace pb::test {
namespace {

namespace fs = std::filesystem;

// A scene folder (dir_/scene) and a folder beside it (dir_/outside) holding the scene's real
// buffer as secret.bin.
class Confinement : public LoaderTest {
 protected:
  void SetUp() override {
    LoaderTest::SetUp();
    fs::create_directories(dir_ / "scene");
    fs::create_directories(dir_ / "outside");
  }
  void TearDown() override {
    fs::current_path(cwd_);
    fs::remove_all(dir_);
  }
  std::string put(const fs::path& rel, const std::vector<unsigned char>& bytes) {
    std::ofstream(dir_ / rel, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return (dir_ / rel).string();
  }
  // triangle_doc() with buffer 0 at `uri`, written to scene/scene.gltf.
  std::string scene_with_buffer(const std::string& uri) {
    Doc d = triangle_doc();
    d.buffer_uri = uri;
    bin_ = d.bin;
    return put("scene/scene.gltf", to_bytes(d.gltf()));
  }
  static std::vector<unsigned char> to_bytes(const std::string& s) { return {s.begin(), s.end()}; }
  // The SceneError's text, or "" when the load succeeds; fails the test if it takes over 20 s
  // (a blocking open).
  static std::string error_of(const std::string& file, const LoadPolicy& policy = {}) {
    auto job = std::async(std::launch::async, [file, policy]() -> std::string {
      try {
        load_gltf(file, policy);
        return "";
      } catch (const SceneError& e) {
        return e.what();
      }
    });
    if (job.wait_for(std::chrono::seconds(20)) != std::future_status::ready) {
      std::fprintf(stderr, "loading %s blocked\n", file.c_str());
      std::_Exit(1);  // the loader thread cannot be stopped
    }
    return job.get();
  }
  void expect_refused(const std::string& file, const std::string& phrase,
                      const LoadPolicy& policy = {}) {
    const std::string m = error_of(file, policy);
    EXPECT_EQ(m.rfind(file + ": ", 0), 0u) << m;
    EXPECT_NE(m.find(phrase), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  std::vector<unsigned char> bin_;
  fs::path cwd_ = fs::current_path();
};

const char* kOutside = "is outside the scene's folder (allow its folder with --asset-dir)";

TEST_F(Confinement, EscapesAreRefused) {
  put("outside/secret.bin", triangle_doc().bin);
  for (const std::string uri :
       {"../outside/secret.bin", "../../../../../../../../etc/passwd", "/etc/hostname",
        "%2e%2e/outside/secret.bin", "..%2foutside%2fsecret.bin", "%2E%2E%2Foutside/secret.bin",
        "/dev/zero", "/proc/self/environ", "sub/../../outside/secret.bin"}) {
    SCOPED_TRACE(uri);
    const std::string file = scene_with_buffer(uri);
    expect_refused(file, "buffer 0 uri '" + uri + "' " + kOutside);
  }
}

TEST_F(Confinement, ASymlinkOutIsRefusedAndOneWithinIsFollowed) {
  put("outside/secret.bin", triangle_doc().bin);
  fs::create_directory_symlink(dir_ / "outside", dir_ / "scene" / "link");
  fs::create_directory_symlink("/etc", dir_ / "scene" / "etc");
  expect_refused(scene_with_buffer("link/secret.bin"), kOutside);
  expect_refused(scene_with_buffer("etc/hostname"), kOutside);
  const std::string file = scene_with_buffer("inner.bin");
  put("scene/real.bin", bin_);
  fs::create_symlink("real.bin", dir_ / "scene" / "inner.bin");
  EXPECT_EQ(error_of(file), "");
}

// The message is the same whether the outside file exists, is missing, or has another size than
// the byteLength: nothing about it is revealed.
TEST_F(Confinement, TheMessageRevealsNothing) {
  const std::string file = scene_with_buffer("../outside/secret.bin");
  const std::string missing = error_of(file);
  put("outside/secret.bin", bin_);
  const std::string present = error_of(file);
  put("outside/secret.bin", std::vector<unsigned char>(1000, 7));
  const std::string other_size = error_of(file);
  fs::remove(dir_ / "outside/secret.bin");
  fs::create_directory(dir_ / "outside/secret.bin");
  const std::string directory = error_of(file);
  EXPECT_NE(missing.find(kOutside), std::string::npos) << missing;
  EXPECT_EQ(present, missing);
  EXPECT_EQ(other_size, missing);
  EXPECT_EQ(directory, missing);
  EXPECT_EQ(missing.find("1000"), std::string::npos);
}

TEST_F(Confinement, FilesThatAreNotRegularAreRefusedWithoutOpening) {
  ASSERT_EQ(::mkfifo((dir_ / "scene/pipe").c_str(), 0600), 0);
  expect_refused(scene_with_buffer("pipe"), "buffer 0 uri 'pipe' is a named pipe");
  fs::create_directory(dir_ / "scene/sub");
  expect_refused(scene_with_buffer("sub"), "buffer 0 uri 'sub' is a directory, not a file");
  // Allowed folders do not make devices readable.
  expect_refused(scene_with_buffer("/dev/zero"), "buffer 0 uri '/dev/zero' is a device",
                 LoadPolicy{{"/dev"}});
  // Nor does a symlink inside to a pipe inside.
  fs::create_symlink("pipe", dir_ / "scene" / "pipe_link");
  expect_refused(scene_with_buffer("pipe_link"), "is a named pipe");
}

TEST_F(Confinement, AssetDirAllowsAFolder) {
  const std::string file = scene_with_buffer("../outside/secret.bin");
  put("outside/secret.bin", bin_);
  EXPECT_EQ(error_of(file, LoadPolicy{{(dir_ / "outside").string()}}), "");
  // Given relative to the working directory, or with a trailing slash.
  fs::current_path(dir_);
  EXPECT_EQ(error_of(file, LoadPolicy{{"outside/"}}), "");
  // Another folder does not.
  fs::create_directory(dir_ / "other");
  expect_refused(file, "is outside the scene's folder and the --asset-dir folders",
                 LoadPolicy{{"other"}});
  // A folder that is not there is an error of its own.
  const std::string m = error_of(file, LoadPolicy{{"missing"}});
  EXPECT_EQ(m.rfind("missing: --asset-dir names no folder", 0), 0u) << m;
  // A sibling whose name starts with the allowed one is not inside it.
  fs::create_directory(dir_ / "outside2");
  put("outside2/secret.bin", bin_);
  expect_refused(scene_with_buffer("../outside2/secret.bin"), "is outside",
                 LoadPolicy{{(dir_ / "outside").string()}});
}

TEST_F(Confinement, ARelativeSceneWorksFromItsFolder) {
  scene_with_buffer("data.bin");
  put("scene/data.bin", bin_);
  fs::current_path(dir_ / "scene");
  EXPECT_EQ(error_of("scene.gltf"), "");
  fs::current_path(dir_);
  EXPECT_EQ(error_of("scene/scene.gltf"), "");
}

TEST_F(Confinement, NetworkUrisStayRefused) {
  expect_refused(scene_with_buffer("http://example.com/data.bin"),
                 "buffer 0 uri 'http://example.com/data.bin' is not a file name");
  expect_refused(scene_with_buffer("file:///etc/hostname"), "is not a file name");
}

// An image from outside would show in the render: refused like a buffer, even when no material
// used it.
TEST_F(Confinement, ImagesAreConfinedToo) {
  put("outside/tex.png", png_bytes(2, 2));
  Doc d = textured(json{{"images", json::array({json{{"uri", "../outside/tex.png"}}})},
                        {"textures", json::array({json{{"source", 0}}})}},
                   json{{"pbrMetallicRoughness", json{{"baseColorTexture", json{{"index", 0}}}}}});
  const std::string file = put("scene/scene.gltf", to_bytes(d.gltf()));
  expect_refused(file, "image 0 uri '../outside/tex.png' " + std::string(kOutside));
  d.j["textures"] = json::array();
  d.j["materials"][0].erase("pbrMetallicRoughness");
  put("scene/scene.gltf", to_bytes(d.gltf()));
  expect_refused(file, "image 0 uri '../outside/tex.png' is outside");
  // Inside, the same image loads.
  put("scene/tex.png", png_bytes(2, 2));
  d.j["images"][0]["uri"] = "tex.png";
  put("scene/scene.gltf", to_bytes(d.gltf()));
  EXPECT_EQ(error_of(file), "");
}

// An SGI image of w x h texels of one RGB colour (uncompressed, 8 bits).
std::vector<unsigned char> sgi_bytes(int w, int h, const std::array<uint8_t, 3>& rgb) {
  std::vector<unsigned char> b(512, 0);
  auto be16 = [&](size_t at, int v) {
    b[at] = uint8_t(v >> 8);
    b[at + 1] = uint8_t(v);
  };
  be16(0, 474);  // magic
  b[2] = 0;      // verbatim
  b[3] = 1;      // one byte per channel
  be16(4, 3);
  be16(6, w);
  be16(8, h);
  be16(10, 3);
  b[15] = 0;    // pixmin 0
  b[19] = 255;  // pixmax 255
  for (int c = 0; c < 3; ++c) b.insert(b.end(), size_t(w * h), rgb[size_t(c)]);
  return b;
}
// An ICO whose one 2 x 2 entry is a PNG.
std::vector<unsigned char> ico_bytes(int seed) {
  const std::vector<unsigned char> png = png_bytes(2, 2, seed);
  std::vector<unsigned char> b = {0, 0, 1, 0, 1, 0, 2, 2, 0, 0, 1, 0, 32, 0};
  const uint32_t size = uint32_t(png.size()), offset = 22;
  for (int k = 0; k < 4; ++k) b.push_back(uint8_t(size >> (8 * k)));
  for (int k = 0; k < 4; ++k) b.push_back(uint8_t(offset >> (8 * k)));
  b.insert(b.end(), png.begin(), png.end());
  return b;
}

// OpenImageIO's SGI and ICO readers cannot read from memory: given the URI, they opened it by
// name in the working directory. A file there with the URI's name must never be read. By
// default such an image is not decoded at all (not one of glTF's formats: a warning, and the
// texture's factor); with --texture-formats any its format is refused (the scene's own file
// present or not), and a missing image is missing.
TEST_F(Confinement, ImagesAreDecodedOnlyFromTheBytesRead) {
  fs::create_directories(dir_ / "cwd");
  fs::current_path(dir_ / "cwd");
  const std::vector<std::pair<std::string, std::vector<unsigned char>>> formats = {
      {"tex.sgi", sgi_bytes(2, 2, {255, 0, 0})}, {"tex.ico", ico_bytes(1)}};
  LoadPolicy any;
  any.any_texture_format = true;
  for (const auto& [name, bytes] : formats) {
    SCOPED_TRACE(name);
    put("cwd/" + name, bytes);
    Doc d =
        textured(json{{"images", json::array({json{{"uri", name}}})},
                      {"textures", json::array({json{{"source", 0}}})}},
                 json{{"pbrMetallicRoughness", json{{"baseColorTexture", json{{"index", 0}}}}}});
    const std::string file = put("scene/scene.gltf", to_bytes(d.gltf()));
    put("scene/" + name, name == "tex.sgi" ? sgi_bytes(2, 2, {0, 0, 255}) : ico_bytes(2));
    const Scene scene = load_gltf(file);
    EXPECT_TRUE(scene.images.empty());
    ASSERT_FALSE(scene.materials.empty());
    for (const Material& m : scene.materials) EXPECT_FALSE(m.base_color_texture.present());
    EXPECT_TRUE(has_warning(scene, name == "tex.sgi" ? "is SGI, not one of glTF's image formats"
                                                     : "is ICO, not one of glTF's image formats"));
    expect_refused(file, "reads files by name, not bytes in memory", any);
    fs::remove(dir_ / "scene" / name);
    expect_refused(file, "has no data (a missing file");
  }
  // The same for a PNG: tinygltf looked for a missing file in the working directory too.
  put("cwd/tex.png", png_bytes(2, 2));
  Doc d = textured(json{{"images", json::array({json{{"uri", "tex.png"}}})},
                        {"textures", json::array({json{{"source", 0}}})}},
                   json{{"pbrMetallicRoughness", json{{"baseColorTexture", json{{"index", 0}}}}}});
  const std::string file = put("scene/scene.gltf", to_bytes(d.gltf()));
  expect_refused(file, "has no data (a missing file");
  // Bytes in no format photonbound recognises are a corrupt image, refused either way.
  put("scene/tex.png", to_bytes("not an image at all, whatever its name says"));
  expect_refused(file, "image 'tex.png': cannot decode the image: it is not a PNG, JPEG or WebP");
  expect_refused(file, "image 'tex.png': cannot decode the image", any);
  // A PNG decodes under both policies.
  put("scene/tex.png", png_bytes(2, 2));
  EXPECT_EQ(error_of(file), "");
  EXPECT_EQ(error_of(file, any), "");
}

// 100,000 nested arrays in extras (200 KB) overflowed the stack in the JSON parser.
TEST_F(Confinement, DeepJsonIsRefusedBeforeParsing) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  Doc d = triangle_doc();
  std::string text = d.gltf();
  text.insert(text.find('{') + 1, "\"extras\":" + deep + ",");
  expect_refused(put("scene/deep.gltf", to_bytes(text)), "JSON nested deeper than 512 levels");
  // In a GLB's JSON chunk too, and in a scene that needs the prepass.
  d.j["extras"] = json::array();
  json* at = &d.j["extras"];
  for (int k = 0; k < 600; ++k) {
    at->push_back(json::array());
    at = &at->back();
  }
  d.j["extensionsUsed"] = json::array({"KHR_draco_mesh_compression"});
  expect_refused(put("scene/deep.glb", d.glb()), "JSON nested deeper than 512 levels");
  // 512 levels are fine.
  Doc ok = triangle_doc();
  std::string fine = ok.gltf();
  fine.insert(fine.find('{') + 1,
              "\"extras\":" + std::string(511, '[') + std::string(511, ']') + ",");
  EXPECT_EQ(error_of(put("scene/ok.gltf", to_bytes(fine))), "");
}

TEST_F(Confinement, StringsWhereNumbersBelongAreRefused) {
  struct Row {
    std::function<void(Doc&)> edit;
    std::string phrase;
  };
  const std::vector<Row> rows = {
      {[](Doc& d) { light0(d)["intensity"] = "NaN"; },
       "extensions.KHR_lights_punctual.lights[0].intensity is a string (\"NaN\") where glTF "
       "requires a number"},
      {[](Doc& d) { light0(d)["range"] = "10"; }, "lights[0].range is a string"},
      {[](Doc& d) {
         light0(d)["color"] = json::array({1, "0.5", 0.25});
       },
       "lights[0].color[1] is a string"},
      {[](Doc& d) { material0(d)["pbrMetallicRoughness"]["metallicFactor"] = "0.5"; },
       "materials[0].pbrMetallicRoughness.metallicFactor is a string"},
      {[](Doc& d) { material0(d)["pbrMetallicRoughness"]["roughnessFactor"] = true; },
       "roughnessFactor is a boolean (true)"},
      {[](Doc& d) { d.j["nodes"][1]["translation"] = "0 0 5"; },
       "nodes[1].translation is a string"},
      {[](Doc& d) { d.j["cameras"][0]["perspective"]["aspectRatio"] = "1.5"; },
       "cameras[0].perspective.aspectRatio is a string"},
      {[](Doc& d) { d.j["meshes"][0]["primitives"][0]["material"] = "0"; },
       "meshes[0].primitives[0].material is a string"},
  };
  for (const Row& r : rows) {
    Doc d = triangle_doc();
    r.edit(d);
    SCOPED_TRACE(r.phrase);
    expect_refused(put("scene/s.gltf", to_bytes(d.gltf())), r.phrase);
  }
  // The author's own values under extras, and names and URIs, are strings as they may be.
  Doc d = triangle_doc();
  light0(d)["extras"] = json{{"intensity", "bright"}, {"range", json::array({"a"})}};
  material0(d)["extras"] = json{{"metallicFactor", "n/a"}};
  d.j["extras"] = json{{"scene", "x"}};
  EXPECT_EQ(error_of(put("scene/s.gltf", to_bytes(d.gltf()))), "");
}

}  // namespace
}  // namespace pb::test
