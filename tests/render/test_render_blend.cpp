// alphaMode BLEND as stochastic coverage (docs/materials.md "Alpha"): a surface of alpha a stops
// a of the camera rays, photons and shadow rays and passes 1 - a, against answers computed by
// hand; BLEND with alpha 1 is OPAQUE bit for bit.
#include "render/renderer.h"
#include "scene/texture.h"
#include "scene_builder.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pb {
namespace {

using test::SceneBuilder;

RenderOptions options(Method method, DirectMode direct = DirectMode::NextEvent) {
  RenderOptions o;
  o.method = method;
  o.direct = direct;
  o.width = o.height = 16;
  o.passes = 1;
  o.photons_per_pass = 20000;
  o.progress = ProgressMode::Never;
  return o;
}

std::vector<float> render(Scene scene, const RenderOptions& o, uint64_t passes) {
  Renderer r(std::move(scene), o);
  for (uint64_t p = 0; p < passes; ++p) r.step();
  FilmImage img;
  r.develop(&img);
  return img.radiance;
}

// The mean of the red channel over the image.
double mean_red(const std::vector<float>& image) {
  double sum = 0.0;
  for (size_t k = 0; k < image.size(); k += 3) sum += image[k];
  return sum / double(image.size() / 3);
}

void make_blend(Scene& s, uint32_t material, float alpha) {
  s.materials[material].alpha_mode = AlphaMode::Blend;
  s.materials[material].alpha = alpha;
}

// A camera at z = 3 looks along -z, with a narrow view, at a black card at z = 1 (alpha a) in
// front of a one-sided emitter of radiance 1 at z = 0 that fills the view: every pixel is
// 1 - a, the light passing the card (the card reflects nothing).
Scene card_before_light(float alpha) {
  SceneBuilder b;
  const uint32_t card = b.material(vec3(0.0f));
  b.quad(vec3(0, 0, 1), vec3(2, 0, 0), vec3(0, 2, 0), card);  // front +z
  b.quad(vec3(0, 0, 0), vec3(4, 0, 0), vec3(0, 4, 0), b.material(vec3(0.0f), vec3(1.0f)));
  make_blend(b.scene, card, alpha);
  b.camera(vec3(0, 0, 3), vec3(0, 0, 0), 0.3f);
  return b.scene;
}

TEST(BlendRender, ACardOfAlphaAQuarterPassesThreeQuartersOfTheCameraRays) {
  // PPM splits each pixel's ray at the card (weight a on it, 1 - a through): exact, every
  // pixel 0.75 to float rounding.
  for (float v : render(card_before_light(0.25f), options(Method::PPM), 2))
    EXPECT_NEAR(v, 0.75f, 1e-6f);
  // SPPM chooses per pixel and pass: each sample is 1 with probability 0.75, else 0. 256 pixels
  // x 32 passes = 8192 Bernoulli samples, standard error sqrt(0.75 x 0.25 / 8192) = 0.0048;
  // 4 standard errors (a fixed seed: this run, not a rate of failures).
  const double m = mean_red(render(card_before_light(0.25f), options(Method::SPPM), 32));
  EXPECT_NEAR(m, 0.75, 4 * 0.0048);
  // With alpha 0 the card is not there, with alpha 1 it hides the light: 1 and 0 exactly.
  for (Method method : {Method::PPM, Method::SPPM}) {
    for (float v : render(card_before_light(0.0f), options(method), 2)) EXPECT_EQ(v, 1.0f);
    for (float v : render(card_before_light(1.0f), options(method), 2)) EXPECT_EQ(v, 0.0f);
  }
}

// A ground y = 0, 6 x 6 (rho 0.5; 0 with `black_ground`) under a sun straight down of irradiance 2
// pi (the open ground's radiance is 0.5 / pi x 2 pi = 1), a card at y = 0.5 of alpha a (rho 0.5
// facing up; 0 with `black_card`) wide enough that every ground point the camera sees is in its
// shadow. `from_above`: the camera looks straight down through the card, else from under it.
Scene card_under_sun(float alpha, bool from_above, bool black_card, bool black_ground) {
  SceneBuilder b;
  b.quad(vec3(0), vec3(0, 0, 3), vec3(3, 0, 0), b.material(vec3(black_ground ? 0.0f : 0.5f)));
  const uint32_t card = b.material(vec3(black_card ? 0.0f : 0.5f));
  b.quad(vec3(0, 0.5f, 0), vec3(0, 0, 2.5f), vec3(2.5f, 0, 0), card);  // front +y
  make_blend(b.scene, card, alpha);
  b.directional_light(vec3(0, -1, 0), vec3(2.0f * kPi));
  if (from_above)
    b.camera(vec3(0, 3, 0), vec3(0, 0, 0), 0.3f, vec3(0, 0, -1));
  else
    b.camera(vec3(0, 0.4f, 0), vec3(0, 0, -1), 0.3f);  // sees the ground at 1.3-2.2 from it
  return b.scene;
}

TEST(BlendRender, TheShadowOfACardOfAlphaAQuarterIsThreeQuartersOfTheLight) {
  // Seen from under the card, the ground in its shadow: 0.75 of the open ground's 1. The card
  // is black, so nothing comes back down from it: the answer is exact.
  // Next-event estimation: each pixel's shadow ray passes with probability 0.75, one per pass;
  // 256 pixels x 32 passes give a standard error of 0.0048 as above (4 of them).
  for (Method method : {Method::PPM, Method::SPPM}) {
    const Scene s = card_under_sun(0.25f, false, true, false);
    EXPECT_NEAR(mean_red(render(s, options(method), 32)), 0.75, 4 * 0.0048) << int(method);
  }
  // All light from photons: the photons pass the card as the shadow rays do. The ratio to the
  // same render with the card at alpha 0 (the same photons up to the card's choices) is 0.75;
  // measured 0.743-0.764 over seeds 1-6 (PPM and SPPM; the open ground 0.961-1.014), so 0.03
  // covers the photons' noise.
  for (Method method : {Method::PPM, Method::SPPM}) {
    const RenderOptions o = options(method, DirectMode::Photons);
    const double shadowed = mean_red(render(card_under_sun(0.25f, false, true, false), o, 32));
    const double open = mean_red(render(card_under_sun(0.0f, false, true, false), o, 32));
    EXPECT_NEAR(open, 1.0, 0.05) << int(method);
    EXPECT_NEAR(shadowed / open, 0.75, 0.03) << int(method);
  }
}

TEST(BlendRender, PhotonsAndCameraPathsCountACardsCoverageOnce) {
  // From above, over a black ground: the camera sees the card (rho 0.5 in the open sun, radiance
  // 1) with probability a and the black ground otherwise, so every pixel is a x 1 = 0.25. The
  // card's photons land with probability a and carry 1 / a: the density estimate is the light
  // on the card where it is, and the camera's a counts the coverage once.
  // Next-event estimation: exact in PPM (the split), and 0.25 to 4 standard errors in SPPM
  // (Bernoulli of 0.25 x 1: sqrt(0.1875 / 8192) = 0.0048).
  for (float v : render(card_under_sun(0.25f, true, false, true), options(Method::PPM), 2))
    EXPECT_NEAR(v, 0.25f, 1e-5f);
  EXPECT_NEAR(mean_red(render(card_under_sun(0.25f, true, false, true), options(Method::SPPM), 32)),
              0.25, 4 * 0.0048);
  // All light from photons: against the opaque card's photon render, a ratio of 0.25; measured
  // 0.233-0.256 over seeds 1-6 (the opaque card 0.979-1.024), so 0.025 covers the noise of the
  // 1 / a photons.
  for (Method method : {Method::PPM, Method::SPPM}) {
    const RenderOptions o = options(method, DirectMode::Photons);
    const double quarter = mean_red(render(card_under_sun(0.25f, true, false, true), o, 32));
    const double whole = mean_red(render(card_under_sun(1.0f, true, false, true), o, 32));
    EXPECT_NEAR(whole, 1.0, 0.05) << int(method);
    EXPECT_NEAR(quarter / whole, 0.25, 0.025) << int(method);
  }
}

TEST(BlendRender, ABlendEmitterEmitsItsCoverage) {
  // The emitter itself BLEND at alpha 0.25, seen directly: 0.25 of its radiance (PPM, exact).
  SceneBuilder b;
  const uint32_t light = b.material(vec3(0.0f), vec3(1.0f));
  b.quad(vec3(0, 0, 0), vec3(4, 0, 0), vec3(0, 4, 0), light);
  make_blend(b.scene, light, 0.25f);
  b.camera(vec3(0, 0, 3), vec3(0, 0, 0), 0.3f);
  for (float v : render(b.scene, options(Method::PPM), 1)) EXPECT_NEAR(v, 0.25f, 1e-6f);
  // Lighting a ground (next-event estimation): 0.25 of the opaque emitter's light, per sample,
  // since the light sampler's radiance there is alpha x Le (texture.h emission_at).
  auto lit = [](float alpha) {
    SceneBuilder g;
    g.quad(vec3(0), vec3(0, 0, 4), vec3(4, 0, 0), g.material(vec3(0.5f)));
    const uint32_t lamp = g.material(vec3(0.0f), vec3(3.0f));
    g.quad(vec3(0, 1, 0), vec3(0.5f, 0, 0), vec3(0, 0, 0.5f), lamp);  // front -y
    if (alpha < 1.0f) make_blend(g.scene, lamp, alpha);
    g.camera(vec3(0, 0.5f, 2), vec3(0, 0, 0), 0.5f);
    return mean_red(render(g.scene, options(Method::PPM), 8));
  };
  EXPECT_NEAR(lit(0.25f) / lit(1.0f), 0.25, 0.01);
}

TEST(BlendRender, BlendOfAlphaOneIsOpaqueExactly) {
  // Coverage 1 everywhere (alpha factor 1, a texture whose alpha is all 255, vertex alphas 1):
  // the same images as OPAQUE, bit for bit, in both methods and both direct modes.
  auto scene = [](bool blend) {
    SceneBuilder b;
    b.quad(vec3(0), vec3(0, 0, 8), vec3(8, 0, 0), b.material(vec3(0.5f)));
    const uint32_t card = b.material(vec3(0.5f), vec3(0.5f));  // an emitter too
    b.quad(vec3(0, 0.5f, 0), vec3(0, 0, 1), vec3(1, 0, 0), card);
    b.scene.meshes[1].texcoords[0] = {vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1)};
    b.scene.meshes[1].colors.assign(4, glm::vec4(1.0f));
    Material& m = b.scene.materials[card];
    m.alpha_mode = blend ? AlphaMode::Blend : AlphaMode::Opaque;
    m.base_color_texture.image = 0;
    b.scene.images.push_back(Image{"rgba", 2, 1, 4, {200, 100, 50, 255, 20, 200, 90, 255}, {}});
    b.directional_light(vec3(0.3f, -1, 0.2f), vec3(2.0f));
    b.camera(vec3(0, 2, 2), vec3(0, 0, 0), 0.8f);
    return b.scene;
  };
  for (Method method : {Method::PPM, Method::SPPM})
    for (DirectMode direct : {DirectMode::NextEvent, DirectMode::Photons})
      EXPECT_EQ(render(scene(true), options(method, direct), 3),
                render(scene(false), options(method, direct), 3));
  // Below 1 anywhere it stays BLEND: the factor, one texel, one vertex.
  Scene s = scene(true);
  settle_blend(s);
  EXPECT_EQ(s.materials[1].alpha_mode, AlphaMode::Opaque);
  for (int k = 0; k < 3; ++k) {
    Scene t = scene(true);
    if (k == 0) t.materials[1].alpha = 0.999f;
    if (k == 1) t.images[0].u8[7] = 254;
    if (k == 2) t.meshes[1].colors[2].w = 0.5f;
    settle_blend(t);
    EXPECT_EQ(t.materials[1].alpha_mode, AlphaMode::Blend) << k;
  }
}

}  // namespace
}  // namespace pb
