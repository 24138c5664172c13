// glTF loader tests: images (data URIs, files, bufferViews, KTX2), samplers, texture transforms
// and tangents. Each row edits gltf_expect.h's triangle_doc() (mostly through textured()) and
// expects a one-line SceneError or a loaded Scene; the cases that write side files are TESTs.
#include "gltf_expect.h"

#include "lights/lights.h"
#include "render/scene_defaults.h"

#include <cmath>

namespace pb::test {
namespace {

json images(const json& list) { return json{{"images", list}}; }
json textures(const json& list) { return json{{"textures", list}}; }
json base_color_texture(int index) {
  return json{{"pbrMetallicRoughness", json{{"baseColorTexture", json{{"index", index}}}}}};
}
// Undecodable bytes as a PNG data URI.
const json kJunkImage = json{{"uri", "data:image/png;base64,AAAAAAAA"}};

// A GLB whose image 0 is a 2 x 2 PNG in a bufferView (returned) of buffer 0.
int image_in_view(Doc& d) {
  d = textured(json::object(), base_color_texture(0));
  const int view = d.view(png_bytes(2, 2));
  d.j.update(images(json::array({json{{"bufferView", view}, {"mimeType", "image/png"}}})));
  d.j.update(textures(json::array({json{{"source", 0}}})));
  return view;
}

const std::vector<LoaderCase> kRows = {
    // One embedded PNG (a data URI) used by four textures: decoded once. Sampler 0 clamps S,
    // mirrors T and filters NEAREST; KHR_texture_transform sets the matrix and texCoord.
    {.name = "TexturesAreDecodedWithSamplersAndTransforms",
     .edit =
         [](Doc& d) {
           json top = images(json::array({png_image(png_bytes(3, 2))}));
           top["samplers"] =
               json::array({json{{"magFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33648}}});
           top["textures"] =
               json::array({json{{"source", 0}, {"sampler", 0}}, json{{"source", 0}}});
           const json xf = json::parse(R"({"KHR_texture_transform": {"offset": [0.5, 0.25],
             "rotation": 0.3, "scale": [2, 4], "texCoord": 1}})");
           d = textured(top, json::parse(R"({
             "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                      "metallicRoughnessTexture": {"index": 1}},
             "normalTexture": {"index": 1, "scale": 0.5},
             "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 1, "texCoord": 1},
             "extensions": {"KHR_materials_specular": {"specularColorTexture": {"index": 0}}}})"));
           material0(d)["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = xf;
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.images.size(), 1u);
           EXPECT_EQ(s.images[0].width, 3);
           EXPECT_EQ(s.images[0].height, 2);
           EXPECT_EQ(s.images[0].u8[3], 40);  // texel 1, R
           const Material& m = s.materials[s.meshes[0].material];
           const TextureRef& b = m.base_color_texture;
           EXPECT_EQ(b.image, 0);
           EXPECT_EQ(b.wrap_s, Wrap::ClampToEdge);
           EXPECT_EQ(b.wrap_t, Wrap::MirroredRepeat);
           EXPECT_TRUE(b.nearest);
           EXPECT_EQ(b.texcoord, 1);
           const float c = std::cos(0.3f), sn = std::sin(0.3f);
           const float want[6] = {2 * c, 4 * sn, 0.5f, -2 * sn, 4 * c, 0.25f};
           for (int k = 0; k < 6; ++k) EXPECT_NEAR(b.m[k], want[k], 1e-6f) << k;
           EXPECT_EQ(m.metallic_roughness_texture.wrap_s, Wrap::Repeat);  // no sampler: REPEAT
           EXPECT_FALSE(m.metallic_roughness_texture.nearest);
           EXPECT_EQ(m.emissive_texture.texcoord, 1);
           EXPECT_NEAR(m.normal_scale, 0.5f, 1e-7f);
           EXPECT_TRUE(m.specular_color_texture.present());
           EXPECT_FALSE(m.transmission_texture.present());
           // A normal texture and no TANGENT: tangents are made from TEXCOORD_0 (u along +x).
           ASSERT_EQ(s.meshes[0].tangents.size(), 3u);
           for (const glm::vec4& t : s.meshes[0].tangents) {
             EXPECT_NEAR(t.x, 1.0f, 1e-5f);
             EXPECT_EQ(std::fabs(t.w), 1.0f);
           }
           ASSERT_EQ(s.meshes[0].texcoords[1].size(), 3u);
           EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
         }},
    // A GLB's image in a bufferView is read from the buffer (its range checked); a bufferView
    // past the buffer, undecodable bytes, a missing file and an absent image are refused,
    // naming the image.
    {.name = "AnImageInABufferViewIsRead",
     .edit = [](Doc& d) { image_in_view(d); },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.images.size(), 1u);
           EXPECT_EQ(s.images[0].width, 2);
         },
     .file = "scene.glb",
     .glb = true},
    {.name = "AnImageBufferViewPastTheBufferIsRefused",
     .edit =
         [](Doc& d) {
           const int view = image_in_view(d);
           d.j["bufferViews"][size_t(view)] =
               json{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 999999}};
         },
     .error = {"image 0"},
     .file = "long.glb",
     .glb = true},
    {.name = "UndecodableImageIsNamedOnce",  // not "image 0: image 0"
     .edit =
         [](Doc& d) {
           json top = images(json::array({kJunkImage}));
           top.update(textures(json::array({json{{"source", 0}}})));
           d = textured(top, base_color_texture(0));
         },
     .error = {"image 0: cannot decode the image"}},
    {.name = "MissingImageFile",
     .edit =
         [](Doc& d) {
           json top = images(json::array({json{{"uri", "nowhere.png"}}}));
           top.update(textures(json::array({json{{"source", 0}}})));
           d = textured(top, json{{"emissiveTexture", json{{"index", 0}}}});
         },
     .error = {"image 'nowhere.png' has no data"}},
    {.name = "AbsentImage",
     .edit =
         [](Doc& d) {
           d = textured(textures(json::array({json{{"source", 4}}})),
                        json{{"emissiveTexture", json{{"index", 0}}}});
         },
     .error = {"image 4, which does not exist"}},
    // Unused images are never decoded: junk nobody uses loads.
    {.name = "UnusedImagesAreNeverDecoded",
     .edit =
         [](Doc& d) {
           d = textured(images(json::array({kJunkImage})), {{"doubleSided", false}});
         },
     .check = [](const Scene& s) { EXPECT_TRUE(s.images.empty()); }},
    // TANGENT through a mirroring node transform: xyz by the linear part, w flipped. Texture 1
    // has only a KHR_texture_basisu source.
    {.name = "FileTangentsAreTransformedAndTexturesWithoutImagesWarn",
     .edit =
         [](Doc& d) {
           json top = images(json::array({png_image(png_bytes(1, 1))}));
           top.update(textures(json::array(
               {json{{"source", 0}},
                json{{"extensions", json{{"KHR_texture_basisu", json{{"source", 0}}}}}}})));
           d = textured(top, json{{"normalTexture", json{{"index", 0}}},
                                  {"emissiveFactor", {1, 1, 1}},
                                  {"emissiveTexture", json{{"index", 1}}}});
           const int tan = d.accessor(
               d.view(std::vector<float>{0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, -1}), kFloat, 3, "VEC4");
           d.j["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = tan;
           d.j["nodes"][0] = json{{"mesh", 0}, {"scale", {-1, 2, 1}}};
         },
     .check =
         [](const Scene& s) {
           ASSERT_EQ(s.meshes[0].tangents.size(), 3u);
           expect_vec(vec3(s.meshes[0].tangents[0]), vec3(0, 1, 0));  // (0, 1, 0) x 2, unit
           EXPECT_EQ(s.meshes[0].tangents[0].w, -1.0f);
           EXPECT_EQ(s.meshes[0].tangents[2].w, 1.0f);
           EXPECT_TRUE(has_warning(s, "has no image photonbound can decode"));
           EXPECT_FALSE(s.materials[0].emissive_texture.present());
         }},
};

using LoaderTextures = LoaderCaseTest;
TEST_P(LoaderTextures, Row) { run(); }
INSTANTIATE_TEST_SUITE_P(Table, LoaderTextures, ::testing::ValuesIn(kRows), case_name);

TEST_F(LoaderTest, ExternalImagesArePartOfTheSceneIdentity) {
  // Editing an external texture changes Scene::content_hash (resume refuses the old state).
  write("wood.png", png_bytes(2, 2, 0));
  const Doc d = textured(json{{"images", json::array({json{{"uri", "wood.png"}}})},
                              {"textures", json::array({json{{"source", 0}}})}},
                         base_color_texture(0));
  const uint64_t before = load(d).content_hash;
  EXPECT_EQ(load(d).content_hash, before);
  write("wood.png", png_bytes(2, 2, 1));
  EXPECT_NE(load(d).content_hash, before);
}

TEST_F(LoaderTest, KtxTwoImagesAsPlainSourcesFallBackToTheirFactorsWithOneWarning) {
  // glTF-Sample-Assets' KTX2 variants point texture.source at a KTX2 image without requiring
  // KHR_texture_basisu: that is the factor alone, warned once for the image however many
  // textures use it, as a basisu-only texture is (above), not a refusal.
  std::vector<unsigned char> ktx2 = {0xab, 'K',  'T',  'X',  ' ',  '2',
                                     '0',  0xbb, '\r', '\n', 0x1a, '\n'};
  ktx2.resize(64, 0);
  write("lamp.ktx2", ktx2);
  const Doc d =
      textured(json{{"images", json::array({json{{"uri", "lamp.ktx2"}}})},
                    {"textures", json::array({json{{"source", 0}}, json{{"source", 0}}})}},
               json::parse(R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1],
                                               "baseColorTexture": {"index": 0}},
                      "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 1}})"));
  const Scene s = load(d);
  EXPECT_TRUE(s.images.empty());
  EXPECT_FALSE(s.materials[0].base_color_texture.present());
  EXPECT_FALSE(s.materials[0].emissive_texture.present());
  expect_vec(s.materials[0].base_color, vec3(0.5f, 0.25f, 1.0f));
  size_t warned = 0;
  for (const std::string& w : s.warnings) warned += w.find("is KTX2 (Basis Universal)") != w.npos;
  EXPECT_EQ(warned, 1u);
}

// An exporter's "no emission": emissiveFactor 1 over an all-black emissive texture. The file then
// has no light and gets the default sky (it was refused: "the scene's lights emit no finite
// positive power", naming no file); one lit texel makes the material a light again.
TEST_F(LoaderTest, AnEmissiveFactorOverABlackTextureIsNoLight) {
  auto with_texel = [&](uint8_t value) {
    std::vector<unsigned char> rgb(12, 0);
    rgb[4] = value;  // the second texel's green
    write_png(path("emit.png"), 2, 2, rgb);
    Doc d = textured(json{{"images", json::array({json{{"uri", "emit.png"}}})},
                          {"textures", json::array({json{{"source", 0}}})}},
                     json{{"emissiveFactor", {1, 1, 1}}, {"emissiveTexture", json{{"index", 0}}}});
    set_roots(d, {0, 1});  // no lamp
    return load(d);
  };
  Scene black = with_texel(0);
  EXPECT_TRUE(black.materials[black.meshes[0].material].emits());  // the factor is positive
  EXPECT_FALSE(has_light(black));
  RenderOptions o;
  const std::vector<std::string> notes = complete_scene(black, o);
  ASSERT_TRUE(black.environment.has_value());
  EXPECT_EQ(black.environment->source, "the default sky");
  EXPECT_NO_THROW(Lights{black});
  EXPECT_TRUE(has_light(with_texel(200)));
}

}  // namespace
}  // namespace pb::test
