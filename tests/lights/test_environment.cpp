// The environment map's orientation, lookup and importance sampling, and the photons and
// next-event samples of environment and directional light, against exact integrals over the
// map's pixels (every row's solid angle and cosine moment are closed forms).
#include "scene_builder.h"

#include "lights/lights.h"
#include "scene/environment.h"
#include "util/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace pb {
namespace {

// An 8 x 4 map with radiance varying by pixel and channel, two black pixels and a bright spot.
Environment test_map() {
  Environment e;
  e.source = "test map";
  e.width = 8;
  e.height = 4;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x)
      e.radiance.push_back(vec3(0.2f + 0.1f * float(x), 0.5f + 0.3f * float(y), 1.0f) *
                           (x == 3 && y == 1 ? 20.0f : 1.0f));
  e.radiance[2] = e.radiance[13] = vec3(0.0f);
  return e;
}

// The polar band of row y: cos theta from top to bottom.
void band(int y, int h, double& top, double& bottom) {
  top = std::cos(kPiD * y / h);
  bottom = std::cos(kPiD * (y + 1) / h);
}

// Exact integral over the map of L times max(0, cos to +Y) (irradiance on an up-facing
// surface; rows 0 and 1 are the upper hemisphere): per pixel (2 pi / W) (c_top^2 - c_bot^2) / 2.
dvec3 upper_irradiance(const Environment& e) {
  dvec3 sum(0.0);
  for (int y = 0; y < e.height / 2; ++y) {
    double top, bottom;
    band(y, e.height, top, bottom);
    for (int x = 0; x < e.width; ++x)
      sum += dvec3(e.radiance[size_t(y * e.width + x)]) * (2 * kPiD / e.width) *
             ((top * top - bottom * bottom) / 2);
  }
  return sum;
}

// Row 0 is the zenith, the centre column -Z, the left and right quarters -X and +X, the edges +Z.
TEST(EnvironmentMap, OrientationAndLookup) {
  Environment e;
  e.width = 4;
  e.height = 2;
  for (int k = 0; k < 8; ++k) e.radiance.push_back(vec3(float(k)));
  const EnvironmentLight env(e);
  auto pixel = [&](const vec3& d) { return int(env.radiance(glm::normalize(d)).x); };
  // Columns: phi in [0, pi/2) from +Z toward -X, [pi/2, pi) toward -Z, [pi, 3pi/2) toward +X,
  // [3pi/2, 2pi) back to +Z; row 0 the upper hemisphere.
  EXPECT_EQ(pixel(vec3(0, 1, 0.01f)), 0);       // the zenith, leaning to +Z
  EXPECT_EQ(pixel(vec3(0, -1, 0.01f)), 4);      // the nadir
  EXPECT_EQ(pixel(vec3(-1, 0.1f, 0.01f)), 0);   // -X, on the +Z side
  EXPECT_EQ(pixel(vec3(-1, 0.1f, -0.01f)), 1);  // -X, on the -Z side
  EXPECT_EQ(pixel(vec3(0.01f, 0.1f, -1)), 2);   // -Z: the centre of the image, right half
  EXPECT_EQ(pixel(vec3(-0.01f, 0.1f, -1)), 1);  // ... left half
  EXPECT_EQ(pixel(vec3(1, -0.1f, -0.01f)), 6);  // +X below the horizon
  EXPECT_EQ(pixel(vec3(1, -0.1f, 0.01f)), 7);
}

// Sampling: the pdf is the density of the samples (the Monte Carlo estimates of the integral of
// L, and of L cos above the horizon, match the exact sums), sample() and pdf() agree, and black
// pixels are never drawn. 400k samples; 4 standard errors.
TEST(EnvironmentMap, ImportanceSamplingIsUnbiased) {
  const Environment e = test_map();
  const EnvironmentLight env(e);
  dvec3 exact(0.0);
  for (int y = 0; y < e.height; ++y) {
    double top, bottom;
    band(y, e.height, top, bottom);
    for (int x = 0; x < e.width; ++x)
      exact += dvec3(e.radiance[size_t(y * e.width + x)]) * (2 * kPiD / e.width) * (top - bottom);
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(env.integral()[c], exact[c], 1e-5 * exact[c]);
  const dvec3 exact_up = upper_irradiance(e);
  Rng rng(3, 0, 0, Stream::Test);
  const int n = 400000;
  dvec3 sum(0.0), sum2(0.0), up(0.0), up2(0.0);
  for (int k = 0; k < n; ++k) {
    float pdf = 0.0f;
    const vec3 d =
        env.sample(rng.next_float(), rng.next_float(), rng.next_float(), rng.next_float(), pdf);
    ASSERT_GT(pdf, 0.0f);
    ASSERT_NEAR(env.pdf(d), pdf, 1e-4f * pdf);
    const dvec3 l(env.radiance(d));
    ASSERT_GT(l.x + l.y + l.z, 0.0);
    const dvec3 x = l / double(pdf), u = x * std::max(0.0, double(d.y));
    sum += x;
    sum2 += x * x;
    up += u;
    up2 += u * u;
  }
  for (int c = 0; c < 3; ++c) {
    const double m = sum[c] / n, se = std::sqrt((sum2[c] / n - m * m) / n);
    EXPECT_NEAR(m, exact[c], 4 * se + 1e-9) << "channel " << c;
    const double mu = up[c] / n, seu = std::sqrt((up2[c] / n - mu * mu) / n);
    EXPECT_NEAR(mu, exact_up[c], 4 * seu) << "channel " << c;
  }
}

// A scene whose bounds are the cube [-1, 1]^3 (one emissive-free box) and the given lights.
Lights lights_of(test::SceneBuilder& b) {
  b.box(vec3(-1), vec3(1), b.material(vec3(0.5f)));
  static Scene keep;  // Lights keeps pointers into the scene's environment
  keep = std::move(b.scene);
  return Lights(keep);
}

// Next-event samples of the map at an up-facing receiver: the mean of Li cos estimates the
// irradiance exactly summed over the upper rows.
TEST(EnvironmentLights, NextEventEstimatesTheIrradiance) {
  test::SceneBuilder b;
  b.scene.environment = test_map();
  const dvec3 exact = upper_irradiance(*b.scene.environment);
  const Lights lights = lights_of(b);
  Rng rng(5, 0, 0, Stream::Test);
  const int n = 400000;
  dvec3 sum(0.0), sum2(0.0);
  for (int k = 0; k < n; ++k) {
    DirectSample s;
    if (!lights.sample_direct(vec3(0, 1, 0), vec3(0, 1, 0), rng, s)) continue;
    EXPECT_EQ(s.distance, INFINITY);
    const dvec3 x = dvec3(s.li) * std::max(0.0, double(s.wi.y));
    sum += x;
    sum2 += x * x;
  }
  for (int c = 0; c < 3; ++c) {
    const double m = sum[c] / n, se = std::sqrt((sum2[c] / n - m * m) / n);
    std::printf("next-event irradiance channel %d: %.5f +- %.5f, exact %.5f\n", c, m, se, exact[c]);
    EXPECT_NEAR(m, exact[c], 4 * se) << "channel " << c;
  }
}

// A uniform environment is sampled by the cosine: every sample of Li cos is exactly pi Le.
TEST(EnvironmentLights, UniformEnvironmentByTheCosineIsExact) {
  test::SceneBuilder b;
  b.scene.environment = Environment{"uniform", 1, 1, {vec3(0.5f, 1.0f, 2.0f)}};
  const Lights lights = lights_of(b);
  Rng rng(6, 0, 0, Stream::Test);
  const vec3 n = glm::normalize(vec3(1, 2, 3));
  for (int k = 0; k < 10000; ++k) {
    DirectSample s;
    if (!lights.sample_direct(vec3(0), n, rng, s)) continue;
    const vec3 e = s.li * glm::dot(s.wi, n);
    EXPECT_NEAR(e.x, kPi * 0.5f, 1e-4f);
    EXPECT_NEAR(e.z, kPi * 2.0f, 4e-4f);
  }
}

// Photons of a light, traced to a horizontal disc of radius a at the scene's centre: the flux
// crossing it downward estimates pi a^2 times the irradiance from above. No photon carries more
// than Lights::max_photon_flux().
dvec3 flux_through_disc(const Lights& lights, double a, int n) {
  Rng rng(9, 0, 0, Stream::Test);
  dvec3 sum(0.0);
  for (int k = 0; k < n; ++k) {
    const EmittedPhoton ph = lights.sample_photon(rng);
    EXPECT_EQ(ph.normal, vec3(0.0f));
    // The sparse-photon bound relies on max_photon_flux() bounding every photon.
    EXPECT_LE(max_component(ph.flux), lights.max_photon_flux() * (1.0f + 1e-5f));
    EXPECT_GT(glm::length(ph.origin), std::sqrt(3.0f));  // starts outside the bounding sphere
    if (!(ph.dir.y < 0.0f)) continue;
    const float t = -ph.origin.y / ph.dir.y;
    const vec3 hit = ph.origin + t * ph.dir;
    if (hit.x * hit.x + hit.z * hit.z < a * a) sum += dvec3(ph.flux);
  }
  return sum / double(n);
}

TEST(EnvironmentLights, PhotonsDeliverTheIrradiance) {
  test::SceneBuilder b;
  b.scene.environment = test_map();
  const dvec3 exact = upper_irradiance(*b.scene.environment) * (kPiD * 0.25);
  const Lights lights = lights_of(b);
  const dvec3 got = flux_through_disc(lights, 0.5, 400000);
  std::printf("environment photons through the disc: %.5f %.5f %.5f, exact %.5f %.5f %.5f\n", got.x,
              got.y, got.z, exact.x, exact.y, exact.z);
  // About 1 photon in 25 crosses the disc (its area over the emission disc's, times the
  // cosine), each carrying nearly the same flux (the map is importance-sampled): a relative
  // standard error of sqrt(24 / 400000) = 0.77%, and 3% is 4 of them. (8M photons: +0.17%.)
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], exact[c], 0.03 * exact[c]) << c;
}

// Directional light of irradiance E travelling at 30 degrees from -Y: the disc facing up
// receives E cos 30 pi a^2; a next-event sample is the delta direction back to the light.
TEST(DirectionalLights, PhotonsAndNextEvent) {
  test::SceneBuilder b;
  const vec3 travel = glm::normalize(vec3(std::sin(kPi / 6), -std::cos(kPi / 6), 0));
  b.directional_light(travel, vec3(2.0f, 1.0f, 0.5f));
  const Lights lights = lights_of(b);
  const dvec3 got = flux_through_disc(lights, 0.5, 200000);
  const dvec3 exact = dvec3(2.0, 1.0, 0.5) * std::cos(kPiD / 6) * (kPiD * 0.25);
  std::printf("directional photons through the disc: %.5f, exact %.5f\n", got.x, exact.x);
  // 1 photon in 14 crosses the disc, all with the same flux: 0.8% standard error at 200k.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], exact[c], 0.032 * exact[c]) << c;
  Rng rng(10, 0, 0, Stream::Test);
  DirectSample s;
  ASSERT_TRUE(lights.sample_direct(vec3(0.3f, -1, 0.2f), vec3(0, 1, 0), rng, s));
  EXPECT_EQ(s.wi, -travel);
  EXPECT_EQ(s.distance, INFINITY);
  EXPECT_EQ(s.li, vec3(2.0f, 1.0f, 0.5f));  // one emitter: chosen with probability 1
}

}  // namespace
}  // namespace pb
