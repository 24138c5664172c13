// glTF loader tests: materials, their factors and the KHR_materials_* extensions (with their
// textures' presence and texCoord; test_gltf_loader_textures.cpp decodes images). Each row edits
// gltf_expect.h's triangle_doc() and expects a one-line SceneError or a loaded Scene.
#include "gltf_expect.h"

#include <cmath>

namespace pb::test {
namespace {

// Material 0 (the triangle's) is `body`; `check` gets the triangle's material.
LoaderCase material(const std::string& name, const json& body,
                    std::function<void(const Scene&, const Material&)> check) {
  return {.name = name,
          .edit = [=](Doc& d) { material0(d) = body; },
          .check = [=](const Scene& s) { check(s, s.materials[s.meshes.at(0).material]); }};
}
// Material 0, named 'bad', has the members of `body`: refused, naming the material and `phrase`.
LoaderCase refused(const std::string& name, const json& body, const std::string& phrase) {
  json m = json{{"name", "bad"}};
  m.update(body);
  return {
      .name = name, .edit = [=](Doc& d) { material0(d) = m; }, .error = {"material 'bad'", phrase}};
}
json ext(const char* extension, const json& members) {
  return {{"extensions", {{extension, members}}}};
}
json pbr(const json& members) { return {{"pbrMetallicRoughness", members}}; }
// textured() with one 2 x 2 image as texture 0, `extension` used, and `material`.
LoaderCase textured_material(const std::string& name, const char* extension, const json& material,
                             std::function<void(const Scene&, const Material&)> check) {
  return {.name = name,
          .edit = [=](Doc& d) { d = textured(one_texture(extension), material); },
          .check = [=](const Scene& s) { check(s, s.materials[s.meshes.at(0).material]); }};
}

const json kAll = json::parse(R"({"name": "all",
  "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.7, 0.5], "metallicFactor": 0.25,
                           "roughnessFactor": 0.5},
  "emissiveFactor": [1, 0.5, 0], "doubleSided": true, "alphaMode": "MASK", "alphaCutoff": 0.3,
  "extensions": {"KHR_materials_ior": {"ior": 1.33},
                 "KHR_materials_emissive_strength": {"emissiveStrength": 4},
                 "KHR_materials_specular": {"specularFactor": 0.5,
                                            "specularColorFactor": [1, 2, 0.5]},
                 "KHR_materials_transmission": {"transmissionFactor": 0.75},
                 "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationDistance": 2,
                                          "attenuationColor": [0.5, 1, 0.25]}}})");
const json kClearcoat = json::parse(R"({"clearcoatFactor": 0.75, "clearcoatRoughnessFactor": 0.25,
  "clearcoatTexture": {"index": 0}, "clearcoatRoughnessTexture": {"index": 0, "texCoord": 1},
  "clearcoatNormalTexture": {"index": 0, "scale": 0.5}})");
const json kAnisotropy = json::parse(R"({"anisotropyStrength": 0.6, "anisotropyRotation": 7.0,
  "anisotropyTexture": {"index": 0, "texCoord": 1}})");
const json kIridescence = json::parse(R"({"iridescenceFactor": 0.7, "iridescenceIor": 1.8,
  "iridescenceThicknessMinimum": 500, "iridescenceThicknessMaximum": 200,
  "iridescenceTexture": {"index": 0}, "iridescenceThicknessTexture": {"index": 0, "texCoord": 1}})");
const json kDiffuseTransmission = json::parse(R"({"diffuseTransmissionFactor": 0.25,
  "diffuseTransmissionColorFactor": [1, 0.5, 0.25], "diffuseTransmissionTexture": {"index": 0},
  "diffuseTransmissionColorTexture": {"index": 0, "texCoord": 1}})");
const json kSheen = json::parse(R"({"sheenColorFactor": [0.9, 0.5, 0.25],
  "sheenRoughnessFactor": 0.75, "sheenColorTexture": {"index": 0},
  "sheenRoughnessTexture": {"index": 0, "texCoord": 1}})");
const json kPrism = json::parse(R"({"name": "prism",
  "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
  "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                 "KHR_materials_volume": {"thicknessFactor": 1},
                 "KHR_materials_dispersion": {"dispersion": 2.5}}})");
// `base` with `key` set to `value`.
json with(json base, const char* key, const json& value) {
  base[key] = value;
  return base;
}

const std::vector<LoaderCase> kRows = {
    // No pbrMetallicRoughness: glTF's defaults, a rough white metal.
    material("WithoutPbrItIsAGltfDefaultRoughWhiteMetal", {{"name", "plain"}},
             [](const Scene&, const Material& m) {
               EXPECT_EQ(m.metallic, 1.0f);
               EXPECT_EQ(m.roughness, 1.0f);
               expect_vec(m.base_color, vec3(1.0f));
               EXPECT_EQ(m.specular, 1.0f);
               EXPECT_TRUE(m.thin);
               EXPECT_FALSE(m.double_sided);
               EXPECT_FALSE(m.masked());
             }),
    // Every extension photonbound reads.
    material("EveryParameterIsKept", kAll,
             [](const Scene& s, const Material& all) {
               expect_vec(all.base_color, vec3(0.9f, 0.8f, 0.7f));
               EXPECT_NEAR(all.alpha, 0.5f, 1e-7f);
               EXPECT_NEAR(all.metallic, 0.25f, 1e-7f);
               EXPECT_NEAR(all.roughness, 0.5f, 1e-7f);
               EXPECT_NEAR(all.ior, 1.33f, 1e-6f);
               EXPECT_NEAR(all.specular, 0.5f, 1e-7f);
               expect_vec(all.specular_color, vec3(1, 2, 0.5f));
               EXPECT_NEAR(all.transmission, 0.75f, 1e-7f);
               EXPECT_FALSE(all.thin);
               // sigma = -ln(color) / distance per channel.
               expect_vec(all.attenuation, vec3(std::log(2.0f) / 2, 0.0f, std::log(4.0f) / 2));
               expect_vec(all.emission, vec3(4, 2, 0));
               EXPECT_TRUE(all.double_sided);
               EXPECT_TRUE(all.masked());
               EXPECT_NEAR(all.alpha_cutoff, 0.3f, 1e-7f);
               EXPECT_TRUE(has_warning(
                   s, "material 'all': KHR_materials_specular does not change a volume"));
             }),
    // Transmission without a volume: thin-walled.
    material("TransmissionWithoutAVolumeIsThinWalled",
             json::parse(R"({"name": "thin", "pbrMetallicRoughness": {"roughnessFactor": 0},
               "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}})"),
             [](const Scene& s, const Material& m) {
               EXPECT_TRUE(m.thin);
               EXPECT_FALSE(has_warning(s, "material 'thin'"));
             }),
    // A volume with thickness 0 is thin-walled too.
    material("AVolumeOfThicknessZeroIsThinWalled",
             json::parse(R"({"name": "zero", "pbrMetallicRoughness": {"roughnessFactor": 0},
               "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                              "KHR_materials_volume": {}}})"),
             [](const Scene&, const Material& m) { EXPECT_TRUE(m.thin); }),
    // KHR_materials_unlit: painted (tests/render/test_render_unlit.cpp); its emission is one of
    // the properties the extension says to ignore.
    material("UnlitIsPaintedAndEmitsNothing",
             json::parse(R"({"name": "baked", "emissiveFactor": [1, 1, 1],
               "extensions": {"KHR_materials_unlit": {}}})"),
             [](const Scene& s, const Material& m) {
               EXPECT_TRUE(m.unlit);
               EXPECT_FALSE(m.emits());
               EXPECT_FALSE(has_warning(s, "baked"));
             }),
    material("WithoutTheExtensionAMaterialIsLit", {{"name", "lit"}},
             [](const Scene&, const Material& m) { EXPECT_FALSE(m.unlit); }),
    // BLEND is coverage (tests/render/test_render_blend.cpp), drawn without a word.
    material("BlendIsReadWithoutAWarning", {{"name", "blend"}, {"alphaMode", "BLEND"}},
             [](const Scene& s, const Material& m) {
               EXPECT_EQ(m.alpha_mode, AlphaMode::Blend);
               EXPECT_FALSE(has_warning(s, "material 'blend'"));
             }),
    {.name = "APrimitiveWithoutMaterialGetsTheDefault",
     .edit = [](Doc& d) { d.j["meshes"][0]["primitives"][0].erase("material"); },
     .check =
         [](const Scene& s) {
           const Material& m = s.materials[s.meshes[0].material];
           EXPECT_EQ(m.name, "default");
           EXPECT_EQ(m.metallic, 0.0f);
           EXPECT_EQ(m.specular, 0.0f);  // Lambertian
           expect_vec(m.base_color, vec3(0.8f));
           EXPECT_TRUE(has_warning(s, "default"));
         }},
    refused("MetallicFactorAboveOne", pbr({{"metallicFactor", 1.5}}), "metallicFactor 1.5"),
    refused("NegativeRoughnessFactor", pbr({{"roughnessFactor", -0.1}}), "roughnessFactor -0.1"),
    refused("IorBelowOneWithoutTransmission", ext("KHR_materials_ior", {{"ior", 0.5}}), "ior 0.5"),
    refused("SpecularFactorAboveOne", ext("KHR_materials_specular", {{"specularFactor", 2}}),
            "specularFactor 2"),
    refused("NegativeTransmissionFactor",
            ext("KHR_materials_transmission", {{"transmissionFactor", -1}}),
            "transmissionFactor -1"),
    refused("ZeroAttenuationDistance", ext("KHR_materials_volume", {{"attenuationDistance", 0}}),
            "attenuationDistance 0"),
    refused("AttenuationColorAboveOne",
            ext("KHR_materials_volume", {{"attenuationColor", {2, 0, 0}}}),
            "attenuationColor must be 3 numbers in [0, 1]"),
    refused("ClearcoatFactorAboveOne", ext("KHR_materials_clearcoat", {{"clearcoatFactor", 1.5}}),
            "clearcoatFactor 1.5"),
    refused("NegativeClearcoatRoughness",
            ext("KHR_materials_clearcoat", {{"clearcoatRoughnessFactor", -1}}),
            "clearcoatRoughnessFactor -1"),
    refused("SheenColorAboveOne", ext("KHR_materials_sheen", {{"sheenColorFactor", {2, 0, 0}}}),
            "sheenColorFactor must be 3 numbers in [0, 1]"),
    refused("SheenRoughnessAboveOne", ext("KHR_materials_sheen", {{"sheenRoughnessFactor", 1.5}}),
            "sheenRoughnessFactor 1.5"),
    refused("AnisotropyStrengthAboveOne",
            ext("KHR_materials_anisotropy", {{"anisotropyStrength", 1.25}}),
            "anisotropyStrength 1.25"),
    refused("AnisotropyRotationNotANumber",
            ext("KHR_materials_anisotropy", {{"anisotropyRotation", "up"}}),
            "anisotropyRotation is not a number"),
    refused("NegativeIridescenceFactor",
            ext("KHR_materials_iridescence", {{"iridescenceFactor", -0.5}}),
            "iridescenceFactor -0.5"),
    refused("IridescenceIorBelowOne", ext("KHR_materials_iridescence", {{"iridescenceIor", 0.8}}),
            "iridescenceIor 0.8 must be finite and at least 1"),
    refused("NegativeIridescenceThickness",
            ext("KHR_materials_iridescence", {{"iridescenceThicknessMaximum", -1}}),
            "iridescenceThicknessMaximum -1 must be finite and at least 0"),
    refused("DiffuseTransmissionFactorAboveOne",
            ext("KHR_materials_diffuse_transmission", {{"diffuseTransmissionFactor", 1.5}}),
            "diffuseTransmissionFactor 1.5"),
    refused("NegativeDispersion", ext("KHR_materials_dispersion", {{"dispersion", -0.1}}),
            "dispersion -0.1 must be finite and at least 0"),
    refused("UnknownAlphaMode", {{"alphaMode", "SOMETIMES"}}, "unknown alphaMode 'SOMETIMES'"),
    refused("BaseColorTextureThatDoesNotExist", pbr({{"baseColorTexture", {{"index", 3}}}}),
            "texture 3, which does not"),
    {.name = "WrongLengthBaseColorIsMalformed",
     .edit =
         [](Doc& d) {
           material0(d) = pbr({{"baseColorFactor", {0.5, 0.5}}});
         },
     .error = {"malformed glTF: Array length of `baseColorFactor`"}},
    {.name = "MaterialIndexOutOfRange",
     .edit = [](Doc& d) { add_mesh_root(d, "odd", 0, 2, 5); },
     .error = {"mesh 'odd' primitive 0 refers to material 5, which does not exist"}},
    {.name = "IorBelowOne",
     .edit =
         [](Doc& d) {
           material0(d) = with(ext("KHR_materials_ior", {{"ior", 0.9}}), "name", "odd");
           material0(d)["extensions"]["KHR_materials_transmission"] = {{"transmissionFactor", 1}};
         },
     .error = {"material 'odd': ior 0.9 must be 0 or finite and >= 1"}},
    {.name = "BaseColorAboveOne",
     .edit =
         [](Doc& d) {
           material0(d) = with(pbr({{"baseColorFactor", {1.2, 0.5, 0.5, 1}}}), "name", "hot");
         },
     .error = {"material 'hot': baseColorFactor (1.2, 0.5, 0.5) is outside [0, 1]"}},
    {.name = "NegativeEmission",
     .edit =
         [](Doc& d) {
           material0(d) = ext("KHR_materials_emissive_strength", {{"emissiveStrength", -2}});
           material0(d)["name"] = "sink";
           material0(d)["emissiveFactor"] = {1, 1, 1};
         },
     .error = {"material 'sink': emission (emissiveFactor x emissiveStrength) must be finite and "
               ">= 0"}},
    // KHR_materials_dispersion: the value as given (20 / Abbe number, any value >= 0) on a
    // volume; on a thin wall, which does not refract, it is kept but warned to have no effect.
    {.name = "DispersionIsRead",
     .edit =
         [](Doc& d) {
           d.j["extensionsUsed"] = json::array({"KHR_materials_dispersion"});
           material0(d) = kPrism;
         },
     .check =
         [](const Scene& s) {
           const Material& m = s.materials[s.meshes[0].material];
           EXPECT_EQ(m.dispersion, 2.5f);
           EXPECT_FALSE(m.thin);
           EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
         }},
    {.name = "DispersionIsIgnoredOnThinWalls",
     .edit =
         [](Doc& d) {
           d.j["extensionsUsed"] = json::array({"KHR_materials_dispersion"});
           material0(d) = kPrism;
           material0(d)["extensions"]["KHR_materials_volume"]["thicknessFactor"] = 0;
         },
     .check =
         [](const Scene& s) {
           EXPECT_TRUE(s.materials[s.meshes[0].material].thin);
           EXPECT_TRUE(has_warning(s, "material 'prism': dispersion without KHR_materials_volume"));
         }},
    // KHR_materials_clearcoat: the factors, clearcoatTexture (R), clearcoatRoughnessTexture (G)
    // and clearcoatNormalTexture with its scale; tangents for the coat's normal texture alone;
    // not warned about as an ignored extension. clearcoatFactor 0 disables the whole layer.
    textured_material("ClearcoatIsReadWithItsTexturesAndTangents", "KHR_materials_clearcoat",
                      ext("KHR_materials_clearcoat", kClearcoat),
                      [](const Scene& s, const Material& m) {
                        EXPECT_NEAR(m.clearcoat, 0.75f, 1e-7f);
                        EXPECT_NEAR(m.clearcoat_roughness, 0.25f, 1e-7f);
                        EXPECT_TRUE(m.clearcoat_texture.present());
                        EXPECT_EQ(m.clearcoat_roughness_texture.texcoord, 1);
                        EXPECT_TRUE(m.clearcoat_normal_texture.present());
                        EXPECT_NEAR(m.clearcoat_normal_scale, 0.5f, 1e-7f);
                        EXPECT_EQ(s.meshes[0].tangents.size(), 3u);
                        EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
                      }),
    textured_material("ClearcoatFactorZeroDisablesTheLayer", "KHR_materials_clearcoat",
                      ext("KHR_materials_clearcoat", with(kClearcoat, "clearcoatFactor", 0)),
                      [](const Scene& s, const Material& o) {
                        EXPECT_EQ(o.clearcoat, 0.0f);
                        EXPECT_FALSE(o.clearcoat_texture.present() ||
                                     o.clearcoat_normal_texture.present());
                        EXPECT_TRUE(s.meshes[0].tangents.empty());
                      }),
    // KHR_materials_anisotropy: anisotropyStrength, anisotropyRotation (kept in (-pi, pi]) and
    // anisotropyTexture; tangents are made from the texture's coordinates without a TANGENT or
    // a normal texture (the direction needs them); not warned about. Strength 0 disables it,
    // and then no tangents are made; without texture coordinates or TANGENT it warns.
    textured_material("AnisotropyIsReadWithItsTextureAndMakesTangents", "KHR_materials_anisotropy",
                      ext("KHR_materials_anisotropy", kAnisotropy),
                      [](const Scene& s, const Material& m) {
                        EXPECT_NEAR(m.anisotropy, 0.6f, 1e-7f);
                        EXPECT_NEAR(m.anisotropy_rotation, 7.0 - 2.0 * M_PI, 1e-6);
                        EXPECT_TRUE(m.anisotropy_texture.present());
                        EXPECT_EQ(m.anisotropy_texture.texcoord, 1);
                        ASSERT_EQ(s.meshes[0].tangents.size(), 3u);
                        for (const glm::vec4& t : s.meshes[0].tangents)
                          EXPECT_NEAR(t.x, 1.0f, 1e-5f);  // u along +x
                        EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
                      }),
    textured_material("AnisotropyStrengthZeroDisablesIt", "KHR_materials_anisotropy",
                      ext("KHR_materials_anisotropy", with(kAnisotropy, "anisotropyStrength", 0)),
                      [](const Scene& s, const Material& o) {
                        EXPECT_EQ(o.anisotropy, 0.0f);
                        EXPECT_FALSE(o.anisotropy_texture.present());
                        EXPECT_TRUE(s.meshes[0].tangents.empty());
                      }),
    material("AnisotropyWithoutTexcoordsOrTangentsWarns",  // triangle_doc() has neither
             with(ext("KHR_materials_anisotropy", {{"anisotropyStrength", 1}}), "name", "brushed"),
             [](const Scene& s, const Material&) {
               EXPECT_TRUE(s.meshes[0].tangents.empty());
               EXPECT_TRUE(has_warning(s, "anisotropy without TANGENT or texture coordinates"))
                   << s.warnings[0];
             }),
    // KHR_materials_iridescence: the factor, the film's index, the thickness range (the minimum
    // may exceed the maximum) and both textures; iridescenceFactor 0 disables it, textures too.
    textured_material("IridescenceIsReadWithItsTextures", "KHR_materials_iridescence",
                      ext("KHR_materials_iridescence", kIridescence),
                      [](const Scene& s, const Material& m) {
                        EXPECT_NEAR(m.iridescence, 0.7f, 1e-7f);
                        EXPECT_NEAR(m.iridescence_ior, 1.8f, 1e-7f);
                        EXPECT_EQ(m.iridescence_thickness_minimum, 500.0f);
                        EXPECT_EQ(m.iridescence_thickness_maximum, 200.0f);
                        EXPECT_TRUE(m.iridescence_texture.present());
                        EXPECT_EQ(m.iridescence_thickness_texture.texcoord, 1);
                        EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
                      }),
    textured_material("IridescenceFactorZeroDisablesIt", "KHR_materials_iridescence",
                      ext("KHR_materials_iridescence", with(kIridescence, "iridescenceFactor", 0)),
                      [](const Scene&, const Material& o) {
                        EXPECT_EQ(o.iridescence, 0.0f);
                        EXPECT_FALSE(o.iridescence_texture.present() ||
                                     o.iridescence_thickness_texture.present());
                      }),
    // KHR_materials_diffuse_transmission: the factor and colour, the A texture and the sRGB
    // colour texture; a factor of 0 is none, textures too.
    textured_material("DiffuseTransmissionIsReadWithItsTextures",
                      "KHR_materials_diffuse_transmission",
                      ext("KHR_materials_diffuse_transmission", kDiffuseTransmission),
                      [](const Scene& s, const Material& m) {
                        EXPECT_EQ(m.diffuse_transmission, 0.25f);
                        expect_vec(m.diffuse_transmission_color, vec3(1, 0.5f, 0.25f));
                        EXPECT_TRUE(m.diffuse_transmission_texture.present());
                        EXPECT_EQ(m.diffuse_transmission_color_texture.texcoord, 1);
                        EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
                      }),
    textured_material("DiffuseTransmissionFactorZeroIsNone", "KHR_materials_diffuse_transmission",
                      ext("KHR_materials_diffuse_transmission",
                          with(kDiffuseTransmission, "diffuseTransmissionFactor", 0)),
                      [](const Scene&, const Material& o) {
                        EXPECT_EQ(o.diffuse_transmission, 0.0f);
                        EXPECT_FALSE(o.diffuse_transmission_texture.present() ||
                                     o.diffuse_transmission_color_texture.present());
                      }),
    // KHR_materials_sheen: sheenColorFactor, sheenRoughnessFactor, sheenColorTexture (sRGB) and
    // sheenRoughnessTexture (A); a black sheenColorFactor disables the layer, textures and all.
    textured_material("SheenIsReadWithItsTextures", "KHR_materials_sheen",
                      ext("KHR_materials_sheen", kSheen),
                      [](const Scene& s, const Material& m) {
                        expect_vec(m.sheen_color, vec3(0.9f, 0.5f, 0.25f));
                        EXPECT_NEAR(m.sheen_roughness, 0.75f, 1e-7f);
                        EXPECT_TRUE(m.sheen_color_texture.present());
                        EXPECT_EQ(m.sheen_roughness_texture.texcoord, 1);
                        EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
                      }),
    textured_material("BlackSheenDisablesTheLayer", "KHR_materials_sheen",
                      ext("KHR_materials_sheen", with(kSheen, "sheenColorFactor", {0, 0, 0})),
                      [](const Scene&, const Material& o) {
                        EXPECT_EQ(o.sheen_color, vec3(0.0f));
                        EXPECT_FALSE(o.sheen_color_texture.present() ||
                                     o.sheen_roughness_texture.present());
                      }),
};

using LoaderMaterials = LoaderCaseTest;
TEST_P(LoaderMaterials, Row) { run(); }
INSTANTIATE_TEST_SUITE_P(Table, LoaderMaterials, ::testing::ValuesIn(kRows), case_name);

}  // namespace
}  // namespace pb::test
