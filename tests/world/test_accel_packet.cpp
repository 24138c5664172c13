// Accel::intersect_packet and occluded_packet (Embree 3's rtcIntersect8 and rtcOccluded8) against
// Accel::intersect and occluded: the camera pass traces its camera rays and the next-event stage
// its shadow rays as packets, and the images are the single rays' bit for bit only if every
// lane's answer is the lone ray's, BLEND coverage (a key per lane) and MASK cut-outs included.
#include "scene_builder.h"

#include "util/rng.h"
#include "world/accel.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>

namespace pb {
namespace {

using test::SceneBuilder;

// Spheres, boxes and a floor, a BLEND card of alpha 0.5 and a MASK card whose alpha 0.3 is under
// its cutoff (every ray passes it), in [-2, 2]^3.
Scene cluttered() {
  SceneBuilder b;
  const uint32_t grey = b.material(vec3(0.5f));
  b.quad(vec3(0, -1, 0), vec3(2, 0, 0), vec3(0, 0, -2), grey);
  b.box(vec3(-1.5f, -1, -1.5f), vec3(-0.5f, 0.2f, -0.3f), grey);
  b.sphere(vec3(0.8f, -0.2f, 0.4f), 0.7f, 24, 12, grey);
  b.sphere(vec3(-0.3f, 0.9f, -0.8f), 0.35f, 16, 8, grey);
  const uint32_t blend = b.material(vec3(0.2f));
  b.scene.materials[blend].alpha_mode = AlphaMode::Blend;
  b.scene.materials[blend].alpha = 0.5f;
  b.quad(vec3(0, 0, 1.2f), vec3(1.2f, 0, 0), vec3(0, 1.2f, 0), blend);
  const uint32_t mask = b.material(vec3(0.7f));
  b.scene.materials[mask].alpha_mode = AlphaMode::Mask;
  b.scene.materials[mask].alpha = 0.3f;
  b.quad(vec3(1.2f, 0, 0), vec3(0, 1.0f, 0), vec3(0, 0, 1.0f), mask);
  return b.scene;
}

bool same_bits(float a, float b) {
  return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b);
}

// Traces rays[0, n) as one packet and each alone, as closest-hit rays and as shadow rays;
// counts the lanes compared, their hits and the shadow rays blocked.
void expect_packet_is_single_rays(const Accel& accel, const Accel::Ray* rays, int n, size_t& lanes,
                                  size_t& hits, size_t& occluded) {
  Hit packet[Accel::kPacket];
  bool found[Accel::kPacket];
  accel.intersect_packet(rays, n, packet, found);
  for (int i = 0; i < n; ++i) {
    Hit alone;
    const bool f = accel.intersect(rays[i].origin, rays[i].dir, rays[i].tnear, rays[i].tfar, alone,
                                   rays[i].key);
    ++lanes;
    ASSERT_EQ(found[i], f) << "lane " << i << " of " << n;
    if (!f) continue;
    ++hits;
    EXPECT_EQ(packet[i].mesh, alone.mesh);
    EXPECT_EQ(packet[i].prim, alone.prim);
    EXPECT_TRUE(same_bits(packet[i].t, alone.t)) << packet[i].t << " " << alone.t;
    EXPECT_TRUE(same_bits(packet[i].u, alone.u)) << packet[i].u << " " << alone.u;
    EXPECT_TRUE(same_bits(packet[i].v, alone.v)) << packet[i].v << " " << alone.v;
  }
  // The same rays as shadow rays.
  bool blocked[Accel::kPacket];
  accel.occluded_packet(rays, n, blocked);
  for (int i = 0; i < n; ++i) {
    const bool b =
        accel.occluded(rays[i].origin, rays[i].dir, rays[i].tnear, rays[i].tfar, rays[i].key);
    EXPECT_EQ(blocked[i], b) << "lane " << i << " of " << n;
    occluded += b;
  }
}

TEST(AccelPacket, EveryLaneIsTheLoneRaysHitBitForBit) {
  const Scene scene = cluttered();
  const Accel accel(scene);
  Rng rng(7, 0, 0, Stream::Camera);
  size_t lanes = 0, hits = 0, occluded = 0;
  // Coherent: rows of 8 camera rays from one eye through neighbouring image points, as the
  // camera pass traces them; every ray with its own BLEND key.
  const vec3 eye(0.3f, 0.4f, 4.0f);
  for (int row = 0; row < 64; ++row)
    for (int col = 0; col < 64; col += Accel::kPacket) {
      Accel::Ray rays[Accel::kPacket];
      for (int i = 0; i < Accel::kPacket; ++i) {
        const float x = (float(col + i) + rng.next_float()) / 64.0f - 0.5f;
        const float y = 0.5f - (float(row) + rng.next_float()) / 64.0f;
        rays[i] = {eye, glm::normalize(vec3(x, y, -1.0f)), 0.0f, INFINITY,
                   (uint64_t(rng.next_u32()) << 32 | rng.next_u32()) | 1u};
      }
      expect_packet_is_single_rays(accel, rays, Accel::kPacket, lanes, hits, occluded);
    }
  // Incoherent: any origin and direction, finite and infinite tfar, key 0 (every BLEND surface
  // met) on some lanes, and packets of 1 to 8 rays.
  for (int packet = 0; packet < 2000; ++packet) {
    const int n = 1 + packet % Accel::kPacket;
    Accel::Ray rays[Accel::kPacket];
    for (int i = 0; i < n; ++i) {
      const vec3 o(4 * rng.next_float() - 2, 4 * rng.next_float() - 2, 4 * rng.next_float() - 2);
      const vec3 d(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
      const float tfar = rng.next_float() < 0.5f ? INFINITY : 4 * rng.next_float();
      const uint64_t key = rng.next_float() < 0.2f ? 0 : uint64_t(rng.next_u32()) << 20 | 1u;
      rays[i] = {o, glm::length(d) > 1e-3f ? glm::normalize(d) : vec3(0, 1, 0), 0.0f, tfar, key};
    }
    expect_packet_is_single_rays(accel, rays, n, lanes, hits, occluded);
  }
  // Enough hits to have met every surface, the cards included, many times over.
  EXPECT_EQ(lanes, size_t(64 * 64 + 2000 * 9 / 2));
  EXPECT_GT(hits, lanes / 3);
  // A segment is blocked exactly where its closest-hit ray finds something (the same filters).
  EXPECT_EQ(occluded, hits);
}

}  // namespace
}  // namespace pb
