// Thin geometry against a gather disc wider than it (ESTIMATOR.md section 3, "Same side").
#include "render/renderer.h"
#include "scene_builder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace pb {
namespace {

using test::SceneBuilder;

FilmImage render(Scene scene, Method method, DirectMode direct, int size, uint64_t photons,
                 int passes, std::optional<double> radius = std::nullopt) {
  RenderOptions o;
  o.method = method;
  o.direct = direct;
  o.width = o.height = size;
  o.radius = radius;
  o.photons_per_pass = photons;
  o.progress = ProgressMode::Never;
  Renderer r(std::move(scene), o);
  for (int pass = 0; pass < passes; ++pass) r.step();
  FilmImage img;
  r.develop(&img);
  return img;
}

// A closed double-sided emissive tube (radius 0.02, length 1, 16 sides, base colour
// (1, 0, 0.733), emission (1, 0.305, 1): issue 37's neon tube) alone in the dark, seen from
// z = 0.6 across its axis, gathered with a disc of radius 0.05, wider than the tube. The tube
// is convex, so no light of its own reaches its outside: every point the camera sees has
// exactly the emitted radiance, and a pixel the tube covers in part a share of it. Light
// emitted inside bounces on the inner walls (red forever: base colour 1); a gather that counts
// those photons for the outer wall makes light out of nothing.
Scene neon_tube() {
  SceneBuilder b;
  const uint32_t m = b.material(vec3(1.0f, 0.0f, 0.733f), vec3(1.0f, 0.305f, 1.0f));
  b.scene.materials[m].double_sided = true;
  b.tube(vec3(0), 0.02f, 0.5f, 16, m);
  b.camera(vec3(0, 0, 0.6f), vec3(0), 0.35f);
  return b.scene;
}

TEST(ThinRender, AClosedEmissiveTubeShowsItsEmissionAndNoMore) {
  const vec3 emitted(1.0f, 0.305f, 1.0f);
  for (Method method : {Method::PPM, Method::SPPM})
    for (DirectMode direct : {DirectMode::NextEvent, DirectMode::Photons}) {
      // The tube is about 2.6 pixels wide, the disc 3.3 in radius.
      const FilmImage img = render(neon_tube(), method, direct, 24, 4000, 4, 0.05);
      float most = 0.0f;
      for (size_t k = 0; k < img.radiance.size(); k += 3) {
        for (int c = 0; c < 3; ++c) {
          // At most the emission (a covered share of it, plus nothing); the only slack is
          // float rounding of the per-pass means.
          EXPECT_LE(img.radiance[k + c], emitted[c] * (1.0f + 1e-5f))
              << "pixel " << k / 3 << " channel " << c << " method " << int(method) << " direct "
              << int(direct);
        }
        most = std::max(most, img.radiance[k]);
      }
      // The pixels down the tube's middle are covered whole (PPM: their centre is on it).
      EXPECT_GE(most, emitted[0] * (1.0f - 1e-5f));
    }
}

// Thin slats (8 cm wide, 1 cm thick, 1 cm above a ground; every surface a Lambertian of 0.6)
// under a uniform sky of 1, seen from straight above at the default radius (4 pixel
// footprints, wider than a slat). A slat's top sees the whole sky and nothing else: exactly 0.6.
// It must not gather the ground's photons beside and under it: they lie behind its plane on a
// surface that faces it. Counting them put the tops' mean at 0.654 (next-event direct light)
// and 0.82 (--direct photons). Now 0.600 and 0.612: next-event light is the sky's alone,
// exact but for rounding; photons leave the noise of 16 passes, whose mean over the 384 slat
// pixels has a standard error of about 0.01 (neighbouring pixels share photons), so 0.04.
Scene slats() {
  SceneBuilder b;
  const uint32_t m = b.material(vec3(0.6f));
  b.quad(vec3(0), vec3(0, 0, 3), vec3(3, 0, 0), m);  // front +y
  for (int k = -2; k <= 2; ++k)
    b.box(vec3(0.3f * float(k) - 0.04f, 0.01f, -2.0f), vec3(0.3f * float(k) + 0.04f, 0.02f, 2.0f),
          m);
  b.scene.environment = Environment{"sky", 1, 1, {vec3(1.0f)}};
  b.camera(vec3(0, 3, 0), vec3(0), 0.5f, vec3(0, 0, -1));
  return b.scene;
}

TEST(ThinRender, ThinSlatTopsUnderTheSkyShowTheSkyAndNotTheGroundBelow) {
  constexpr int kSize = 48;
  for (Method method : {Method::PPM, Method::SPPM})
    for (DirectMode direct : {DirectMode::NextEvent, DirectMode::Photons}) {
      const FilmImage img = render(slats(), method, direct, kSize, 50000, 16);
      // Pixel column x spans world x in [x0, x1] on the tops (2.98 below the camera, which
      // looks down with +x to the right); the columns wholly on a top are averaged.
      double sum = 0.0;
      int n = 0;
      const double half_width = std::tan(0.25) * 2.98;
      for (int x = 0; x < kSize; ++x) {
        const double x0 = half_width * (2.0 * x / kSize - 1.0),
                     x1 = half_width * (2.0 * (x + 1) / kSize - 1.0);
        for (int k = -2; k <= 2; ++k) {
          if (x0 < 0.3 * k - 0.04 || x1 > 0.3 * k + 0.04) continue;
          for (int y = 0; y < kSize; ++y)
            for (int c = 0; c < 3; ++c) sum += img.radiance[3 * size_t(y * kSize + x) + size_t(c)];
          n += 3 * kSize;
        }
      }
      ASSERT_EQ(n, 8 * 3 * kSize);  // two columns per slat
      EXPECT_NEAR(sum / n, 0.6, direct == DirectMode::NextEvent ? 0.01 : 0.04)
          << "method " << int(method) << " direct " << int(direct);
    }
}

// A board (albedo 0.9, 1 cm thick, its top 2 cm up) over half of a ground (albedo 0.1), lit by
// a sun 10 degrees above the horizon from beyond the board, seen from straight above across the
// board's edge at x = 0. The board shades the ground beyond its edge for 11 cm: there the ground
// sees neither the sun nor the board's top (which faces away from it), only the unlit side of
// the board and the ground around it, so its light is of third order and below 0.001. The
// board's top faces the way the ground does and lies in front of its plane, closer than the
// disc's radius (about 4 cm): counting its sunlit photons for the shaded ground beside the edge
// makes light where there is none. With --direct photons (the top's photons carry the sun's
// light) the shade's first 5 cm came out at 0.0057 (PPM) and 0.0052 (SPPM) on average, 57% and
// 52% of what the lit ground's 0.1 would give there; now 0 to 5 digits.
Scene board_in_low_sun() {
  SceneBuilder b;
  const uint32_t ground = b.material(vec3(0.1f)), board = b.material(vec3(0.9f));
  b.quad(vec3(0), vec3(0, 0, 3), vec3(3, 0, 0), ground);  // front +y
  b.box(vec3(-2.0f, 0.01f, -2.0f), vec3(0.0f, 0.02f, 2.0f), board);
  const float elevation = 10.0f * kPi / 180.0f;
  // Irradiance pi / sin(10 deg) on a surface facing the sun: pi on the horizontal, so a lit
  // surface of albedo rho shows rho.
  b.directional_light(vec3(std::cos(elevation), -std::sin(elevation), 0.0f),
                      vec3(kPi / std::sin(elevation)));
  b.camera(vec3(0, 1, 0), vec3(0), 0.5f, vec3(0, 0, -1));
  return b.scene;
}

TEST(ThinRender, ShadeBesideABoardDoesNotGatherTheSunlitTop) {
  constexpr int kSize = 48;
  for (Method method : {Method::PPM, Method::SPPM}) {
    const FilmImage img = render(board_in_low_sun(), method, DirectMode::Photons, kSize, 50000, 16);
    // Columns wholly on the shaded ground within 5 cm of the edge (the camera looks down with
    // +x to the right), where the board's top lies inside the disc.
    const double half_width = std::tan(0.25) * 1.0;
    double sum = 0.0;
    int n = 0;
    for (int x = 0; x < kSize; ++x) {
      const double x0 = half_width * (2.0 * x / kSize - 1.0),
                   x1 = half_width * (2.0 * (x + 1) / kSize - 1.0);
      if (x0 < 0.0 || x1 > 0.05) continue;
      for (int y = 0; y < kSize; ++y)
        for (int c = 0; c < 3; ++c) sum += img.radiance[3 * size_t(y * kSize + x) + size_t(c)];
      n += 3 * kSize;
    }
    ASSERT_GT(n, 0);
    std::printf("method %d: shade beside the board %.5f over %d\n", int(method), sum / n, n);
    EXPECT_LE(sum / n, 0.002) << "method " << int(method);
  }
}

// Strips in the sky (issue 37's house: clapboards, slats and louvres narrower than the disc,
// often modelled as separate planes): 41 coplanar quads 1.2 cm tall and 3 cm apart, a
// Lambertian of 0.6 under a uniform sky of 1, seen head-on from 2 m at the default radius (4
// pixel footprints, 8.5 cm: more than the spacing), with --direct photons (every light a
// photon's). A strip sees the sky alone, so its radiance is exactly 0.6 and a pixel's is
// 1 - 0.4 a for the share a of its area the strips cover (SPPM; PPM: its centre's). A strip's
// disc is a band between two edges (kernel mass about 0.15), and the next strips lie in its
// plane within the disc, beyond those edges: counting their photons, renormalised by the
// band's mass, made the strips about 1.5 times as bright as they are.
Scene strips_in_the_sky() {
  SceneBuilder b;
  const uint32_t m = b.material(vec3(0.6f));
  for (int k = -20; k <= 20; ++k)
    b.quad(vec3(0.0f, 0.03f * float(k), 0.0f), vec3(1.5f, 0, 0), vec3(0, 0.006f, 0), m);
  b.scene.environment = Environment{"sky", 1, 1, {vec3(1.0f)}};
  b.camera(vec3(0, 0, 2), vec3(0), 0.5f);
  return b.scene;
}

// The share of image row y (of n) that the strips cover: the plane z = 0 is seen head-on, so a
// row spans world heights [top - (y + 1) s, top - y s] with s = 2 top / n, the centre's (PPM)
// at its middle.
double strip_share(int y, int n, bool centre) {
  const double top = 2.0 * std::tan(0.25), s = 2.0 * top / n;
  const double hi = top - y * s, lo = hi - s;
  double share = 0.0;
  for (int k = -20; k <= 20; ++k) {
    const double a = 0.03 * k - 0.006, b = 0.03 * k + 0.006;
    if (centre)
      share += (0.5 * (lo + hi) > a && 0.5 * (lo + hi) < b) ? 1.0 : 0.0;
    else
      share += std::max(0.0, std::min(hi, b) - std::max(lo, a)) / s;
  }
  return share;
}

TEST(ThinRender, StripsInTheSkyShowTheirAlbedo) {
  constexpr int kSize = 48;
  for (Method method : {Method::PPM, Method::SPPM}) {
    const FilmImage img =
        render(strips_in_the_sky(), method, DirectMode::Photons, kSize, 50000, 16);
    // Over the pixels a strip covers (at least a quarter of them), the error's mean and how
    // often the bound covers it.
    double error = 0.0;
    int n = 0, covered = 0;
    for (int y = 0; y < kSize; ++y) {
      const double a = strip_share(y, kSize, method == Method::PPM);
      if (a < 0.25) continue;
      for (int x = 0; x < kSize; ++x)
        for (int c = 0; c < 3; ++c) {
          const size_t k = 3 * size_t(y * kSize + x) + size_t(c);
          const double e = img.radiance[k] - (1.0 - 0.4 * a);
          error += e;
          covered += std::abs(e) <= img.bound[k];
          ++n;
        }
    }
    ASSERT_GT(n, 0);
    std::printf("method %d: mean error %.4f over %d, covered %.3f\n", int(method), error / n, n,
                double(covered) / n);
    // Measured: -0.013 (PPM) and +0.002 (SPPM) after these 16 passes, within 0.0032 after 64
    // and 256, so the mean's noise is about 0.01 here; counting the next strips' photons gave
    // +0.29 and +0.25.
    EXPECT_NEAR(error / n, 0.0, 0.04) << "method " << int(method);
    // The bounds at 90% (measured 0.92 and 1.00).
    EXPECT_GE(double(covered) / n, 0.8) << "method " << int(method);
  }
}

}  // namespace
}  // namespace pb
