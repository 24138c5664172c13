// Light sampling: spherical-triangle directions and next-event estimates against exact answers;
// textured emitters (power, where photons start, next-event estimates) and double-sided ones.
#include "bsdf/microfacet.h"
#include "lights/lights.h"
#include "sample_mean.h"
#include "util/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace pb {
namespace {

// Moller-Trumbore: does the ray p + t d (t > 0) hit triangle (v0, v1, v2)?
bool hits(const vec3& p, const vec3& d, const vec3& v0, const vec3& v1, const vec3& v2) {
  const glm::dvec3 e1 = glm::dvec3(v1 - v0), e2 = glm::dvec3(v2 - v0), dd(d);
  const glm::dvec3 h = glm::cross(dd, e2);
  const double det = glm::dot(e1, h);
  if (std::fabs(det) < 1e-15) return false;
  const glm::dvec3 s = glm::dvec3(p - v0);
  const double u = glm::dot(s, h) / det;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(dd, q) / det;
  const double t = glm::dot(e2, q) / det;
  const double eps = 1e-5;
  return u > -eps && v > -eps && u + v < 1 + eps && t > 0;
}

// Every sampled direction points into the triangle, and the samples are uniform in solid
// angle: the solid-angle estimate of the projected solid angle (integral of the cosine to the
// triangle's normal) agrees with an independent area-sampling estimate. 200k samples each; the
// tolerance is 4 combined standard errors.
TEST(SphericalTriangle, DirectionsHitTheTriangleUniformlyInSolidAngle) {
  const vec3 tris[][4] = {
      {vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0), vec3(0.2f, 0.3f, 0.5f)},
      {vec3(-1, 0, -1), vec3(1, 0, -1), vec3(0, 0, 1), vec3(0.1f, 0.05f, 0.0f)},  // close
      {vec3(0, 0, 0), vec3(3, 0, 0), vec3(0, 0.2f, 0), vec3(1.5f, 0.05f, 2.0f)},  // thin
  };
  for (const auto& tri : tris) {
    const vec3 p = tri[3];
    const vec3 n = glm::normalize(glm::cross(tri[1] - tri[0], tri[2] - tri[0]));
    const int kSamples = 200000;
    double sum_sa = 0.0, sq_sa = 0.0, sum_area = 0.0, sq_area = 0.0;
    float omega = 0.0f;
    for (int i = 0; i < kSamples; ++i) {
      Rng rng(5, 0, uint64_t(i), Stream::Test);
      vec3 d;
      ASSERT_TRUE(sample_spherical_triangle(tri[0], tri[1], tri[2], p, rng.next_float(),
                                            rng.next_float(), d, omega));
      ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
      ASSERT_TRUE(hits(p, d, tri[0], tri[1], tri[2])) << i;
      const double f = std::fabs(glm::dot(d, n)) * omega;
      sum_sa += f;
      sq_sa += f * f;
      // Area sampling of the same integral: |cos_l| A / d^2 ... times |cos to n| = cos_l.
      const float s = std::sqrt(rng.next_float()), u2 = rng.next_float();
      const vec3 y = tri[0] + (1 - s) * (tri[1] - tri[0]) + u2 * s * (tri[2] - tri[0]);
      const vec3 w = y - p;
      const double d2 = glm::dot(w, w);
      const double cos_l = std::fabs(glm::dot(glm::normalize(w), n));
      const double area = 0.5 * glm::length(glm::cross(tri[1] - tri[0], tri[2] - tri[0]));
      const double g = cos_l * cos_l * area / d2;
      sum_area += g;
      sq_area += g * g;
    }
    const double n_ = kSamples;
    const double m1 = sum_sa / n_, m2 = sum_area / n_;
    const double se = std::sqrt((sq_sa / n_ - m1 * m1) / n_ + (sq_area / n_ - m2 * m2) / n_);
    EXPECT_NEAR(m1, m2, 4.0 * se) << "triangle at " << p.x << "," << p.y << "," << p.z;
  }
}

TEST(SphericalTriangle, RefusesDegenerateAndTinySolidAngles) {
  vec3 d;
  float omega;
  // Receiver in the triangle's plane, and a triangle seen edge-on from far away.
  EXPECT_FALSE(sample_spherical_triangle(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0), vec3(2, 2, 0),
                                         0.5f, 0.5f, d, omega));
  EXPECT_FALSE(sample_spherical_triangle(vec3(0, 0, 0), vec3(1e-3f, 0, 0), vec3(0, 1e-3f, 0),
                                         vec3(0, 0, 100), 0.5f, 0.5f, d, omega));
}

// The solid angle the sampler returns is the triangle's: the two halves of an a x b rectangle
// seen from a point at height d over one corner subtend atan(ab / (d sqrt(a^2 + b^2 + d^2)))
// together (the rectangle's closed form, independent of both triangle formulas), from a
// rectangle near the refusal threshold (each half 6.2e-4 sr) to one that fills most of the
// hemisphere; and the octant triangle subtends pi / 2. Float output: 2e-6 relative.
TEST(SphericalTriangle, TheSolidAngleIsTheTrianglesOwn) {
  const double cases[][3] = {{0.025, 0.05, 1.0}, {0.3, 0.2, 1.0}, {2.0, 3.0, 0.5}, {10, 10, 0.1}};
  for (const auto& c : cases) {
    const float a = float(c[0]), b = float(c[1]), d = float(c[2]);
    const vec3 p(0.0f), p00(0, 0, d), pa0(a, 0, d), pab(a, b, d), p0b(0, b, d);
    vec3 dir;
    float half1 = 0.0f, half2 = 0.0f;
    ASSERT_TRUE(sample_spherical_triangle(p00, pa0, pab, p, 0.3f, 0.6f, dir, half1));
    ASSERT_TRUE(sample_spherical_triangle(p00, pab, p0b, p, 0.7f, 0.2f, dir, half2));
    const double ad = double(a), bd = double(b), dd = double(d);
    const double exact = std::atan(ad * bd / (dd * std::sqrt(ad * ad + bd * bd + dd * dd)));
    EXPECT_NEAR(double(half1) + double(half2), exact, 2e-6 * exact) << a << " x " << b;
  }
  vec3 dir;
  float octant = 0.0f;
  ASSERT_TRUE(sample_spherical_triangle(vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1), vec3(0.0f),
                                        0.5f, 0.5f, dir, octant));
  EXPECT_NEAR(double(octant), kPiD / 2.0, 2e-6);
}

// The next-event choice weights' atan2: within its 1e-5 of libm's over every quadrant of the
// upper half-plane and ratios from 1e-6 to 1e6, relatively close for small angles (where the
// weight is the solid angle of a far emitter), and positive wherever the angle is.
TEST(NextEventChoice, TheWeightsAtan2IsWithinItsBound) {
  double worst = 0.0, worst_rel = 0.0;
  for (int i = -120; i <= 120; ++i) {
    const float ratio = std::pow(10.0f, float(i) / 20.0f);
    for (const float x : {1.0f, -1.0f, 0.0f}) {
      const float y = x == 0.0f ? ratio : ratio * std::fabs(x);
      const double want = std::atan2(double(y), double(x)), got = double(atan2_upper(y, x));
      worst = std::max(worst, std::fabs(got - want));
      worst_rel = std::max(worst_rel, std::fabs(got - want) / want);
      EXPECT_GT(got, 0.0) << y << " " << x;
    }
  }
  EXPECT_LT(worst, 1.2e-5);      // the polynomial's 1e-5 and float rounding
  EXPECT_LT(worst_rel, 1.5e-4);  // its leading coefficient 0.999866
  EXPECT_EQ(atan2_upper(0.0f, 1.0f), 0.0f);
  EXPECT_EQ(atan2_upper(0.0f, -1.0f), kPi);
}

// ---------------------------------------------------------------------------------------------
// Textured and double-sided emitters

double srgb(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// A 2 x 1 m quad in z = 0 facing +z, uv (0, 0) at (0, 1, 0) (the image's top-left at the top),
// u along +x, v along -y, with one emissive material.
Scene emissive_quad(const Material& mat, std::vector<Image> images = {}) {
  Scene s;
  Mesh m;
  m.positions = {vec3(0, 0, 0), vec3(2, 0, 0), vec3(2, 1, 0), vec3(0, 1, 0)};
  m.texcoords[0] = {vec2(0, 1), vec2(1, 1), vec2(1, 0), vec2(0, 0)};
  m.indices = {0, 1, 2, 0, 2, 3};
  s.meshes.push_back(m);
  s.materials.push_back(mat);
  s.images = std::move(images);
  return s;
}

using test::Mean;

TEST(TexturedEmitter, PhotonPowerIsTheIntegralOfTheTexturedRadiance) {
  // A 2 x 2 sRGB emissive texture, clamped and bilinear, times emissiveFactor (2, 1, 0.5): with
  // clamping the bilinear surface over [0, 1]^2 integrates to the mean of its four decoded texels
  // (each axis: 1/4 flat, 1/2 ramp, 1/4 flat), so the power per channel is pi A factor x mean.
  // The photons' mean flux must equal it (4 standard errors); the sampler's own estimate
  // (midpoint rule on its pieces) to 2%.
  const uint8_t r[4] = {255, 30, 128, 0}, g[4] = {10, 200, 60, 255};
  Image im{"e", 2, 2, 3, std::vector<uint8_t>(12), {}};
  for (int k = 0; k < 4; ++k) {
    im.u8[3 * k] = r[k];
    im.u8[3 * k + 1] = g[k];
    im.u8[3 * k + 2] = 255;
  }
  Material mat = Material::lambertian(vec3(0.0f));
  mat.emission = vec3(2.0f, 1.0f, 0.5f);
  mat.emissive_texture.image = 0;
  mat.emissive_texture.wrap_s = mat.emissive_texture.wrap_t = Wrap::ClampToEdge;
  const Scene scene = emissive_quad(mat, {im});
  const Lights lights(scene);
  double mean_r = 0, mean_g = 0;
  for (int k = 0; k < 4; ++k) {
    mean_r += srgb(r[k] / 255.0) / 4;
    mean_g += srgb(g[k] / 255.0) / 4;
  }
  const double want[3] = {kPiD * 2 * 2.0 * mean_r, kPiD * 2 * 1.0 * mean_g, kPiD * 2 * 0.5};
  Mean flux[3];
  for (int i = 0; i < 400000; ++i) {
    Rng rng(11, 0, uint64_t(i), Stream::Test);
    const EmittedPhoton p = lights.sample_photon(rng);
    ASSERT_GT(glm::dot(p.dir, vec3(0, 0, 1)), 0.0f);  // one-sided: the front only
    for (int c = 0; c < 3; ++c) flux[c].add(p.flux[c]);
  }
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(flux[c].mean(), want[c], 4.0 * flux[c].se()) << "channel " << c;
    EXPECT_NEAR(lights.total_power()[c], want[c], 0.02 * want[c]) << "channel " << c;
  }
}

TEST(TexturedEmitter, DarkTrianglesAreSkippedButNoneABrightTexelReaches) {
  // A 1 x 1 m grid of 8 x 8 quads (128 triangles) under a 16 x 16 texture, black but for texel
  // (7, 8), bilinear: its hat spans +-1 texel about its centre (7.5/16, 8.5/16), across the
  // grid lines s = t = 1/2, so 8 triangles see it, some only through the filter's reach and
  // the rest not at all (skipped whole). The hat integrates to 1/256 of the square, so the
  // power is pi x 3 / 256 per channel (to 2%, the pieces' midpoint rule); a triangle dropped
  // while the filter still reads the texel loses at least 1/8 of it. The photons' mean flux
  // agrees (4 standard errors), and a photon carries flux only from inside the hat.
  Image im{"dot", 16, 16, 3, std::vector<uint8_t>(16 * 16 * 3, 0), {}};
  for (int k = 0; k < 3; ++k) im.u8[size_t((8 * 16 + 7) * 3 + k)] = 255;
  Material mat = Material::lambertian(vec3(0.0f));
  mat.emission = vec3(3.0f);
  mat.emissive_texture.image = 0;
  Scene scene;
  Mesh m;
  const int n = 8;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = float(i) / n, y = float(j) / n;
      m.positions.push_back(vec3(x, 1.0f - y, 0.0f));  // v = t down the image, y up
      m.texcoords[0].push_back(vec2(x, y));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});  // counter-clockwise from +z
    }
  scene.meshes.push_back(m);
  scene.materials.push_back(mat);
  scene.images = {im};
  const Lights lights(scene);
  const double want = kPiD * 3.0 / 256.0;
  Mean flux;
  for (int i = 0; i < 200000; ++i) {
    Rng rng(13, 0, uint64_t(i), Stream::Test);
    const EmittedPhoton p = lights.sample_photon(rng);
    ASSERT_GT(glm::dot(p.dir, vec3(0, 0, 1)), 0.0f);
    const bool in = std::fabs(p.origin.x - 7.5f / 16) < 1.0f / 16 &&
                    std::fabs((1.0f - p.origin.y) - 8.5f / 16) < 1.0f / 16;
    if (!in) EXPECT_EQ(p.flux, vec3(0.0f)) << p.origin.x << " " << p.origin.y;
    flux.add(p.flux.x);
  }
  EXPECT_NEAR(flux.mean(), want, 4.0 * flux.se());
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(lights.total_power()[c], want, 0.02 * want) << c;
}

TEST(TexturedEmitter, APieceBudgetCoarsensThePiecesButNotThePhotonFlux) {
  // The 2 x 1 m quad under a 64 x 32 texture of random texels: its two triangles ask for 32^2
  // pieces each (2048 in all). Under a budget of 200 each gets floor(32 sqrt(200 / 2048)) = 10
  // per side, 100 pieces, and its choice follows the texture less closely; the photons' mean
  // flux is the texture's integral either way (4 standard errors of the difference), since
  // every photon carries the radiance looked up where it leaves.
  Image im{"noise", 64, 32, 3, std::vector<uint8_t>(64 * 32 * 3), {}};
  Rng texels(5, 0, 0, Stream::Test);
  for (uint8_t& v : im.u8) v = uint8_t(255.0f * texels.next_float());
  Material mat = Material::lambertian(vec3(0.0f));
  mat.emission = vec3(1.0f);
  mat.emissive_texture.image = 0;
  const Scene scene = emissive_quad(mat, {im});
  const Lights fine(scene), coarse(scene, 200.0);
  EXPECT_EQ(fine.emitter_count(), 2u * 32u * 32u);
  EXPECT_EQ(coarse.emitter_count(), 2u * 10u * 10u);
  Mean a, b;
  for (int i = 0; i < 200000; ++i) {
    Rng ra(17, 0, uint64_t(i), Stream::Test), rb(19, 0, uint64_t(i), Stream::Test);
    a.add(fine.sample_photon(ra).flux.x);
    b.add(coarse.sample_photon(rb).flux.x);
  }
  std::printf("photon flux: %.5f fine (%.5f), %.5f coarse (%.5f)\n", a.mean(), a.se(), b.mean(),
              b.se());
  EXPECT_NEAR(a.mean(), b.mean(), 4.0 * std::hypot(a.se(), b.se()));
  // The midpoint rule on 100 pieces of about 10 texels still finds the power to 2%.
  EXPECT_NEAR(coarse.total_power().x, fine.total_power().x, 0.02 * fine.total_power().x);
}

TEST(TexturedEmitter, PhotonsLeaveWhereTheTextureIsBright) {
  // An 8 x 1 texture, bright in its first two texels (u < 1/4) and black elsewhere, NEAREST:
  // uniform sampling would start 25% of the photons in the bright quarter; choosing pieces by
  // their power starts them there but for the pieces whose bound reaches a bright texel's
  // neighbour (measured 83%). Every photon's flux is the radiance where it starts.
  Image im{"mask", 8, 1, 3, std::vector<uint8_t>(24, 0), {}};
  for (int k = 0; k < 6; ++k) im.u8[size_t(k)] = 255;
  Material mat = Material::lambertian(vec3(0.0f));
  mat.emission = vec3(1.0f);
  mat.emissive_texture.image = 0;
  mat.emissive_texture.nearest = true;
  const Scene scene = emissive_quad(mat, {im});
  const Lights lights(scene);
  int bright = 0;
  const int n = 100000;
  Mean flux;
  for (int i = 0; i < n; ++i) {
    Rng rng(12, 0, uint64_t(i), Stream::Test);
    const EmittedPhoton p = lights.sample_photon(rng);
    const bool in = p.origin.x < 0.5f;  // u < 1/4 on the 2 m wide quad
    bright += in;
    if (!in) EXPECT_EQ(p.flux, vec3(0.0f)) << p.origin.x;
    flux.add(p.flux.x);
  }
  EXPECT_GT(double(bright) / n, 0.75);
  EXPECT_NEAR(flux.mean(), kPiD * 2 * 0.25, 4.0 * flux.se());  // pi x (bright area 0.5)
}

TEST(TexturedEmitter, NextEventEstimateMatchesTheIrradianceIntegral) {
  // Irradiance at a receiver facing the quad (0.3 m in front of its bright corner), from the
  // textured emitter, by next-event samples (cos at the receiver included) against a 400 x 200
  // midpoint quadrature of Le(x) cos_r cos_l / d^2 over the quad, Le from the hand-written
  // bilinear (clamped) texture: within 4 standard errors + 1e-3 relative.
  Image im{"e", 2, 2, 1, {255, 0, 40, 160}, {}};
  Material mat = Material::lambertian(vec3(0.0f));
  mat.emission = vec3(3.0f);
  mat.emissive_texture.image = 0;
  mat.emissive_texture.wrap_s = mat.emissive_texture.wrap_t = Wrap::ClampToEdge;
  const Scene scene = emissive_quad(mat, {im});
  const Lights lights(scene);
  const vec3 receiver(0.4f, 0.7f, 0.3f), normal(0, 0, -1);
  auto texel = [&](int x, int y) { return srgb(im.u8[size_t(2 * y + x)] / 255.0); };
  auto le = [&](double u, double v) {
    const double x = std::clamp(u * 2 - 0.5, 0.0, 1.0), y = std::clamp(v * 2 - 0.5, 0.0, 1.0);
    return 3.0 * ((1 - x) * (1 - y) * texel(0, 0) + x * (1 - y) * texel(1, 0) +
                  (1 - x) * y * texel(0, 1) + x * y * texel(1, 1));
  };
  double want = 0.0;
  for (int i = 0; i < 400; ++i)
    for (int j = 0; j < 200; ++j) {
      const double u = (i + 0.5) / 400, v = (j + 0.5) / 200;
      const dvec3 d = dvec3(2 * u, 1 - v, 0) - dvec3(receiver);
      const double d2 = glm::dot(d, d), cos = -d.z / std::sqrt(d2);  // equal at both ends
      want += le(u, v) * cos * cos / d2 * (2.0 / 80000);
    }
  Mean e;
  for (int i = 0; i < 400000; ++i) {
    Rng rng(13, 0, uint64_t(i), Stream::Test);
    DirectSample s;
    e.add(lights.sample_direct(receiver, normal, rng, s) ? double(s.li.x) * glm::dot(s.wi, normal)
                                                         : 0.0);
  }
  EXPECT_NEAR(e.mean(), want, 4.0 * e.se() + 1e-3 * want);
}

TEST(CoatedEmitter, TheClearCoatDarkensEveryEmissionByItsFresnel) {
  // KHR_materials_clearcoat puts the coat over the emission: 1 - c (0.04 + 0.96 (1 - cos)^5) of
  // it leaves at cosine cos with the normal. With the same random numbers, every photon and
  // every next-event sample of a coated emitter is the uncoated one's times that share at its
  // own direction (relative 1e-5), near the quad (solid-angle sampling) and far from it (area
  // sampling); the photons' mean flux is the coated emitter's power, pi A Le (1 - c x the
  // cosine-weighted mean of Schlick's term: 0.04 + 0.96 x 2 / 42 for the cosine-weighted mean
  // of (1 - cos)^5, which is 2 B(2, 6) = 1/21).
  Material bare = Material::lambertian(vec3(0.0f));
  bare.emission = vec3(1.5f);
  Material coated = bare;
  coated.clearcoat = 0.6f;
  const Scene a = emissive_quad(bare), b = emissive_quad(coated);
  const Lights plain(a), coat(b);
  Mean flux;
  for (int i = 0; i < 100000; ++i) {
    Rng r1(18, 0, uint64_t(i), Stream::Test), r2(18, 0, uint64_t(i), Stream::Test);
    const EmittedPhoton p = plain.sample_photon(r1), q = coat.sample_photon(r2);
    ASSERT_EQ(p.dir, q.dir);
    const float share = 1.0f - clearcoat_fresnel(0.6f, p.dir.z);
    EXPECT_NEAR(q.flux.x, p.flux.x * share, 1e-5f * p.flux.x);
    flux.add(q.flux.x);
  }
  const double power = kPiD * 2 * 1.5 * (1.0 - 0.6 * (0.04 + 0.96 / 21.0));
  EXPECT_NEAR(flux.mean(), power, 4.0 * flux.se());
  for (const vec3& receiver : {vec3(0.7f, 0.4f, 0.5f), vec3(3.0f, -2.0f, 9.0f)})
    for (int i = 0; i < 2000; ++i) {
      Rng r1(19, 0, uint64_t(i), Stream::Test), r2(19, 0, uint64_t(i), Stream::Test);
      DirectSample s, t;
      const bool ok = plain.sample_direct(receiver, vec3(0, 0, -1), r1, s);
      ASSERT_EQ(ok, coat.sample_direct(receiver, vec3(0, 0, -1), r2, t));
      if (!ok) continue;
      const float share = 1.0f - clearcoat_fresnel(0.6f, s.wi.z);
      EXPECT_NEAR(t.li.x, s.li.x * share, 1e-5f * s.li.x);
    }
}

TEST(DoubleSidedEmitter, EmitsTwiceThePowerFromBothSides) {
  // A doubleSided emitter of radiance Le emits 2 pi A Le, half of its photons to each side, and
  // lights a receiver behind it as much as one in front (mirror-image receivers).
  Material mat = Material::lambertian(vec3(0.0f));
  mat.emission = vec3(1.5f);
  mat.double_sided = true;
  const Scene scene = emissive_quad(mat);
  const Lights lights(scene);
  EXPECT_NEAR(lights.total_power().x, 2 * kPiD * 2 * 1.5, 1e-4);
  EXPECT_NEAR(total_emitted_power(scene), 3 * 2 * kPiD * 2 * 1.5, 1e-3);
  int back = 0;
  Mean flux;
  for (int i = 0; i < 100000; ++i) {
    Rng rng(14, 0, uint64_t(i), Stream::Test);
    const EmittedPhoton p = lights.sample_photon(rng);
    back += p.dir.z < 0.0f;
    flux.add(p.flux.x);
  }
  EXPECT_NEAR(back / 100000.0, 0.5, 0.006);            // 4 standard errors of a fair coin
  EXPECT_NEAR(flux.mean(), 2 * kPiD * 2 * 1.5, 1e-4);  // every photon carries the same power
  Mean front, behind;
  for (int i = 0; i < 200000; ++i) {
    Rng a(15, 0, uint64_t(i), Stream::Test), b(16, 0, uint64_t(i), Stream::Test);
    DirectSample s;
    front.add(lights.sample_direct(vec3(0.7f, 0.4f, 0.5f), vec3(0, 0, -1), a, s) ? double(s.li.x)
                                                                                 : 0.0);
    behind.add(lights.sample_direct(vec3(0.7f, 0.4f, -0.5f), vec3(0, 0, 1), b, s) ? double(s.li.x)
                                                                                  : 0.0);
  }
  EXPECT_GT(behind.mean(), 0.0);
  // Near the quad both are sampled in solid angle: each sample is Le x the solid angle.
  EXPECT_NEAR(front.mean(), behind.mean(), 4.0 * (front.se() + behind.se()) + 1e-6);
  // One-sided: nothing behind.
  mat.double_sided = false;
  const Scene one = emissive_quad(mat);
  const Lights single(one);
  Rng rng(17, 0, 0, Stream::Test);
  DirectSample s;
  EXPECT_FALSE(single.sample_direct(vec3(0.7f, 0.4f, -0.5f), vec3(0, 0, 1), rng, s));
}

}  // namespace
}  // namespace pb
