// glTF's materials in whole renders of small in-memory scenes, against answers computed by hand:
// thin and volumetric glass (Fresnel and Beer-Lambert transmittance), double-sided emitters,
// alphaMode MASK cut-outs for camera rays, shadow rays and photons, a base colour texture with
// KHR_texture_transform, a normal texture, and glTF's default material (a rough metal).
#include "render/camera_paths.h"
#include "render/renderer.h"
#include "util/parallel.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pb {
namespace {

// Builds meshes in world space; each is one material.
struct SceneBuilder {
  Scene s;
  uint32_t material(const Material& m) {
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
  }
  // Quad c +- u +- v, front u x v, uv (0, 0) at c - u + v, u to c + u, v to c - v.
  Mesh& quad(vec3 c, vec3 u, vec3 v, uint32_t mat) {
    Mesh m;
    m.positions = {c - u - v, c + u - v, c + u + v, c - u + v};
    m.normals.assign(4, glm::normalize(glm::cross(u, v)));
    m.texcoords[0] = {vec2(0, 1), vec2(1, 1), vec2(1, 0), vec2(0, 0)};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = mat;
    s.meshes.push_back(m);
    return s.meshes.back();
  }
  // Closed box [lo, hi], faces outward.
  void box(vec3 lo, vec3 hi, uint32_t mat) {
    const vec3 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {1.0f, -1.0f}) {
        vec3 n(0.0f), u(0.0f), v(0.0f);
        n[axis] = sign;
        u[(axis + 1) % 3] = h[(axis + 1) % 3];
        v[(axis + 2) % 3] = h[(axis + 2) % 3];
        if (glm::dot(glm::cross(u, v), n) < 0.0f) std::swap(u, v);
        quad(c + n * h[axis], u, v, mat);
      }
  }
  void camera(vec3 position, vec3 forward, vec3 up, float yfov) {
    Camera c;
    c.position = position;
    c.forward = glm::normalize(forward);
    c.up = glm::normalize(up);
    c.right = glm::cross(c.forward, c.up);
    c.yfov = yfov;
    s.cameras.push_back(c);
  }
  Scene done() {
    for (const Mesh& m : s.meshes)
      for (const vec3& p : m.positions) s.bounds.extend(p);
    s.source = "in memory";
    return s;
  }
};

RenderOptions options(int size, Method method = Method::PPM) {
  RenderOptions o;
  o.method = method;
  o.width = o.height = size;
  o.passes = 1;
  o.photons_per_pass = 2000;
  o.max_depth = 32;
  o.progress = ProgressMode::Never;
  return o;
}

// Pixel radiances after `passes` passes.
std::vector<float> render(Scene scene, const RenderOptions& o, uint64_t passes = 1) {
  Renderer r(std::move(scene), o);
  for (uint64_t p = 0; p < passes; ++p) r.step();
  FilmImage img;
  r.develop(&img);
  return img.radiance;
}

// The mean of one channel over an image's pixels and its standard error: for images whose
// pixels are independent samples of one value (a tiny field of view on a uniform scene).
struct PixelMean {
  double mean, se;
};
PixelMean pixel_mean(const std::vector<float>& image, int channel) {
  const size_t n = image.size() / 3;
  double sum = 0.0, sum2 = 0.0;
  for (size_t p = 0; p < n; ++p) {
    const double v = image[3 * p + size_t(channel)];
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / double(n);
  return {mean, std::sqrt(std::max(0.0, sum2 / double(n) - mean * mean) / double(n - 1))};
}

Material emitter(vec3 le, bool double_sided = false) {
  Material m = Material::lambertian(vec3(0.0f));
  m.emission = le;
  m.double_sided = double_sided;
  return m;
}

// glTF's doubleSided false is back-face culling: the camera's first ray passes through the back
// of a single-sided face. The camera at z = 2 looks along -z at a quad at z = 0 whose front
// faces -z (away from it), and behind it at a one-sided emitter of radiance 1 facing the camera.
// Culled, every pixel sees the emitter itself: exactly 1. Double-sided, it sees the quad's back,
// which nothing lights (the emitter is behind the quad, photons land on its front only, and
// next-event shadow rays from the back side pass through the quad): exactly 0. A transmissive
// single-sided quad keeps its back: thin glass between, the pixel sees the emitter through it,
// less what Fresnel reflects.
TEST(MaterialRender, TheCameraSeesThroughTheBackOfASingleSidedFace) {
  auto scene = [](const Material& between) {
    SceneBuilder b;
    b.quad(vec3(0), vec3(0, 1, 0), vec3(1, 0, 0), b.material(between));  // front -z
    b.quad(vec3(0, 0, -3), vec3(4, 0, 0), vec3(0, 4, 0), b.material(emitter(vec3(1.0f))));
    b.camera(vec3(0, 0, 2), vec3(0, 0, -1), vec3(0, 1, 0), 0.3f);
    return b.done();
  };
  Material single = Material::lambertian(vec3(0.5f)), both = single;
  both.double_sided = true;
  Material glass = Material::glass(1.5f, true);
  for (Method m : {Method::PPM, Method::SPPM}) {
    const RenderOptions o = options(4, m);
    for (float l : render(scene(single), o, 2)) EXPECT_EQ(l, 1.0f);
    for (float l : render(scene(both), o, 2)) EXPECT_EQ(l, 0.0f);
  }
  // The share of the view culling leaves out (the note the command line prints).
  {
    const RenderOptions o = options(4);
    const Renderer culled(scene(single), o), drawn(scene(both), o);
    EXPECT_EQ(culled_view_share(culled.world(), culled.camera()), 1.0);
    EXPECT_EQ(culled_view_share(drawn.world(), drawn.camera()), 0.0);
  }
  // PPM follows both of the glass's delta branches (SPPM picks one at random per pass).
  for (float l : render(scene(glass), options(4), 1)) {
    EXPECT_GT(l, 0.8f);  // through thin glass at normal incidence, less Schlick's F
    EXPECT_LT(l, 0.99f);
  }
}

// World::camera_enclosure (the warning that an environment cannot light what the camera sees):
// a camera inside a closed double-sided box, with a smaller box beside it, is enclosed, the
// outer box last in every direction; single-sided, the box's inner faces are its backs, which
// the camera sees through (camera_hit), so the environment is in view and nothing is enclosed;
// with one face of the double-sided box missing the camera sees out as well.
TEST(MaterialRender, CameraEnclosureNamesTheOutermostShell) {
  auto world_of = [](bool double_sided, bool open) {
    SceneBuilder b;
    int face = 0;
    auto name_faces = [&] {
      for (Mesh& m : b.s.meshes)
        if (m.name.empty()) m.name = "face " + std::to_string(face++);
    };
    Material m = Material::lambertian(vec3(0.5f));
    m.double_sided = double_sided;
    const uint32_t mat = b.material(m);
    const vec3 c(0.0f), h(5.0f);
    const vec3 x(h.x, 0, 0), y(0, h.y, 0), z(0, 0, h.z);
    b.quad(c + x, y, z, mat);
    b.quad(c - x, z, y, mat);
    b.quad(c + y, z, x, mat);
    b.quad(c - y, x, z, mat);
    b.quad(c + z, x, y, mat);
    if (!open) b.quad(c - z, y, x, mat);
    name_faces();
    b.quad(vec3(2, 0, 0), vec3(0.5f, 0, 0), vec3(0, 0.5f, 0), mat).name = "inner";
    b.s.environment = Environment{"the sky", 1, 1, {vec3(1.0f)}};
    return std::make_unique<World>(b.done());
  };
  const auto closed = world_of(true, false);
  const auto e = closed->camera_enclosure(vec3(0.5f, 0.5f, 0.5f));
  ASSERT_TRUE(e.has_value());
  // Every direction ends on one of the outer box's faces: six meshes, the share of each about
  // a sixth, all above a tenth; the three most frequent are listed.
  ASSERT_EQ(e->outermost.size(), 3u);
  for (const auto& [mesh, share] : e->outermost) {
    EXPECT_EQ(mesh.rfind("face ", 0), 0u) << mesh;
    EXPECT_GT(share, 0.1);
  }
  EXPECT_FALSE(world_of(false, false)->camera_enclosure(vec3(0.5f)).has_value());
  EXPECT_FALSE(world_of(true, true)->camera_enclosure(vec3(0.5f)).has_value());
}

TEST(MaterialRender, VolumetricGlassSlabTransmitsByFresnelAndBeerLambert) {
  // The centre pixel looks along -z at normal incidence through a slab (z in [-1.2, -1], ior 1.5,
  // base b, attenuation colour c at distance 0.1, so tau = c^(0.2 / 0.1) per crossing) at an
  // emitter of radiance 1. The PPM camera path sums every internal bounce (depth 32):
  //   T = b^2 (1 - R)^2 tau / (1 - R^2 tau^2),  R = 0.04.
  SceneBuilder b;
  Material glass = Material::glass(1.5f, false);
  glass.base_color = vec3(0.9f, 0.8f, 0.7f);
  const vec3 c(0.5f, 0.25f, 1.0f);
  glass.attenuation = -glm::log(c) / 0.1f;
  b.box(vec3(-1, -1, -1.2f), vec3(1, 1, -1), b.material(glass));
  b.quad(vec3(0, 0, -3), vec3(4, 0, 0), vec3(0, 4, 0), b.material(emitter(vec3(1.0f))));
  b.camera(vec3(0, 0, 2), vec3(0, 0, -1), vec3(0, 1, 0), 0.5f);
  const std::vector<float> l = render(b.done(), options(1));
  for (int ch = 0; ch < 3; ++ch) {
    const double base = glass.base_color[ch], tau = double(c[ch]) * c[ch], r = 0.04;
    const double t = base * base * (1 - r) * (1 - r) * tau / (1 - r * r * tau * tau);
    EXPECT_NEAR(l[size_t(ch)], t, 2e-6) << "channel " << ch;
  }
}

TEST(MaterialRender, ADispersiveSlabTransmitsEachChannelByItsOwnIndex) {
  // The slab above, wide and without attenuation, with KHR_materials_dispersion 3 (Abbe number
  // 6.7), seen at 0.7 rad from its normal: each channel refracts by its own index n_c and goes
  // on alone, so the camera sees T_c = b_c^2 (1 - F_c)^2 / (1 - F_c^2) of the emitter, F_c the
  // exact Fresnel term at 0.7 rad for n_c (the same at both faces, inside at the channel's own
  // angle). PPM splits every branch: exact (2e-6). SPPM draws one branch per vertex, inside the
  // slab only the reflection or its own channel's refraction (Bsdf::sample_delta's tint): its
  // 16 x 16 pixels at a 0.005 rad field of view see the same slab, so their means after 256
  // passes are independent samples of one value, within 4 of their standard errors of T_c.
  const float theta = 0.7f;
  SceneBuilder b;
  Material glass = Material::glass(1.5f, false);
  glass.base_color = vec3(0.9f, 0.8f, 0.7f);
  glass.dispersion = 3.0f;
  b.box(vec3(-30, -30, -1.2f), vec3(30, 30, -1), b.material(glass));
  b.quad(vec3(0, 0, -3), vec3(60, 0, 0), vec3(0, 60, 0), b.material(emitter(vec3(1.0f))));
  b.camera(vec3(0, 0, 2), vec3(std::sin(theta), 0, -std::cos(theta)), vec3(0, 1, 0), 0.005f);
  double want[3];
  for (int ch = 0; ch < 3; ++ch) {
    const double f = fresnel_dielectric(std::cos(theta), dispersed_ior(1.5f, 3.0f, ch));
    const double base = glass.base_color[ch];
    want[ch] = base * base * (1 - f) * (1 - f) / (1 - f * f);
  }
  const std::vector<float> ppm = render(b.done(), options(1));
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(ppm[size_t(ch)], want[ch], 2e-6) << "channel " << ch;
  EXPECT_GT(std::fabs(want[2] - want[0]), 0.01);  // the channels' Fresnel terms differ
  const std::vector<float> sppm = render(b.done(), options(16, Method::SPPM), 256);
  for (int ch = 0; ch < 3; ++ch) {
    const PixelMean m = pixel_mean(sppm, ch);
    EXPECT_GT(m.se, 0.0);
    EXPECT_NEAR(m.mean, want[ch], 4.0 * m.se) << "channel " << ch;
  }
}

TEST(MaterialRender, ARoughThinSheetTransmitsItsBlurredLobe) {
  // A thin rough sheet (KHR_materials_transmission 1, no volume) in front of an emitter of
  // radiance 1 that fills everything behind it, seen at 0.5 rad: each pixel sees T = integral
  // of baseColor (1 - F) D V |cos| over the directions through the sheet (the GGX lobe mirrored
  // through it; Schlick's F, f0 0.04), by a 600 x 600 midpoint rule here. SPPM follows the lobe
  // through the sheet: at roughness 0.5 the emitter is sampled through it (next-event), at 0.2
  // only hit (Bsdf::glass_lit_directly). Its 16 x 16 pixels (a 0.005 rad field of view) are
  // independent samples of T after 256 passes, within 4 of their standard errors (and 0.5% for
  // the quadrature). PPM renders the sheet as smooth glass, base (1 - F(cos)), exactly.
  const float theta = 0.5f;
  const double zo = std::cos(theta), so = std::sin(theta);
  for (float roughness : {0.5f, 0.2f}) {
    SceneBuilder b;
    Material sheet = Material::glass(1.5f, true);
    sheet.roughness = roughness;
    sheet.base_color = vec3(0.9f, 0.8f, 0.7f);
    sheet.double_sided = true;
    b.quad(vec3(0), vec3(50, 0, 0), vec3(0, 50, 0), b.material(sheet));
    b.quad(vec3(0, 0, -1), vec3(1000, 0, 0), vec3(0, 1000, 0), b.material(emitter(vec3(1.0f))));
    b.camera(vec3(0, 0, 2), vec3(so, 0, -zo), vec3(0, 1, 0), 0.005f);
    const double a = double(roughness) * roughness, a2 = a * a;
    double lobe = 0.0;
    const int q = 600;
    for (int i = 0; i < q; ++i)
      for (int j = 0; j < q; ++j) {  // wi mirrored to wo's side: (r cos phi, r sin phi, z)
        const double z = (i + 0.5) / q, phi = 2.0 * kPiD * (j + 0.5) / q, r = std::sqrt(1 - z * z);
        const glm::dvec3 h =
            glm::normalize(glm::dvec3(so + r * std::cos(phi), r * std::sin(phi), zo + z));
        const double c = h.z * h.z * (a2 - 1.0) + 1.0, d = a2 / (kPiD * c * c);
        const double v =
            0.5 / (z * std::sqrt(zo * zo * (1 - a2) + a2) + zo * std::sqrt(z * z * (1 - a2) + a2));
        const double f = 0.04 + 0.96 * std::pow(1.0 - (so * h.x + zo * h.z), 5.0);
        lobe += (1.0 - f) * d * v * z;
      }
    lobe *= 2.0 * kPiD / (double(q) * q);
    const std::vector<float> sppm = render(b.done(), options(16, Method::SPPM), 256);
    const std::vector<float> ppm = render(b.done(), options(1));
    const double smooth = 1.0 - (0.04 + 0.96 * std::pow(1.0 - zo, 5.0));
    for (int ch = 0; ch < 3; ++ch) {
      const PixelMean m = pixel_mean(sppm, ch);
      const double want = sheet.base_color[ch] * lobe;
      EXPECT_NEAR(m.mean, want, 4.0 * m.se + 0.005 * want) << roughness << " channel " << ch;
      EXPECT_NEAR(ppm[size_t(ch)], sheet.base_color[ch] * smooth, 2e-6) << "channel " << ch;
    }
    // Single scattering loses some (at roughness 0.5, lobe = 0.905 smooth).
    EXPECT_LT(lobe, (roughness > 0.3f ? 0.95 : 1.0) * smooth) << roughness;
  }
}

TEST(MaterialRender, ADiffuselyTransmittingSheetPassesItsColour) {
  // KHR_materials_diffuse_transmission 1 without a specular layer: f = colour / pi through the
  // sheet, so in front of an emitter of radiance 1 that fills everything behind it the camera
  // sees the colour exactly, whatever the angle. SPPM follows the sheet and samples the emitter
  // through it (next-event): its 16 x 16 pixels are samples of the colour after 128 passes,
  // within 4 standard errors. PPM's fixed points cannot follow it: the sheet is then a plain
  // diffuse reflector whose lit side faces away, 0 exactly.
  SceneBuilder b;
  Material sheet = Material::lambertian(vec3(0.5f));
  sheet.diffuse_transmission = 1.0f;
  sheet.diffuse_transmission_color = vec3(0.8f, 0.6f, 0.4f);
  sheet.double_sided = true;
  b.quad(vec3(0), vec3(50, 0, 0), vec3(0, 50, 0), b.material(sheet));
  b.quad(vec3(0, 0, -1), vec3(1000, 0, 0), vec3(0, 1000, 0), b.material(emitter(vec3(1.0f))));
  b.camera(vec3(0, 0, 2), vec3(0.4f, 0, -1), vec3(0, 1, 0), 0.005f);
  const std::vector<float> sppm = render(b.done(), options(16, Method::SPPM), 128);
  for (int ch = 0; ch < 3; ++ch) {
    const PixelMean m = pixel_mean(sppm, ch);
    EXPECT_NEAR(m.mean, sheet.diffuse_transmission_color[ch], 4.0 * m.se + 1e-6) << ch;
    EXPECT_GT(m.se, 0.0);
  }
  EXPECT_EQ(render(b.done(), options(1)), std::vector<float>(3, 0.0f));
}

TEST(MaterialRender, TransmissionPpmCannotFollowIsNamed) {
  // The materials PPM renders smooth though rough (main.cpp warns with their names): rough
  // transmission, thin or not, or a roughness texture; not smooth glass, an opaque material,
  // or a metal (which transmits nothing).
  SceneBuilder b;
  auto named = [&](const char* name, float roughness, float transmission, float metallic) {
    Material m = Material::glass(1.5f, false);
    m.name = name;
    m.roughness = roughness;
    m.transmission = transmission;
    m.metallic = metallic;
    return b.material(m);
  };
  for (uint32_t m : {named("frosted", 0.5f, 1.0f, 0.0f), named("clear", 0.01f, 1.0f, 0.0f),
                     named("opaque", 0.5f, 0.0f, 0.0f), named("metal", 0.5f, 1.0f, 1.0f),
                     named("veiled", 0.04f, 0.3f, 0.0f), named("leaf", 0.01f, 0.0f, 0.0f)})
    b.quad(vec3(0, 0, -float(m)), vec3(1, 0, 0), vec3(0, 1, 0), m);
  b.quad(vec3(0, 0, 3), vec3(1, 0, 0), vec3(0, -1, 0), b.material(emitter(vec3(1.0f))));
  b.camera(vec3(0, 0, 2), vec3(0, 0, -1), vec3(0, 1, 0), 0.5f);
  const World world(b.done());
  b.s.materials[5].diffuse_transmission = 0.5f;  // the leaf transmits diffusely
  EXPECT_EQ(World(b.done()).followed_transmission_names(), "materials 'frosted', 'veiled', 'leaf'");
  EXPECT_EQ(world.followed_transmission_names(), "materials 'frosted', 'veiled'");
}

TEST(MaterialRender, ASmoothClearCoatOverBlackMirrorsByItsViewWeight) {
  // KHR_materials_clearcoat over a black base: the camera sees the coat's mirror image of an
  // emitter of radiance 2, weighted by k = clearcoat (0.04 + 0.96 (1 - cos theta)^5) at the
  // view angle theta. The base is black, so photons and next-event add nothing. PPM follows the
  // mirror branch: exact to float rounding (2e-6). SPPM picks the branch by delta_probability
  // p per pass, dividing by it: a pass gives 2k / p with probability p, else 0, so 1024 passes
  // are within 4 standard deviations, 4 x 2k sqrt((1 - p) / (1024 p)) (about 2%).
  for (double theta : {0.4, 1.1}) {
    SceneBuilder b;
    Material coat = Material::lambertian(vec3(0.0f));
    coat.clearcoat = 0.8f;
    b.quad(vec3(0), vec3(20, 0, 0), vec3(0, 0, -20), b.material(coat));  // front +y
    const vec3 d(0.0f, -float(std::cos(theta)), -float(std::sin(theta)));
    const vec3 mirror(0.0f, -d.y, d.z), hit = vec3(0, 1, 0) + d / -d.y;
    const vec3 c = hit + 5.0f * mirror, u = glm::normalize(glm::cross(mirror, vec3(1, 0, 0)));
    b.quad(c, vec3(10, 0, 0), 10.0f * u, b.material(emitter(vec3(2.0f), true)));
    b.camera(vec3(0, 1, 0), d, vec3(0.0f, -d.z, d.y), 0.01f);
    const double k = 0.8 * (0.04 + 0.96 * std::pow(1.0 - std::cos(theta), 5.0));
    const std::vector<float> ppm = render(b.done(), options(1));
    EXPECT_NEAR(ppm[0], 2.0 * k, 2e-6) << theta;
    const double p = Bsdf(coat, vec3(0, 1, 0), vec3(0, 1, 0)).delta_probability(-d);
    EXPECT_GT(p, 0.9);
    const std::vector<float> sppm = render(b.done(), options(1, Method::SPPM), 1024);
    EXPECT_NEAR(sppm[0], 2.0 * k, 4.0 * 2.0 * k * std::sqrt((1.0 - p) / (1024.0 * p))) << theta;
  }
}

TEST(MaterialRender, ACoatedEmitterIsSeenDarkenedByTheCoat) {
  // The camera looks at a coated emitter (radiance 2, clearcoat 0.6, black base) head-on and
  // at 1.2 rad: it sees 2 (1 - 0.6 (0.04 + 0.96 (1 - cos)^5)), exactly (PPM, 2e-6).
  for (double theta : {0.0, 1.2}) {
    SceneBuilder b;
    Material m = emitter(vec3(2.0f));
    m.clearcoat = 0.6f;
    b.quad(vec3(0), vec3(5, 0, 0), vec3(0, 5, 0), b.material(m));  // front +z
    const vec3 eye(0.0f, -2.0f * float(std::sin(theta)), 2.0f * float(std::cos(theta)));
    b.camera(eye, -eye, glm::normalize(vec3(0.0f, float(std::cos(theta)), float(std::sin(theta)))),
             0.01f);
    const double want = 2.0 * (1.0 - 0.6 * (0.04 + 0.96 * std::pow(1.0 - std::cos(theta), 5.0)));
    EXPECT_NEAR(render(b.done(), options(1))[0], want, 2e-6) << theta;
  }
}

TEST(MaterialRender, ThinGlassTransmitsOnceStraightThrough) {
  // A thin-walled pane (no volume): the ray goes straight through once, T = b (1 - 0.04), and
  // no attenuation applies (a thin wall has no inside).
  SceneBuilder b;
  Material thin = Material::glass(1.5f, true);
  thin.base_color = vec3(0.9f, 0.8f, 0.7f);
  thin.attenuation = vec3(5.0f);  // ignored: thin
  b.quad(vec3(0, 0, -1), vec3(1, 0, 0), vec3(0, 1, 0), b.material(thin));
  b.quad(vec3(0, 0, -3), vec3(4, 0, 0), vec3(0, 4, 0), b.material(emitter(vec3(2.0f))));
  b.camera(vec3(0, 0, 2), vec3(0, 0, -1), vec3(0, 1, 0), 0.5f);
  const std::vector<float> l = render(b.done(), options(1));
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(l[size_t(ch)], 2.0 * thin.base_color[ch] * 0.96, 2e-6);
}

TEST(MaterialRender, DoubleSidedEmitterIsSeenFromBehind) {
  // The camera (at z = -2) looks at the emitter's back: its front faces +z, away from it.
  for (bool both : {false, true}) {
    SceneBuilder b;
    b.quad(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0), b.material(emitter(vec3(3.0f), both)));
    b.quad(vec3(0, 0, 3), vec3(4, 0, 0), vec3(0, 4, 0),
           b.material(Material::lambertian(vec3(0.5f))));
    b.camera(vec3(0, 0, -2), vec3(0, 0, 1), vec3(0, 1, 0), 0.5f);
    for (Method m : {Method::PPM, Method::SPPM}) {
      const std::vector<float> l = render(b.done(), options(1, m), 2);
      EXPECT_NEAR(l[0], both ? 3.0f : 0.0f, 1e-6f) << "double-sided " << both;
    }
  }
}

// Lambertian plane y = 0 (rho 0.5) under a point light of intensity 10 at height 1, a camera 3 m
// above looking down; an occluder at y = 0.5 between them (2 x 2 texels, left column alpha 0,
// right alpha 1, NEAREST, cutoff 0.5).
Scene masked_scene(bool masked) {
  SceneBuilder b;
  b.quad(vec3(0), vec3(5, 0, 0), vec3(0, 0, -5), b.material(Material::lambertian(vec3(0.5f))));
  Material leaf = Material::lambertian(vec3(0.3f));
  leaf.alpha_mode = masked ? AlphaMode::Mask : AlphaMode::Opaque;
  leaf.base_color_texture.image = 0;
  leaf.base_color_texture.nearest = true;
  b.quad(vec3(0, 0.5f, 0), vec3(0.5f, 0, 0), vec3(0, 0, -0.5f), b.material(leaf));
  b.s.images.push_back(Image{"alpha", 2, 1, 4, {200, 200, 200, 0, 200, 200, 200, 255}, {}});
  PunctualLight l;
  l.position = vec3(0, 1, 0);
  l.intensity = vec3(10.0f);
  b.s.lights.push_back(l);
  b.camera(vec3(0, 3, 0), vec3(0, -1, 0), vec3(0, 0, -1), 0.6f);
  return b.done();
}

// Equal to float rounding, 1e-5 relative (a few ulps through a path of products), in at least
// 95% of the pixel-channels and within 10% in all: an ulp in a photon's power can flip a Russian
// roulette decision (about 1e-7 per decision, 1e-3 over a render here; its hit rounding depends
// on the CPU's Embree kernels), and that photon then lands elsewhere.
void expect_close(const std::vector<float>& a, const std::vector<float>& b) {
  ASSERT_EQ(a.size(), b.size());
  size_t off = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    off += !(std::fabs(a[k] - b[k]) <= 1e-5f * std::fabs(b[k]));
    EXPECT_NEAR(a[k], b[k], 0.1f * std::fabs(b[k])) << k;
  }
  EXPECT_LE(off, a.size() / 20);
}

TEST(MaterialRender, VertexColoursMultiplyTheBaseColourAndItsAlpha) {
  // glTF's COLOR_0 multiplies the base colour: a room whose floor has the constant vertex colour
  // c over a white factor renders as the floor of factor c, in both methods, to float rounding
  // (the barycentric weights sum to 1 within 1 ulp, and every random number is the same).
  auto room = [](vec3 factor, const std::vector<glm::vec4>& colours, bool wall) {
    SceneBuilder b;
    Mesh& floor = b.quad(vec3(0, -1, 0), vec3(1, 0, 0), vec3(0, 0, -1),
                         b.material(Material::lambertian(factor)));  // front +y
    floor.colors = colours;
    b.quad(vec3(0, 1, 0), vec3(0.2f, 0, 0), vec3(0, 0, 0.2f), b.material(emitter(vec3(5.0f))));
    if (wall)  // front +z, toward the camera
      b.quad(vec3(0, 0, -1), vec3(1, 0, 0), vec3(0, 1, 0),
             b.material(Material::lambertian(vec3(0.5f))));
    b.camera(vec3(0, 0, 2), vec3(0, -0.5f, -1), vec3(0, 1, 0), 0.9f);
    return b.done();
  };
  const vec3 c(0.9f, 0.4f, 0.2f);
  const std::vector<glm::vec4> constant(4, glm::vec4(c, 1.0f));
  for (Method method : {Method::PPM, Method::SPPM}) {
    const std::vector<float> coloured =
        render(room(vec3(1.0f), constant, true), options(8, method), 3);
    expect_close(coloured, render(room(c, {}, true), options(8, method), 3));
    EXPECT_NE(coloured, render(room(vec3(1.0f), {}, true), options(8, method), 3));
  }
  // Its alpha multiplies the base colour's: under MASK (cutoff 0.5), an alpha of 0.3 at every
  // vertex cuts the floor out, so the camera sees through it to nothing (every pixel 0, the
  // wall gone), and an alpha of 0.7 keeps it.
  auto masked = [&](float alpha) {
    Scene s =
        room(vec3(1.0f), std::vector<glm::vec4>(4, glm::vec4(1.0f, 1.0f, 1.0f, alpha)), false);
    s.materials[s.meshes[0].material].alpha_mode = AlphaMode::Mask;
    s.materials[s.meshes[0].material].alpha_cutoff = 0.5f;
    return render(std::move(s), options(8), 1);
  };
  const std::vector<float> opaque = render(room(vec3(1.0f), {}, false), options(8), 1);
  expect_close(masked(0.7f), opaque);
  size_t lit = 0;
  for (float v : opaque) lit += v > 0.0f;
  EXPECT_GT(lit, 30u);
  EXPECT_EQ(masked(0.3f), std::vector<float>(opaque.size(), 0.0f));
}

TEST(MaterialRender, MaskCutOutsPassCameraRaysShadowRaysAndPhotons) {
  // Plane points (x, 0, z) with x < 0, |z| < 0.5 see the light through the transparent left
  // column of the occluder (the segment to the light crosses y = 0.5 at x / 2); their radiance is
  // the unoccluded 5 / (pi d^3). With x > 0 the segment crosses the opaque column: shadow (0 with
  // next-event estimation). Camera rays pass the left column to the plane.
  const RenderOptions o = options(8);
  Renderer r(masked_scene(true), o);
  r.step();
  int lit = 0, dark = 0;
  for (size_t k = 0; k < r.camera_pass().points.size(); ++k) {
    const VisiblePoint& p = r.camera_pass().points[k];
    if (std::fabs(p.position.y) > 1e-4f) continue;  // on the occluder
    const double d =
        std::sqrt(double(p.position.x) * p.position.x + 1 + p.position.z * p.position.z);
    const PointEstimate e = estimate(r.states()[k], 1, double(o.photons_per_pass));
    const bool through = p.position.x < 0.0f && std::fabs(p.position.z) < 0.5f;
    const bool blocked = p.position.x > 0.0f && std::fabs(p.position.z) < 0.5f;
    if (through) {
      EXPECT_NEAR(e.radiance.x, 5.0 / (kPiD * d * d * d), 1e-5) << p.position.x;
      ++lit;
    }
    if (blocked) {
      EXPECT_EQ(e.radiance.x, 0.0) << p.position.x;
      ++dark;
    }
  }
  EXPECT_GT(lit, 0);
  EXPECT_GT(dark, 0);
  // The camera sees the plane through the cut-out: more plane points than without the mask.
  Renderer opaque(masked_scene(false), o);
  size_t on_plane_masked = 0, on_plane_opaque = 0;
  for (const VisiblePoint& p : r.camera_pass().points)
    on_plane_masked += std::fabs(p.position.y) < 1e-4f;
  for (const VisiblePoint& p : opaque.camera_pass().points)
    on_plane_opaque += std::fabs(p.position.y) < 1e-4f;
  EXPECT_GT(on_plane_masked, on_plane_opaque);
  // Photons pass too: with all light from photons the plane behind the cut-out is lit (within
  // 20% after 20 passes of 20000 photons: kernel estimate, radius from the default) and the
  // shadowed half gets nothing.
  RenderOptions po = options(8);
  po.direct = DirectMode::Photons;
  po.photons_per_pass = 20000;
  Renderer pr(masked_scene(true), po);
  for (int i = 0; i < 20; ++i) pr.step();
  double through_sum = 0.0, exact_sum = 0.0, blocked_sum = 0.0;
  for (size_t k = 0; k < pr.camera_pass().points.size(); ++k) {
    const VisiblePoint& p = pr.camera_pass().points[k];
    if (std::fabs(p.position.y) > 1e-4f || std::fabs(p.position.z) > 0.4f) continue;
    const double d =
        std::sqrt(double(p.position.x) * p.position.x + 1 + p.position.z * p.position.z);
    const double l = estimate(pr.states()[k], 20, double(po.photons_per_pass)).radiance.x;
    if (p.position.x < -0.1f) {
      through_sum += l;
      exact_sum += 5.0 / (kPiD * d * d * d);
    } else if (p.position.x > 0.1f) {
      blocked_sum += l;
    }
  }
  EXPECT_NEAR(through_sum, exact_sum, 0.2 * exact_sum);
  EXPECT_LT(blocked_sum, 0.05 * exact_sum);
}

TEST(MaterialRender, BaseColourTextureWithTransformAtThePoints) {
  // A Lambertian plane with a 2 x 2 NEAREST texture under KHR_texture_transform offset (0.5, 0):
  // a point's reflectance is the sRGB-decoded texel at (u + 0.5, v), so L = tex / pi x 10 cos /
  // d^2 exactly with next-event estimation.
  SceneBuilder b;
  Material m = Material::lambertian(vec3(1.0f));
  m.base_color_texture.image = 0;
  m.base_color_texture.nearest = true;
  set_texture_transform(m.base_color_texture, vec2(0.5f, 0.0f), 0.0f, vec2(1.0f));
  b.quad(vec3(0), vec3(1, 0, 0), vec3(0, 0, -1), b.material(m));
  b.s.images.push_back(Image{"c", 2, 2, 3, {255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128}, {}});
  PunctualLight light;
  light.position = vec3(0, 1, 0);
  light.intensity = vec3(10.0f);
  b.s.lights.push_back(light);
  b.camera(vec3(0, 3, 0), vec3(0, -1, 0), vec3(0, 0, -1), 0.6f);
  const RenderOptions o = options(8);
  Renderer r(b.done(), o);
  r.step();
  const Image& im = r.world().scene().images[0];
  ASSERT_EQ(r.camera_pass().points.size(), 64u);
  for (size_t k = 0; k < 64; ++k) {
    const vec3 p = r.camera_pass().points[k].position;
    // The quad spans x, z in [-1, 1]; u = (x + 1) / 2 and v = (z + 1) / 2 (v toward +z).
    const float s = (p.x + 1) / 2 + 0.5f, t = (p.z + 1) / 2;
    const int tx = int(std::floor((s - std::floor(s)) * 2)), ty = std::min(1, int(t * 2));
    const glm::vec4 rho = texel(im, tx, ty, true);
    const double d = std::sqrt(double(p.x) * p.x + 1 + p.z * p.z);
    const PointEstimate e = estimate(r.states()[k], 1, double(o.photons_per_pass));
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(e.radiance[c], rho[c] / kPiD * 10 / (d * d * d), 1e-5) << k << " " << c;
  }
}

TEST(MaterialRender, NormalTextureTiltsTheShadingNormal) {
  // A constant normal texture (0.5 + 0.5 sin 30, 0.5, 0.5 + 0.5 cos 30: 30 degrees toward the
  // tangent) on a plane whose tangent is +x: the shading normal is (sin 30, cos 30, 0) and the
  // Lambertian radiance under the light is rho / pi x 10 max(0, ns.wi) / d^2 (next-event).
  SceneBuilder b;
  Material m = Material::lambertian(vec3(0.5f));
  m.normal_texture.image = 0;
  const float s30 = 0.5f, c30 = std::sqrt(3.0f) / 2;
  b.s.images.push_back(Image{"n", 1, 1, 3, {}, {0.5f + 0.5f * s30, 0.5f, 0.5f + 0.5f * c30}});
  Mesh& plane = b.quad(vec3(0), vec3(1, 0, 0), vec3(0, 0, -1), b.material(m));
  plane.tangents.assign(4, glm::vec4(1, 0, 0, 1));
  PunctualLight light;
  light.position = vec3(0, 1, 0);
  light.intensity = vec3(10.0f);
  b.s.lights.push_back(light);
  b.camera(vec3(0, 3, 0), vec3(0, -1, 0), vec3(0, 0, -1), 0.6f);
  const RenderOptions o = options(8);
  Renderer r(b.done(), o);
  r.step();
  const vec3 ns(s30, c30, 0.0f);
  for (size_t k = 0; k < r.camera_pass().points.size(); ++k) {
    const vec3 p = r.camera_pass().points[k].position;
    EXPECT_NEAR(glm::dot(r.camera_pass().points[k].shading, ns), 1.0f, 1e-5f);
    const vec3 to = vec3(0, 1, 0) - p;
    const double d2 = glm::dot(to, to),
                 cos = std::max(0.0, double(glm::dot(to, ns)) / std::sqrt(d2));
    const PointEstimate e = estimate(r.states()[k], 1, double(o.photons_per_pass));
    EXPECT_NEAR(e.radiance.x, 0.5 / kPiD * 10 * cos / d2, 1e-5) << k;
  }
}

// glTF appendix B in double (test_microfacet.cpp's reference, repeated for the plane).
double gltf_f(const dvec3& v, const dvec3& l, double base, double metallic, double rough) {
  const dvec3 n(0, 1, 0), h = glm::normalize(v + l);
  const double a = std::max(rough * rough, 1e-4), a2 = a * a;
  const double nh = glm::dot(n, h), nl = glm::dot(n, l), nv = glm::dot(n, v);
  const double D = a2 / (kPiD * std::pow(nh * nh * (a2 - 1) + 1, 2));
  const double V =
      1 / (2 * (nv * std::sqrt(a2 + (1 - a2) * nl * nl) + nl * std::sqrt(a2 + (1 - a2) * nv * nv)));
  const double w = std::pow(1 - std::fabs(glm::dot(v, h)), 5), fd = 0.04 + 0.96 * w;
  const double dielectric = (1 - fd) * base / kPiD + fd * D * V;
  const double metal = (base + (1 - base) * w) * D * V;
  return (1 - metallic) * dielectric + metallic * metal;
}

TEST(MaterialRender, DefaultMaterialIsARoughWhiteMetal) {
  // Material{} is glTF's default (no pbrMetallicRoughness): metallic 1, roughness 1, white. On a
  // plane under a point light it reflects glTF's rough metal lobe (next-event: exact), not black.
  SceneBuilder b;
  b.quad(vec3(0), vec3(5, 0, 0), vec3(0, 0, -5), b.material(Material{}));
  PunctualLight light;
  light.position = vec3(0, 1, 0);
  light.intensity = vec3(10.0f);
  b.s.lights.push_back(light);
  b.camera(vec3(0.5f, 3, 0), vec3(0, -1, 0), vec3(0, 0, -1), 0.6f);
  const RenderOptions o = options(8);
  Renderer r(b.done(), o);
  r.step();
  ASSERT_EQ(r.camera_pass().points.size(), 64u);  // a visible point on every pixel: not a mirror
  ASSERT_EQ(r.camera_pass().glossy.size(), 64u);
  for (size_t k = 0; k < 64; ++k) {
    const dvec3 p(r.camera_pass().points[k].position);
    const dvec3 v = glm::normalize(dvec3(0.5, 3, 0) - p), to = dvec3(0, 1, 0) - p;
    const double d2 = glm::dot(to, to);
    const dvec3 l = to / std::sqrt(d2);
    const double want = gltf_f(v, l, 1.0, 1.0, 1.0) * 10 * l.y / d2;
    const PointEstimate e = estimate(r.states()[k], 1, double(o.photons_per_pass));
    EXPECT_GT(want, 0.01);
    EXPECT_NEAR(e.radiance.x, want, 1e-4 * want) << k;
  }
}

TEST(MaterialRender, AnisotropyTurnsWithTheTangentTheRotationAndTheTexture) {
  // KHR_materials_anisotropy on a brushed white metal plane under a point light (next-event:
  // exact). The tangent is +x, so b = n x t = -z; anisotropyRotation 0.5 and a texel whose RG
  // holds the direction at 0.6 rad (B = 0.5 halves the strength 0.8) give the direction at
  // 1.1 rad, cos 1.1 x - sin 1.1 z, and strength 0.4: each visible point's radiance is the
  // extension's BRDF (its D_GGX_anisotropic and V_GGX_anisotropic, written out here) x 10 l.y /
  // d^2, relative 1e-4. The same plane without the texture's turn (direction 0.5 rad, full
  // strength) differs: the test sees the direction.
  for (bool textured : {true, false}) {
    SceneBuilder b;
    Material m = Material::metal(vec3(1.0f), 0.3f);
    m.anisotropy = 0.8f;
    m.anisotropy_rotation = 0.5f;
    const float phi = 0.6f;
    if (textured) {
      m.anisotropy_texture.image = 0;
      b.s.images.push_back(Image{
          "a", 1, 1, 3, {}, {0.5f + 0.5f * std::cos(phi), 0.5f + 0.5f * std::sin(phi), 0.5f}});
    }
    Mesh& plane = b.quad(vec3(0), vec3(5, 0, 0), vec3(0, 0, -5), b.material(m));
    plane.tangents.assign(4, glm::vec4(1, 0, 0, 1));
    PunctualLight light;
    light.position = vec3(0, 1, 0);
    light.intensity = vec3(10.0f);
    b.s.lights.push_back(light);
    b.camera(vec3(0.5f, 3, 0), vec3(0, -1, 0), vec3(0, 0, -1), 0.6f);
    const RenderOptions o = options(8);
    Renderer r(b.done(), o);
    r.step();
    ASSERT_EQ(r.camera_pass().points.size(), 64u);
    const double turn = textured ? 0.5 + phi : 0.5, strength = textured ? 0.4 : 0.8;
    const dvec3 n(0, 1, 0), t(std::cos(turn), 0, -std::sin(turn)), bt = glm::cross(n, t);
    const double alpha = 0.09, at = alpha + (1 - alpha) * strength * strength, ab = alpha;
    for (size_t k = 0; k < 64; ++k) {
      const dvec3 p(r.camera_pass().points[k].position);
      const dvec3 v = glm::normalize(dvec3(0.5, 3, 0) - p), to = dvec3(0, 1, 0) - p;
      const double d2 = glm::dot(to, to);
      const dvec3 l = to / std::sqrt(d2), h = glm::normalize(v + l);
      const double a2 = at * ab;
      const dvec3 f(ab * glm::dot(t, h), at * glm::dot(bt, h), a2 * glm::dot(n, h));
      const double w2 = a2 / glm::dot(f, f), D = a2 * w2 * w2 / kPiD;
      const double gv = l.y * glm::length(dvec3(at * glm::dot(t, v), ab * glm::dot(bt, v), v.y));
      const double gl = v.y * glm::length(dvec3(at * glm::dot(t, l), ab * glm::dot(bt, l), l.y));
      const double want = D * 0.5 / (gv + gl) * 10 * l.y / d2;  // white metal: F = 1
      const PointEstimate e = estimate(r.states()[k], 1, double(o.photons_per_pass));
      EXPECT_NEAR(e.radiance.x, want, 1e-4 * want) << textured << " " << k;
    }
  }
}

TEST(MaterialRender, GlossyCoatedAndTexturedImagesAreBitIdenticalAcrossThreadCounts) {
  // Glossy points (PPM's side table, SPPM's block scratch), a smooth coat (both parts: PPM splits,
  // SPPM draws), a textured double-sided emitter and a volume: the image does not depend on the
  // thread count, under either method.
  auto scene = [] {
    SceneBuilder b;
    b.quad(vec3(0), vec3(2, 0, 0), vec3(0, 0, -2), b.material(Material::metal(vec3(0.8f), 0.4f)));
    Material coat = Material::lambertian(vec3(0.6f, 0.3f, 0.2f));
    coat.specular = 1.0f;
    coat.roughness = 0.0f;
    b.quad(vec3(0, 1, -2), vec3(2, 0, 0), vec3(0, 1, 0), b.material(coat));
    Material lamp = emitter(vec3(4.0f), true);
    lamp.emissive_texture.image = 0;
    b.s.images.push_back(
        Image{"e", 2, 2, 3, {255, 255, 255, 30, 30, 30, 90, 0, 200, 0, 255, 0}, {}});
    b.quad(vec3(0, 1.8f, -0.5f), vec3(0.4f, 0, 0), vec3(0, 0, 0.4f), b.material(lamp));
    Material glass = Material::glass(1.5f, false);
    glass.attenuation = vec3(0.5f, 1.0f, 2.0f);
    b.box(vec3(-0.3f, 0.0f, -0.8f), vec3(0.3f, 0.6f, -0.2f), b.material(glass));
    b.camera(vec3(0, 1, 2.5f), vec3(0, -0.3f, -1), vec3(0, 1, 0), 0.9f);
    return b.done();
  };
  for (Method m : {Method::PPM, Method::SPPM}) {
    RenderOptions o = options(24, m);
    o.photons_per_pass = 20000;
    std::vector<float> images[2];
    for (int threads : {1, 2}) {
      ThreadLimit limit(threads);
      images[threads - 1] = render(scene(), o, 3);
    }
    EXPECT_EQ(images[0], images[1]) << (m == Method::PPM ? "ppm" : "sppm");
    double sum = 0.0;
    for (float v : images[0]) sum += v;
    EXPECT_GT(sum, 0.0);
  }
}

}  // namespace
}  // namespace pb
