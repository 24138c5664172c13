// KHR_materials_unlit (docs/materials.md "Unlit"): the camera sees the base colour (factor x
// texture x COLOR_0) as the surface's radiance, exactly, with a bound of 0 (or rounding's); to
// light the surface is black: it reflects no photon and lights nothing.
#include "render/renderer.h"
#include "scene_builder.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pb {
namespace {

using test::SceneBuilder;

RenderOptions options(Method method) {
  RenderOptions o;
  o.method = method;
  o.width = o.height = 16;
  o.passes = 1;
  o.photons_per_pass = 20000;
  o.progress = ProgressMode::Never;
  return o;
}

FilmImage render(Scene scene, const RenderOptions& o, uint64_t passes) {
  Renderer r(std::move(scene), o);
  for (uint64_t p = 0; p < passes; ++p) r.step();
  FilmImage img;
  r.develop(&img);
  return img;
}

// A camera at z = 3 looks along -z at an unlit quad at z = 0 that fills its view, in the light of
// a point light beside the camera and a white sky: factor (0.4, 0.5, 1) x a 2 x 1 texture (sRGB
// 255 and 128 in the halves) x COLOR_0 (1, 0.6, 0.5). Each pixel sees factor x texel x colour.
Scene unlit_quad(bool unlit) {
  SceneBuilder b;
  const uint32_t m = b.material(vec3(0.4f, 0.5f, 1.0f));
  b.quad(vec3(0), vec3(2, 0, 0), vec3(0, 2, 0), m);  // front +z
  Mesh& quad = b.scene.meshes.back();
  quad.texcoords[0] = {vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1)};
  quad.colors.assign(4, glm::vec4(1.0f, 0.6f, 0.5f, 1.0f));
  Material& mat = b.scene.materials[m];
  mat.unlit = unlit;
  mat.base_color_texture.image = 0;
  mat.base_color_texture.nearest = true;
  b.scene.images.push_back(Image{"halves", 2, 1, 3, {255, 255, 255, 128, 128, 128}, {}});
  b.point_light(vec3(0.5f, 0.5f, 2), vec3(10.0f));
  b.scene.environment = Environment{"sky", 1, 1, {vec3(1.0f)}};
  b.camera(vec3(0, 0, 3), vec3(0, 0, 0), 0.5f);
  return b.scene;
}

TEST(UnlitRender, TheCameraSeesTheBaseColourExactlyWithABoundOfZero) {
  const float half = 0.21586050f;  // sRGB 128 decoded (IEC 61966-2-1)
  const vec3 colour = vec3(0.4f, 0.5f, 1.0f) * vec3(1.0f, 0.6f, 0.5f);
  for (Method method : {Method::PPM, Method::SPPM}) {
    const FilmImage img = render(unlit_quad(true), options(method), 4);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        // Pixel columns 0-7 see u < 0.5 (texel 255), 8-15 u > 0.5 (texel 128).
        const float texel = x < 8 ? 1.0f : half;
        for (int c = 0; c < 3; ++c) {
          const size_t k = 3 * size_t(y * 16 + x) + size_t(c);
          EXPECT_NEAR(img.radiance[k], colour[c] * texel, 1e-6f) << x << " " << y;
          // PPM's one ray per pixel: exact, bound 0. SPPM's jittered rays interpolate COLOR_0
          // with barycentrics that sum to 1 within an ulp: samples that differ by rounding.
          if (method == Method::PPM)
            EXPECT_EQ(img.bound[k], 0.0f) << x << " " << y;
          else
            EXPECT_LE(img.bound[k], 1e-6f) << x << " " << y;
        }
      }
    // Lit, the same quad is another picture: brighter by the light where it faces it.
    const FilmImage lit = render(unlit_quad(false), options(method), 4);
    EXPECT_NE(lit.radiance, img.radiance);
  }
}

// A ground y = 0 (rho 0.5) under a point light, the camera looking down at it; beside the light
// and out of the view, a large white quad facing the ground, unlit or a black Lambertian: to light
// the unlit quad is black, so the ground's image is the same (to float rounding: the photons
// that land on the black quad are kept in the grid, which changes its order and summing order).
Scene ground_beside(bool unlit) {
  SceneBuilder b;
  b.quad(vec3(0), vec3(0, 0, 3), vec3(3, 0, 0), b.material(vec3(0.5f)));  // front +y
  const uint32_t m = b.material(unlit ? vec3(1.0f) : vec3(0.0f));
  b.scene.materials[m].unlit = unlit;
  b.quad(vec3(2.5f, 1.5f, 0), vec3(1, 0, 0), vec3(0, 0, 1), m);  // front -y, toward the ground
  b.point_light(vec3(0, 1, 0), vec3(10.0f));
  b.camera(vec3(0, 3, 0), vec3(0, 0, 0), 0.4f, vec3(0, 0, -1));
  return b.scene;
}

TEST(UnlitRender, ItLightsNothingAndReflectsNoPhoton) {
  for (Method method : {Method::PPM, Method::SPPM}) {
    RenderOptions o = options(method);
    for (DirectMode direct : {DirectMode::NextEvent, DirectMode::Photons}) {
      o.direct = direct;
      const FilmImage unlit = render(ground_beside(true), o, 4);
      const FilmImage black = render(ground_beside(false), o, 4);
      ASSERT_EQ(unlit.radiance.size(), black.radiance.size());
      double sum = 0.0;
      for (size_t k = 0; k < unlit.radiance.size(); ++k) {
        EXPECT_NEAR(unlit.radiance[k], black.radiance[k], 1e-5f * black.radiance[k] + 1e-9f) << k;
        sum += black.radiance[k];
      }
      EXPECT_GT(sum, 0.0);  // the ground is lit
    }
  }
}

}  // namespace
}  // namespace pb
