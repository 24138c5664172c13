// KHR_materials_pbrSpecularGlossiness read into glTF's dielectric: the loaded material's Bsdf
// equals the extension's BRDF, f = F D V + (1 - F) c_diff / pi with c_diff = diffuse (1 -
// max(specular)), F0 = specular, F90 = 1 and alpha = (1 - glossiness)^2 (glTF 2.0 appendix B's
// GGX and height-correlated V, written out here), from the factors alone and per texel from the
// specularGlossinessTexture (RGB sRGB specular, A linear glossiness).
#include "bsdf_test_util.h"
#include "gltf_expect.h"
#include "scene_builder.h"

#include "bsdf/bsdf.h"
#include "util/rng.h"
#include "world/world.h"

#include <cmath>

namespace {

using namespace pb::test;
using pb::Bsdf;
using pb::Scene;
using pb::vec3;

// The extension's BRDF for a grey specular s (then 1 - max F = 1 - F exactly), n = +z.
double reference(const vec3& wo, const vec3& wi, double s, double gloss, const vec3& diffuse,
                 int channel) {
  const double a = (1.0 - gloss) * (1.0 - gloss), a2 = a * a;
  const glm::dvec3 h = glm::normalize(glm::dvec3(wo) + glm::dvec3(wi));
  const double nv = wo.z, nl = wi.z, nh = h.z, vh = glm::dot(glm::dvec3(wo), h);
  const double f = s + (1.0 - s) * std::pow(1.0 - std::fabs(vh), 5.0);
  const double d = a2 / (M_PI * std::pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
  const double vis =
      0.5 / (nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2));
  const double c_diff = diffuse[channel] * (1.0 - s);
  return f * d * vis + (1.0 - f) * c_diff / M_PI;
}

void expect_brdf(const Bsdf& b, double s, double gloss, const vec3& diffuse, uint64_t seed) {
  pb::Rng rng(seed, 0, 0, pb::Stream::Test);
  int checked = 0;
  for (int k = 0; k < 400; ++k) {
    vec3 wo = random_unit(rng), wi = random_unit(rng);
    wo.z = std::fabs(wo.z);
    wi.z = std::fabs(wi.z);
    if (wo.z < 0.05f || wi.z < 0.05f) continue;
    const vec3 f = b.eval(wo, wi);
    for (int c = 0; c < 3; ++c) {
      const double want = reference(wo, wi, s, gloss, diffuse, c);
      EXPECT_NEAR(f[c], want, 2e-4 * want + 1e-6) << k << " " << c;
    }
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

class SpecGloss : public DecodeTest {};

TEST_F(SpecGloss, FactorsBecomeTheExtensionsBrdf) {
  // No pbrMetallicRoughness (whose default is a rough white metal): the extension's factors
  // alone decide, with the textureless c_diff folded into the base colour.
  Doc d;
  d.require({"KHR_materials_pbrSpecularGlossiness"});
  d.j["materials"][0] = json{{"name", "sg"},
                             {"extensions", json{{"KHR_materials_pbrSpecularGlossiness",
                                                  json{{"diffuseFactor", {0.6, 0.3, 0.2, 0.8}},
                                                       {"specularFactor", {0.1, 0.1, 0.1}},
                                                       {"glossinessFactor", 0.6}}}}}};
  const std::vector<float> quad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  d.mesh_node(json{{"attributes", json{{"POSITION", d.accessor(d.view(quad), kFloat, 4, "VEC3")}}},
                   {"indices", d.accessor(d.view(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}), kUShort,
                                          6, "SCALAR")}});
  const Scene s = pb::load_gltf(d.write(path("sg.gltf")));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const pb::Material& m = s.materials[s.meshes[0].material];
  EXPECT_EQ(m.metallic, 0.0f);
  EXPECT_NEAR(m.roughness, 0.4f, 1e-7f);
  EXPECT_NEAR(m.alpha, 0.8f, 1e-7f);
  EXPECT_NEAR(m.base_color.x, 0.6f * 0.9f, 1e-7f);
  const vec3 n(0, 0, 1);
  expect_brdf(Bsdf(m, n, n), 0.1, 0.6, vec3(0.6f, 0.3f, 0.2f), 901);
  // Out of range: refused with the material and the member named.
  d.j["materials"][0]["extensions"]["KHR_materials_pbrSpecularGlossiness"]["glossinessFactor"] =
      1.5;
  expect_error(d.write(path("bad.gltf")), "material 'sg': glossinessFactor 1.5 is outside [0, 1]");
}

TEST_F(SpecGloss, TheTextureSetsSpecularAndGlossinessPerTexel) {
  // A 1 x 1 RGBA texture: specular = factor x sRGB(R, G, B) (grey here), glossiness = factor x
  // A / 255, and c_diff's (1 - max specular) from those, at the hit.
  SceneBuilder b;
  pb::Material m;
  m.metallic = 0.0f;
  m.base_color = vec3(0.7f, 0.5f, 0.3f);
  m.specular_color = vec3(0.5f / 0.04f);
  m.sg_specular = vec3(0.5f);
  m.sg_glossiness = 0.9f;
  m.roughness = 1.0f - 0.9f;
  pb::Image im;
  im.name = "sg.png";
  im.width = im.height = 1;
  im.channels = 4;
  im.u8 = {128, 128, 128, 200};
  b.scene.images.push_back(im);
  m.specular_glossiness_texture.image = 0;
  b.scene.materials.push_back(m);
  b.quad(vec3(0), vec3(1, 0, 0), vec3(0, 1, 0), 0);
  b.point_light(vec3(0, 0, 5), vec3(1));
  const pb::World world(std::move(b.scene));
  pb::Hit h;
  h.u = h.v = 0.25f;
  const pb::Surface surface = world.surface(h);
  const double srgb = std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4);
  expect_brdf(surface.bsdf, 0.5 * srgb, 0.9 * 200.0 / 255.0, vec3(0.7f, 0.5f, 0.3f), 902);
}

}  // namespace
