// The loader's memory budgets (LoadPolicy::max_memory, docs/usage.md "Memory"): all decoded
// texels of a scene together, each image checked from its header before it is decoded, and
// the same image bytes decoded once however many images name them.
#include "gltf_expect.h"

#include "gltf/gltf_prepass.h"

namespace pb::test {
namespace {

// Four textures (base colour, metallic-roughness, emissive, normal) over images 0..3.
json four_textures() {
  return json::parse(R"({
    "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                             "metallicRoughnessTexture": {"index": 1}},
    "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 2},
    "normalTexture": {"index": 3}})");
}

Doc four_images(const std::vector<json>& images) {
  json top = json{{"images", images}, {"textures", json::array()}};
  for (int i = 0; i < 4; ++i) top["textures"].push_back(json{{"source", i}});
  return textured(top, four_textures());
}

// A 256 x 256 8-bit RGB image, decoded. png_bytes' texels repeat every 256, so its PNG and the
// rest of the scene's files take a few KiB, far less than half of it.
constexpr int kSide = 256;
constexpr uint64_t kOneImage = kSide * kSide * 3;

using Budgets = LoaderTest;

TEST_F(Budgets, FourImagesOfTheSameBytesAreDecodedOnceAndCountedOnce) {
  // Three images naming one file and a data URI of the same bytes: one decoded image, within
  // a budget of one and a half (the files count too).
  write("wood.png", png_bytes(kSide, kSide));
  const json file = json{{"uri", "wood.png"}};
  const Doc d = four_images({file, file, png_image(png_bytes(kSide, kSide)), file});
  const Scene s = load_gltf(write("scene.gltf", d.gltf()), LoadPolicy{{}, kOneImage * 3 / 2});
  ASSERT_EQ(s.images.size(), 1u);
  const Material& m = s.materials[s.meshes[0].material];
  for (const TextureRef* t : {&m.base_color_texture, &m.metallic_roughness_texture,
                              &m.emissive_texture, &m.normal_texture})
    EXPECT_EQ(t->image, 0);
}

TEST_F(Budgets, TheTexelsOfAllImagesTogetherAreCapped) {
  // Four different images: they fit a budget of four and a half, not of two and a half; the
  // refusal names the image that passes it, its size and the budget.
  std::vector<json> images;
  for (int k = 0; k < 4; ++k) images.push_back(png_image(png_bytes(kSide, kSide, k)));
  const Doc d = four_images(images);
  const std::string file = write("scene.gltf", d.gltf());
  EXPECT_EQ(load_gltf(file, LoadPolicy{{}, kOneImage * 9 / 2}).images.size(), 4u);
  expect_error(file, ": the image is 256x256 with 3 channels, 192 KiB decoded",
               LoadPolicy{{}, kOneImage * 5 / 2});
  expect_error(file, "the scene's files and textures would take ",
               LoadPolicy{{}, kOneImage * 5 / 2});
  expect_error(file, ", over the 480 KiB of --max-memory", LoadPolicy{{}, kOneImage * 5 / 2});
}

TEST_F(Budgets, ADataUriOverItsCapIsRefusedBeforeAnyParserCopiesIt) {
  // kMaxJsonString + 1 bytes of base64: refused from the one scan over the text, naming the
  // member. (A 683 MiB data: URI took 3.8 GB and 35 s to load; now 0.8 GB, the file's bytes.)
  Doc d = triangle_doc();
  std::string uri = "data:application/octet-stream;base64,";
  uri.resize(gltf::kMaxJsonString + 1, 'A');
  d.more_buffers.push_back(json{{"byteLength", 3 * (uri.size() / 4)}, {"uri", std::move(uri)}});
  expect_error(write("scene.gltf", d.gltf()),
               "buffers[1].uri is a data: URI of 256 MiB, over the 256 MiB photonbound reads");
}

TEST_F(Budgets, FilesTheSceneNamesCountAgainstTheBudget) {
  // A 64 KiB buffer file with 32 KiB allowed: refused before it is read, naming the buffer and
  // the option; with 1 MiB it loads. The scene file's own bytes count too.
  Doc d = triangle_doc();
  std::vector<unsigned char> bin = d.bin;
  bin.resize(64 << 10, 0);
  write("big.bin", bin);
  d.buffer_uri = "big.bin";
  json gltf = json::parse(d.gltf());
  gltf["buffers"][0]["byteLength"] = bin.size();
  const std::string file = write("scene.gltf", gltf.dump());
  EXPECT_EQ(load_gltf(file, LoadPolicy{{}, 1 << 20}).meshes.size(), 1u);
  expect_error(file, "buffer 0 uri 'big.bin' is larger than", LoadPolicy{{}, 32 << 10});
  expect_error(file, "--max-memory leaves for the scene's files", LoadPolicy{{}, 32 << 10});
  expect_error(file, "file is larger than 100 bytes (--max-memory)", LoadPolicy{{}, 100});
}

}  // namespace
}  // namespace pb::test
