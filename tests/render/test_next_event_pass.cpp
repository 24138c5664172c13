// next_event_pass traces the shadow rays of many points as packets (Accel::occluded_packet);
// each point's next-event sample must stay next_event_at's, bit for bit: the same draws, the same
// rays and the same sum, with one test per point (an area light), two (the environment's MIS draw
// at a glossy point), none (a black point), and BLEND cards that pass some rays by their keys.
#include "scene_builder.h"

#include "render/pass_stages.h"
#include "world/world.h"

#include <gtest/gtest.h>

#include <bit>
#include <vector>

namespace pb {
namespace {

bool same_bits(double a, double b) {
  return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b);
}

// A ground y = 0 (Lambertian; rough metal for the glossy points) under a sky and a lamp at y = 2,
// with BLEND cards of alpha 0.5 at y = 1 over part of it.
Scene lit_ground() {
  test::SceneBuilder b;
  b.quad(vec3(0), vec3(4, 0, 0), vec3(0, 0, -4), b.material(vec3(0.6f)));
  b.quad(vec3(0, 2, 0), vec3(0.5f, 0, 0), vec3(0, 0, 0.5f), b.material(vec3(0), vec3(8)));
  const uint32_t card = b.material(vec3(0.3f));
  b.scene.materials[card].alpha_mode = AlphaMode::Blend;
  b.scene.materials[card].alpha = 0.5f;
  b.quad(vec3(1, 1, 0), vec3(1, 0, 0), vec3(0, 0, 1), card);
  b.quad(vec3(-1.5f, 1, 1), vec3(0.6f, 0, 0), vec3(0, 0, 0.6f), card);
  Environment sky;
  sky.source = "test sky";
  sky.radiance = {vec3(0.5f)};
  b.scene.environment = sky;
  return std::move(b.scene);
}

TEST(NextEventPass, EachPointsSampleIsNextEventAtsWithTheShadowRaysInPackets) {
  const World world(lit_ground());
  ASSERT_TRUE(world.has_blend());
  const Bsdf metal(Material::metal(vec3(0.9f), 0.3f), vec3(0, 1, 0), vec3(0, 1, 0));
  constexpr size_t kPoints = 1000;  // 15 groups of 64 and a part
  std::vector<VisiblePoint> points(kPoints);
  std::vector<PointBsdf> glossy;
  Rng rng(3, 0, 0, Stream::Camera);
  for (size_t k = 0; k < kPoints; ++k) {
    VisiblePoint& p = points[k];
    p.position = vec3(6 * rng.next_float() - 3, 1e-6f, 6 * rng.next_float() - 3);
    p.normal = p.shading = vec3(0, 1, 0);
    // Every 7th point black (no sample), every 3rd glossy (two tests: the sky's MIS draw).
    p.f = k % 7 == 3 ? vec3(0.0f) : vec3(0.2f, 0.15f, 0.1f);
    if (k % 3 == 1) glossy.push_back({uint32_t(k), glm::normalize(vec3(0.3f, 1, 0.2f)), metal});
  }
  const PointBsdfTable table{glossy, 0};
  std::vector<OwnerValues> out(kPoints);
  for (OwnerValues& o : out) o.direct = dvec3(0.25, 0.5, 0.125);  // added to, not replaced
  constexpr uint64_t kSeed = 11, kPass = 5, kFirst = 40000;
  next_event_pass(world, points, table, kSeed, kPass, kFirst, out);
  size_t lit = 0, glossy_seen = 0;
  for (size_t k = 0; k < kPoints; ++k) {
    const PointBsdf* g = nullptr;
    for (const PointBsdf& e : glossy)
      if (e.point == k) g = &e;
    glossy_seen += g != nullptr;
    dvec3 expected(0.25, 0.5, 0.125);
    if (points[k].f.x > 0.0f)
      expected += next_event_at(world, points[k], g, kSeed, kPass, kFirst + k);
    for (int c = 0; c < 3; ++c)
      EXPECT_TRUE(same_bits(out[k].direct[c], expected[c]))
          << "point " << k << " channel " << c << ": " << out[k].direct[c] << " " << expected[c];
    lit += out[k].direct.x > 0.25;
  }
  EXPECT_EQ(glossy_seen, glossy.size());
  // Most points see the lamp or the sky; the cards and the lamp's back shade some.
  EXPECT_GT(lit, kPoints / 2);
}

}  // namespace
}  // namespace pb
