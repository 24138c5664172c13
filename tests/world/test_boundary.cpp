// The boundary index (boundary.h, ESTIMATOR.md section 11): the kernel's moments over the part of
// a disc that lies on reachable surface, against brute-force integration over the disc.
#include "boundary_scene.h"
#include "estimator/kernel.h"
#include "world/boundary.h"
#include "world/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace pb {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The unit-mass quintic kernel and its Laplacian, written out again here (kernel.h's profile).
double kappa(double t) {
  return 7.0 / (2.0 * kPi) * (1 - 10 * t * t * t + 15 * std::pow(t, 4) - 6 * std::pow(t, 5));
}
double lap_kappa(double t) { return 105.0 / kPi * (-3 * t + 8 * t * t - 5 * t * t * t); }

// A floor [-1, 1]^2 at z = 0 facing +z, and a wall on its edge x = 1 facing back over it (-x):
// the floor's other three edges are borders, x = 1 a 90-degree crease.
Scene scene_of(const char* source, std::vector<Mesh> meshes) {
  return test::boundary_scene(source, std::move(meshes));
}

Scene floor_and_wall() {
  Mesh floor;
  floor.name = "floor";
  floor.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  floor.indices = {0, 1, 2, 0, 2, 3};
  Mesh wall;
  wall.name = "wall";
  wall.positions = {{1, -1, 0}, {1, 1, 0}, {1, 1, 2}, {1, -1, 2}};
  wall.indices = {0, 2, 1, 0, 3, 2};  // (0, 2, 2) x (0, 2, 0) points along -x
  return scene_of("floor_and_wall", {floor, wall});
}

// Moments over the part of the disc about (px, py) on the floor (x < 1, y in [-1, 1]), by a
// 1200^2 midpoint grid over the unit square of u: error about 1e-4 at the kernel's smooth rim.
DiscMoments brute_force(double px, double py, double r) {
  DiscMoments m{0.0, 0.0, 0.0, 0.0, false};
  constexpr int n = 1200;
  const double h = 2.0 / n;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double ux = -1 + (i + 0.5) * h, uy = -1 + (j + 0.5) * h;
      const double t2 = ux * ux + uy * uy;
      if (t2 >= 1.0) continue;
      const double x = px + r * ux, y = py + r * uy;
      if (x >= 1.0 || x <= -1.0 || y <= -1.0 || y >= 1.0) continue;
      const double t = std::sqrt(t2);
      m.mass += kappa(t) * h * h;
      m.second += t2 * kappa(t) * h * h;
      m.lap_mass += lap_kappa(t) * h * h;
      m.lap_second += t2 * lap_kappa(t) * h * h;
    }
  }
  return m;
}

TEST(Boundary, RadialIntegralsOverTheWholeDisc) {
  // 2 pi G(1): mass 1, second moment 5/24, Laplacian mass 0, Laplacian second moment 4.
  EXPECT_NEAR(2 * kPi * kernel::mass_to(1.0), 1.0, 1e-12);
  EXPECT_NEAR(2 * kPi * kernel::second_to(1.0), 5.0 / 24.0, 1e-12);
  EXPECT_NEAR(2 * kPi * kernel::laplacian_mass_to(1.0), 0.0, 1e-12);
  EXPECT_NEAR(2 * kPi * kernel::laplacian_second_to(1.0), 4.0, 1e-12);
  EXPECT_EQ(kernel::mass_to(0.0), 0.0);
}

TEST(Boundary, PolarMomentsOfAnUnblockedDisc) {
  // Every direction seeing the whole radius: the whole disc's moments (kernel.h).
  double rho[BoundaryIndex::kDirections];
  std::fill(rho, rho + BoundaryIndex::kDirections, 0.5);
  const DiscMoments m = kernel::polar_moments(rho, BoundaryIndex::kDirections, 0.5);
  EXPECT_NEAR(m.mass, 1.0, 1e-12);
  EXPECT_NEAR(m.second, 5.0 / 24.0, 1e-12);
  EXPECT_NEAR(m.lap_mass, 0.0, 1e-12);
  EXPECT_NEAR(m.lap_second, 4.0, 1e-12);
  EXPECT_FALSE(m.full);
}

class BoundaryMoments : public ::testing::Test {
 protected:
  BoundaryMoments() : world_(floor_and_wall()), index_(world_, 0.5f) {}
  World world_;
  BoundaryIndex index_;
  // Floor triangle 0 holds the points below its diagonal (y < x).
  uint32_t floor_triangle() const { return world_.triangle_index(0, 0); }
};

TEST_F(BoundaryMoments, FarFromEveryEdgeTheDiscIsWhole) {
  const DiscMoments m =
      index_.moments(floor_triangle(), vec3(0.2f, -0.1f, 0.0f), vec3(0, 0, 1), 0.3f);
  EXPECT_DOUBLE_EQ(m.mass, 1.0);
  EXPECT_TRUE(m.full || std::fabs(m.mass - 1.0) < 1e-9);
}

TEST_F(BoundaryMoments, CutByTheCreaseMatchesBruteForce) {
  // Chords at 0.1, 0.5 and 0.75 of the radius r = 0.2. The 64-direction midpoint rule in the
  // angle has its largest error where the chord passes close to the centre (the visible extent
  // then changes fast with the angle near the chord's ends): measured 3e-4 in the mass and
  // 0.04 in the Laplacian moments (lap kappa peaks at 8) at 0.1 r. That Laplacian error moves
  // the bias estimate by k2 / 2 * 0.04 L, 0.2% of L, well inside the noise of the Laplacian
  // sample. The grid's own error is about 1e-4.
  for (double d : {0.02, 0.1, 0.15}) {
    const double px = 1.0 - d, py = -0.3;
    const DiscMoments m =
        index_.moments(floor_triangle(), vec3(float(px), float(py), 0.0f), vec3(0, 0, 1), 0.2f);
    const DiscMoments b = brute_force(px, py, 0.2);
    EXPECT_FALSE(m.full);
    EXPECT_NEAR(m.mass, b.mass, 2e-3) << d;
    EXPECT_NEAR(m.second, b.second, 2e-3) << d;
    EXPECT_NEAR(m.lap_mass, b.lap_mass, 0.05) << d;
    EXPECT_NEAR(m.lap_second, b.lap_second, 0.05) << d;
  }
}

TEST_F(BoundaryMoments, CornerOfTwoBordersMatchesBruteForce) {
  const double px = -0.9, py = -0.95;
  const DiscMoments m = index_.moments(world_.triangle_index(0, 0),
                                       vec3(float(px), float(py), 0.0f), vec3(0, 0, 1), 0.2f);
  const DiscMoments b = brute_force(px, py, 0.2);
  EXPECT_NEAR(m.mass, b.mass, 2e-3);
  EXPECT_NEAR(m.second, b.second, 2e-3);
}

TEST_F(BoundaryMoments, PointOnTheCreaseSeesHalfTheDisc) {
  // A pixel centre that sees exactly the line where two walls meet: its own triangle's side of
  // the crease is half the disc (every ray along the surface meets the crease at distance 0,
  // which must not make the whole disc unreachable).
  const DiscMoments m =
      index_.moments(floor_triangle(), vec3(1.0f, -0.3f, 0.0f), vec3(0, 0, 1), 0.2f);
  const DiscMoments b = brute_force(1.0 - 1e-9, -0.3, 0.2);
  EXPECT_NEAR(m.mass, 0.5, 5e-3);
  EXPECT_NEAR(m.mass, b.mass, 5e-3);
  EXPECT_NEAR(m.second, b.second, 5e-3);
}

TEST_F(BoundaryMoments, PointOnTheWallFootSeesHalfTheWall) {
  // The same crease from the wall's side: the wall's triangles face -x.
  const uint32_t t = world_.triangle_index(1, 0);
  const DiscMoments m = index_.moments(t, vec3(1.0f, 0.3f, 0.0f), vec3(-1, 0, 0), 0.2f);
  EXPECT_NEAR(m.mass, 0.5, 5e-3);
}

// The floor of floor_and_wall with a comb of 40 thin quads standing through it (x = -0.8 +
// 0.04 k, y in [0.2, 0.3], z in [-0.5, 0.5]): each crossing is a blocker segment of the floor, so
// the floor's triangles list more segments than one run of the index holds.
Scene floor_with_comb() {
  Scene s = floor_and_wall();
  Mesh comb;
  comb.name = "comb";
  for (int k = 0; k < 40; ++k) {
    const float x = -0.8f + 0.04f * float(k);
    const uint32_t b = uint32_t(comb.positions.size());
    comb.positions.insert(comb.positions.end(),
                          {{x, 0.2f, -0.5f}, {x, 0.3f, -0.5f}, {x, 0.3f, 0.5f}, {x, 0.2f, 0.5f}});
    comb.indices.insert(comb.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
  }
  s.meshes.push_back(comb);
  for (const vec3& p : s.meshes.back().positions) s.bounds.extend(p);
  return s;
}

// Distance from (px, py) on the floor to the nearest place it ends: its square's border (the
// crease x = 1 included) or a tooth of the comb (the segment x = x_k, y in [0.2, 0.3]).
double nearest_end(double px, double py) {
  double d = std::min({1.0 - px, px + 1.0, 1.0 - py, py + 1.0});
  for (int k = 0; k < 40; ++k) {
    const double x = -0.8 + 0.04 * k, y = std::clamp(py, 0.2, 0.3);
    d = std::min(d, std::hypot(px - x, py - y));
  }
  return d;
}

// clearance() against the brute-force distance, over a grid of floor points and three radii,
// and consistent with moments(): the disc is whole up to the clearance and cut just beyond it.
TEST(BoundaryClearance, IsTheDistanceToTheNearestEndWithinTheRadius) {
  const World world(floor_with_comb());
  const BoundaryIndex index(world, 0.5f);
  int cut = 0, checked = 0;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const double px = -0.975 + 0.05 * i, py = -0.975 + 0.05 * j;
      // Floor triangle 0 holds y < x, triangle 1 the rest (floor.indices).
      const uint32_t t = world.triangle_index(0, py < px ? 0 : 1);
      if (std::fabs(py - px) < 1e-3) continue;  // on the diagonal: either triangle
      const vec3 p(float(px), float(py), 0.0f);
      for (float r : {0.05f, 0.2f, 0.45f}) {
        const float c = index.clearance(t, p, r);
        const double expected = std::min(nearest_end(px, py), double(r));
        // The comb's cuts lie just above the floor (at half the index's tolerance, 3.3e-4
        // here), and distances are 3D: within 1e-3 of the planar distance.
        EXPECT_NEAR(c, expected, 1e-3) << px << ", " << py << ", r " << r;
        EXPECT_LE(c, r);
        EXPECT_TRUE(index.moments(t, p, vec3(0, 0, 1), c).full) << px << ", " << py;
        if (c < r) {
          EXPECT_FALSE(index.moments(t, p, vec3(0, 0, 1), std::min(r, c * 1.01f)).full)
              << px << ", " << py << ", r " << r;
          ++cut;
        }
        ++checked;
      }
    }
  EXPECT_GT(cut, checked / 4);  // the grid exercises both sides
}

// Tiles: 120 x 120 separate unit squares, each of two triangles with four border edges
// (57,600 segments, 28,800 triangles). At a radius of the whole field every segment is within
// reach of every triangle: 1.7e9 pairs, far past BoundaryIndex::kPairBudget, so the index must
// give up (an unposed skinned character at a preview resolution hung here, growing past 6 GB)
// and count every disc as whole. At a radius of a tenth of a tile it lists each tile's own
// borders and cuts a disc on a border.
Scene tiles() {
  Mesh m;
  m.name = "tiles";
  for (int i = 0; i < 120; ++i)
    for (int j = 0; j < 120; ++j) {
      const float x = 2.0f * float(i), y = 2.0f * float(j);
      const uint32_t b = uint32_t(m.positions.size());
      m.positions.insert(m.positions.end(),
                         {{x, y, 0}, {x + 1, y, 0}, {x + 1, y + 1, 0}, {x, y + 1, 0}});
      m.indices.insert(m.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
    }
  return scene_of("tiles", {m});
}

TEST(BoundaryIndexBudget, AFieldOfEdgesWithinAHugeRadiusGivesTheIndexUp) {
  const World world(tiles());
  const BoundaryIndex huge(world, 400.0f);
  EXPECT_TRUE(huge.truncated());
  EXPECT_EQ(huge.segment_count(), 0u);
  const uint32_t t = world.triangle_index(0, 0);  // tile (0, 0), below its diagonal
  EXPECT_TRUE(huge.moments(t, vec3(0.5f, 0.01f, 0.0f), vec3(0, 0, 1), 0.3f).full);
  const BoundaryIndex small(world, 0.1f);
  EXPECT_FALSE(small.truncated());
  EXPECT_EQ(small.segment_count(), 4u * 120u * 120u);
  const DiscMoments cut = small.moments(t, vec3(0.5f, 0.01f, 0.0f), vec3(0, 0, 1), 0.1f);
  EXPECT_FALSE(cut.full);
  EXPECT_GT(cut.mass, 0.5);  // the disc's centre is inside the tile, 0.01 from its border
  EXPECT_LT(cut.mass, 1.0);
}

}  // namespace
}  // namespace pb
