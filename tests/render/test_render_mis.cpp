// The environment's direct light at glossy points by multiple importance sampling
// (render/next_event.cpp): unbiased, and free of the light samples' rare large values.
#include "render_fixture.h"
#include "scene_builder.h"

#include "bsdf/bsdf.h"
#include "render/next_event.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace pb {
namespace {

// A white metal plane of roughness r under a uniform sky of radiance 1, seen along its normal
// from far away (the view within 0.1 degree of it over the image): every pixel's radiance is
// the directional albedo at normal view, integral of f cos over the hemisphere; no photon
// comes back to the plane (nothing else is there), so next-event estimation is all of it.
Scene metal_plane(float roughness) {
  test::SceneBuilder b;
  b.scene.materials.push_back(Material::metal(vec3(1.0f), roughness));
  b.quad(vec3(0), vec3(50, 0, 0), vec3(0, 0, -50), uint32_t(b.scene.materials.size() - 1));
  b.camera(vec3(0, 300, 0), vec3(0), 0.004f, vec3(0, 0, -1));
  Environment sky;
  sky.source = "test sky";
  sky.radiance = {vec3(1.0f)};
  b.scene.environment = sky;
  return std::move(b.scene);
}

// The albedo at normal view, and the per-sample variance of light samples alone (the sky drawn
// by the cosine: each sample pi f), by a midpoint rule in (cos theta, phi) fine enough for the
// lobe (roughness 0.3: alpha 0.09, about 5 degrees wide).
struct Moments {
  double albedo, light_only_variance;
};
Moments moments(float roughness) {
  const vec3 n(0, 1, 0);
  const Bsdf bsdf(Material::metal(vec3(1.0f), roughness), n, n);
  constexpr int kTheta = 4000, kPhi = 64;
  double m1 = 0.0, m2 = 0.0;
  for (int i = 0; i < kTheta; ++i) {
    const double c = (i + 0.5) / kTheta, s = std::sqrt(1.0 - c * c);
    for (int j = 0; j < kPhi; ++j) {
      const double phi = 2.0 * kPiD * (j + 0.5) / kPhi;
      const vec3 wi(float(s * std::cos(phi)), float(c), float(s * std::sin(phi)));
      const double f = bsdf.eval(n, wi).x;
      const double dw = (1.0 / kTheta) * (2.0 * kPiD / kPhi);
      m1 += f * c * dw;
      m2 += kPiD * f * f * c * dw;  // E[(pi f)^2] under the pdf cos / pi
    }
  }
  return {m1, m2 - m1 * m1};
}

// Rendered with both methods: PPM gathers the whole lobe at its fixed points (next_event_at's
// draw), SPPM follows a lobe below --follow-roughness (the path's own draw) and gathers one
// above it.
TEST(EnvironmentMis, AGlossyPlaneUnderTheSkyShowsItsAlbedoWithLessNoise) {
  for (float roughness : {0.3f, 0.8f}) {
    const Moments m = moments(roughness);
    for (Method method : {Method::PPM, Method::SPPM}) {
      RenderOptions o = test::quick_options("built.gltf", 16, 64);
      o.method = method;
      o.photons_per_pass = 1000;
      Renderer r(metal_plane(roughness), o);
      for (uint64_t k = 0; k < *o.passes; ++k) r.step();
      FilmImage film;
      r.develop(&film);
      const size_t n = film.radiance.size() / 3;
      double sum = 0.0, var = 0.0;
      for (size_t p = 0; p < n; ++p) {
        sum += film.radiance[3 * p];
        var += film.variance[3 * p];
      }
      const double mean = sum / double(n), se = std::sqrt(var) / double(n);
      const double per_pass = var / double(n) * double(*o.passes);
      std::printf(
          "roughness %.1f %s: mean %.5f +- %.5f, albedo %.5f; per-pass variance %.5f, "
          "light samples alone %.5f\n",
          roughness, method == Method::PPM ? "ppm" : "sppm", mean, se, m.albedo, per_pass,
          m.light_only_variance);
      // Unbiased: the pixels are independent, so their mean's standard error is se.
      EXPECT_NEAR(mean, m.albedo, 4.0 * se + 1e-4) << roughness;
      // Less noise than the light samples alone would give (their variance by quadrature): at
      // roughness 0.3 the lobe's peak is 39 times the cosine's, a few of its light samples
      // carry most of the variance, and the lobe's own draws take them over (74 times less:
      // 0.128 against 9.48). At 0.8, above kMisRoughness, the light samples alone (0.0006:
      // within a factor 2, the estimate of a variance over 256 pixels x 64 passes).
      if (roughness < kMisRoughness)
        EXPECT_LT(per_pass, 0.05 * m.light_only_variance) << roughness;
      else
        EXPECT_LT(per_pass, 2.0 * m.light_only_variance) << roughness;
    }
  }
}

}  // namespace
}  // namespace pb
