// Triangles piled at one place (issue 36) in the boundary index (boundary.h, boundary_copies.cpp):
// exact copies are indexed once, in work linear in the triangles, and give the index a single
// copy gives; a pile that is not made of copies stops at the work budget and gives the index up.
// The work is counted (BoundaryIndex::work(): candidates the index's queries returned), not timed.
#include "boundary_scene.h"
#include "world/boundary.h"
#include "world/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <thread>

namespace pb {
namespace {

Scene scene_of(std::vector<Mesh> meshes) {
  return test::boundary_scene("copies", std::move(meshes));
}

// A floor [-1, 1]^2 at z = 0 facing +z (triangles 0 and 1), and a fin standing through it in
// the plane y = 0 (from z = -0.2 to 0.5), listed `copies` times in one mesh. Every other copy
// starts its corner list at another corner (the same triangle, the same winding), and the fin's
// mesh has `turned` more fins each turned about the y axis through its centre by a different
// small angle: piled at one place too, but not copies.
Scene floor_and_fin(int copies, int turned = 0) {
  Mesh floor;
  floor.name = "floor";
  floor.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  floor.indices = {0, 1, 2, 0, 2, 3};
  Mesh fin;
  fin.name = "fin";
  fin.positions = {{-0.3f, 0, -0.2f}, {0.3f, 0, -0.2f}, {0, 0, 0.5f}};
  for (int k = 0; k < copies; ++k) {
    if (k % 2 == 0)
      fin.indices.insert(fin.indices.end(), {0u, 1u, 2u});
    else
      fin.indices.insert(fin.indices.end(), {1u, 2u, 0u});
  }
  const vec3 centre = (fin.positions[0] + fin.positions[1] + fin.positions[2]) / 3.0f;
  for (int k = 1; k <= turned; ++k) {
    const float a = 1e-4f * float(k), c = std::cos(a), s = std::sin(a);
    const uint32_t b = uint32_t(fin.positions.size());
    for (int i = 0; i < 3; ++i) {
      const vec3 d = fin.positions[size_t(i)] - centre;
      fin.positions.push_back(centre + vec3(c * d.x + s * d.z, 0.0f, -s * d.x + c * d.z));
    }
    fin.indices.insert(fin.indices.end(), {b, b + 1, b + 2});
  }
  return scene_of({floor, fin});
}

// Points near where the fin crosses the floor (the floor's blocker cut, y = 0) and near the
// fin's border, on the floor and on the fin.
struct Probe {
  bool on_fin;
  vec3 p, n;
};
const Probe kProbes[] = {
    {false, {0.1f, 0.05f, 0.0f}, {0, 0, 1}}, {false, {-0.2f, -0.08f, 0.0f}, {0, 0, 1}},
    {false, {0.5f, 0.5f, 0.0f}, {0, 0, 1}},  {true, {0.0f, 0.0f, 0.1f}, {0, -1, 0}},
    {true, {0.1f, 0.0f, 0.25f}, {0, -1, 0}}, {true, {-0.15f, 0.0f, 0.02f}, {0, -1, 0}},
};

// The floor's triangle under (x, y): triangle 0 holds y < x.
uint32_t floor_triangle(const vec3& p) { return p.y < p.x ? 0u : 1u; }

TEST(BoundaryCopies, A65536FoldPileIsIndexedOnceInLinearWork) {
  constexpr int kCopies = 65536;
  const World one(floor_and_fin(1));
  const World pile(floor_and_fin(kCopies));
  const float radius = 0.15f;
  const BoundaryIndex single(one, radius);
  const BoundaryIndex piled(pile, radius);
  EXPECT_EQ(single.coincident_count(), 0u);
  EXPECT_EQ(piled.coincident_count(), size_t(kCopies - 1));
  EXPECT_FALSE(piled.truncated());
  EXPECT_GT(single.segment_count(), 3u);  // the fin's border and both crossings at least
  EXPECT_EQ(piled.segment_count(), single.segment_count());
  // Each geometric query about the pile returns every copy, so the work grows with the copies;
  // quadratic growth (every copy querying every other, 4.3e9 candidates, minutes) is what this
  // bounds. Measured: 17 per triangle.
  const size_t triangles = pile.triangle_count();
  EXPECT_LE(piled.work(), 32 * triangles) << piled.work();
  // Every copy answers as the single fin, and the floor as under the single fin.
  for (const Probe& q : kProbes) {
    for (uint32_t copy : {0u, 1u, uint32_t(kCopies / 2), uint32_t(kCopies - 1)}) {
      const uint32_t t = q.on_fin ? 2u + copy : floor_triangle(q.p);
      const uint32_t t1 = q.on_fin ? 2u : floor_triangle(q.p);
      const DiscMoments a = piled.moments(t, q.p, q.n, radius);
      const DiscMoments b = single.moments(t1, q.p, q.n, radius);
      EXPECT_EQ(a.full, b.full) << q.p.x << ", " << q.p.z << " copy " << copy;
      EXPECT_EQ(a.mass, b.mass) << q.p.x << ", " << q.p.z << " copy " << copy;
      EXPECT_EQ(a.lap_second, b.lap_second);
      EXPECT_EQ(piled.clearance(t, q.p, radius), single.clearance(t1, q.p, radius));
    }
  }
  // The probes see both sides: cut discs and whole ones.
  int cut = 0;
  for (const Probe& q : kProbes)
    cut += !piled.moments(q.on_fin ? 2u : floor_triangle(q.p), q.p, q.n, radius).full;
  EXPECT_GT(cut, 0);
  EXPECT_LT(cut, int(std::size(kProbes)));
}

// A lone triangle listed twice: each copy shares all three edges with the other, which hid
// every border before copies were indexed once (a disc at its edge counted as whole).
TEST(BoundaryCopies, ALoneTriangleListedTwiceKeepsItsBorders) {
  Mesh m;
  m.name = "twice";
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  m.indices = {0, 1, 2, 0, 1, 2};
  const World twice(scene_of({m}));
  m.indices = {0, 1, 2};
  const World once(scene_of({m}));
  const BoundaryIndex a(twice, 0.2f), b(once, 0.2f);
  EXPECT_EQ(a.segment_count(), 3u);
  const vec3 p(0.0f, -0.95f, 0.0f);  // 0.05 from the bottom edge
  for (uint32_t t : {0u, 1u}) {
    const DiscMoments m2 = a.moments(t, p, vec3(0, 0, 1), 0.2f);
    EXPECT_FALSE(m2.full);
    EXPECT_EQ(m2.mass, b.moments(0, p, vec3(0, 0, 1), 0.2f).mass);
  }
}

// Fins piled at one place, each turned by its own angle: no two are copies, so each query about
// the pile returns all of them (1,024 fins: 15M candidates for the whole index). A small work
// budget stops the construction: the index is given up, having examined at most the budget plus
// 256 per triangle plus, per thread, what it examined since its last check of the budget (at
// most three queries, each returning at most every triangle).
TEST(BoundaryIndexBudget, APileOfTurnedFinsStopsAtTheWorkBudget) {
  const World world(floor_and_fin(1, 1023));
  const size_t triangles = world.triangle_count();
  const BoundaryIndex whole(world, 0.15f);
  EXPECT_FALSE(whole.truncated());
  EXPECT_EQ(whole.coincident_count(), 0u);
  constexpr size_t kSmall = size_t(1) << 18;
  const size_t limit = kSmall + 256 * triangles;
  EXPECT_GT(whole.work(), 4 * limit);  // the small budget does cut it short
  const BoundaryIndex cut(world, 0.15f, kSmall);
  EXPECT_TRUE(cut.truncated());
  EXPECT_EQ(cut.segment_count(), 0u);
  EXPECT_GT(cut.work(), limit);
  const size_t threads = std::max(1u, std::thread::hardware_concurrency());
  EXPECT_LE(cut.work(), limit + 3 * threads * triangles);
  EXPECT_TRUE(cut.moments(0, vec3(0.1f, 0.05f, 0.0f), vec3(0, 0, 1), 0.15f).full);
}

}  // namespace
}  // namespace pb
