// HashGrid against brute force: exact index sets (so a missed, extra or repeated photon fails),
// dist2 values, determinism of the visit order, and input validation.
#include "estimator/kernel.h"
#include "render/hash_grid.h"
#include "render/pass_stages.h"
#include "util/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

namespace pb {
namespace {

struct Query {
  vec3 center;
  float radius;
};

vec3 random_in(Rng& rng, const vec3& lo, const vec3& hi) {
  const vec3 u(rng.next_float(), rng.next_float(), rng.next_float());
  return lo + u * (hi - lo);
}

std::vector<vec3> random_cloud(uint64_t seed, size_t n, const vec3& lo, const vec3& hi) {
  std::vector<vec3> pts(n);
  for (size_t i = 0; i < n; ++i) {
    Rng rng(seed, 0, i, Stream::Test);
    pts[i] = random_in(rng, lo, hi);
  }
  return pts;
}

std::vector<float> radii_of(const std::vector<Query>& qs) {
  std::vector<float> r;
  for (const Query& q : qs) r.push_back(q.radius);
  return r;
}

// Checks one query: visited set == brute-force set (same float test), no repeats, dist2 equal to
// the float formula and close to the double-precision distance. Returns the visited count.
size_t check_query(const HashGrid& grid, const std::vector<vec3>& pts, const Query& q) {
  std::vector<uint32_t> got;
  grid.query(q.center, q.radius, [&](uint32_t i, float d2) {
    EXPECT_LT(i, pts.size());
    if (i >= pts.size()) return;
    EXPECT_EQ(d2, HashGrid::distance2(pts[i], q.center)) << "photon " << i;
    const dvec3 d = dvec3(pts[i]) - dvec3(q.center);
    EXPECT_NEAR(d2, glm::dot(d, d), 1e-6 * (glm::dot(d, d) + 1e-30) + 1e-3 * q.radius * q.radius);
    got.push_back(i);
  });
  std::vector<uint32_t> want;
  const float r2 = q.radius * q.radius;
  for (size_t i = 0; i < pts.size(); ++i)
    if (HashGrid::distance2(pts[i], q.center) < r2) want.push_back(uint32_t(i));
  std::sort(got.begin(), got.end());
  EXPECT_EQ(std::adjacent_find(got.begin(), got.end()), got.end())
      << "photon visited twice; centre (" << q.center.x << ", " << q.center.y << ", " << q.center.z
      << ") r " << q.radius;
  EXPECT_EQ(got, want) << "centre (" << q.center.x << ", " << q.center.y << ", " << q.center.z
                       << ") r " << q.radius;
  return want.size();
}

size_t check_all(const HashGrid& grid, const std::vector<vec3>& pts, const std::vector<Query>& qs) {
  size_t total = 0;
  for (const Query& q : qs) total += check_query(grid, pts, q);
  return total;
}

TEST(HashGrid, EqualRadiiMatchBruteForce) {
  const auto pts = random_cloud(1, 20000, vec3(0.0f), vec3(1.0f));
  std::vector<Query> qs;
  for (size_t i = 0; i < 2000; ++i) {
    Rng rng(2, 0, i, Stream::Test);
    qs.push_back({random_in(rng, vec3(-0.05f), vec3(1.05f)), 0.03f});
  }
  HashGrid grid;
  grid.build(pts, radii_of(qs));
  EXPECT_EQ(grid.level_count(), 1);
  EXPECT_GT(check_all(grid, pts, qs), 2000u);  // ~2 photons per query: the sets are not trivial
}

TEST(HashGrid, RadiiSpanning1000x) {
  const auto pts = random_cloud(3, 20000, vec3(0.0f), vec3(1.0f));
  std::vector<Query> qs;
  for (size_t i = 0; i < 1500; ++i) {
    Rng rng(4, 0, i, Stream::Test);
    const vec3 c = random_in(rng, vec3(0.0f), vec3(1.0f));
    qs.push_back({c, 1e-3f * std::pow(1000.0f, rng.next_float())});
  }
  qs.push_back({vec3(0.5f), 1e-3f});
  qs.push_back({vec3(0.5f), 1.0f});
  HashGrid grid;
  grid.build(pts, radii_of(qs));
  EXPECT_EQ(grid.level_count(), 11);  // ceil(log2(1000)) + 1 levels, all used
  check_all(grid, pts, qs);
}

TEST(HashGrid, BoundariesOutsideAndNegativeCoordinates) {
  // r = 0.125 gives cells of 0.25: lattice photons lie exactly on cell faces, edges and corners.
  const float r = 0.125f;
  std::vector<vec3> pts;
  for (int z = -4; z <= 4; ++z)
    for (int y = -4; y <= 4; ++y)
      for (int x = -4; x <= 4; ++x) pts.push_back(vec3(float(x), float(y), float(z)) * 0.25f);
  const auto extra = random_cloud(5, 3000, vec3(-1.0f), vec3(1.0f));
  pts.insert(pts.end(), extra.begin(), extra.end());

  std::vector<Query> qs;
  for (float a : {-1.0f, 1.0f})
    for (float b : {-1.0f, 1.0f})
      for (float c : {-1.0f, 1.0f}) qs.push_back({vec3(a, b, c), r});  // cloud corners
  for (float a : {-1.0f, -0.25f, 0.0f, 0.125f, 0.25f, 1.0f, 1.05f, 1.124f, 1.125f, 1.2f})
    for (float b : {-1.0f, 0.0f, 0.375f})
      for (float c : {-1.0f, 0.5f, 1.1f}) qs.push_back({vec3(a, b, c), r});  // faces, outside
  qs.push_back({vec3(100.0f, 0.0f, 0.0f), r});                               // far outside
  qs.push_back({vec3(-1e30f, 1e30f, 0.0f), r});
  for (size_t i = 0; i < 1000; ++i) {
    Rng rng(6, 0, i, Stream::Test);
    qs.push_back({random_in(rng, vec3(-1.3f), vec3(1.3f)), r});
  }
  HashGrid grid;
  grid.build(pts, radii_of(qs));
  check_all(grid, pts, qs);

  // A lattice photon at exactly distance r is excluded (strict test); one at the centre is in.
  std::vector<uint32_t> got;
  grid.query(vec3(0.125f, 0.0f, 0.0f), r, [&](uint32_t i, float) { got.push_back(i); });
  for (uint32_t i : got) EXPECT_GT(i, 728u) << "lattice photon at distance exactly r visited";
  got.clear();
  grid.query(vec3(-0.25f, 0.5f, -1.0f), r, [&](uint32_t i, float d2) {
    if (i <= 728) {
      EXPECT_EQ(d2, 0.0f);
    }
    got.push_back(i);
  });
  EXPECT_NE(std::find(got.begin(), got.end(), uint32_t((0 * 9 + 6) * 9 + 3)), got.end());
}

TEST(HashGrid, RadiusLargerThanBuildRadiiIsExact) {
  const auto pts = random_cloud(7, 20000, vec3(-1.0f), vec3(1.0f));
  HashGrid grid;
  const std::vector<float> build_radii = {0.01f, 0.02f};
  grid.build(pts, build_radii);
  // 3x: up to ~64 cells (dedupe path); 10x: ~1300 cells (per-cell filter path);
  // 100x and beyond: more cells than photons (linear scan path).
  for (float scale : {1.0f, 2.0f, 3.0f, 5.0f, 10.0f, 30.0f, 100.0f, 1000.0f}) {
    std::vector<Query> qs;
    for (size_t i = 0; i < 20; ++i) {
      Rng rng(8, uint64_t(scale), i, Stream::Test);
      qs.push_back({random_in(rng, vec3(-1.2f), vec3(1.2f)), 0.02f * scale});
    }
    check_all(grid, pts, qs);
  }
}

TEST(HashGrid, SmallTablesForceBucketCollisions) {
  // A table has n to 2n buckets, so with few photons two of a query's 8 cells often share a
  // bucket: it must be scanned once and each photon visited once. (n is kept above the cell
  // count so these queries take the bucket-dedupe path, not the linear scan.)
  for (size_t n : {8, 12, 16, 24, 32, 64, 128}) {
    const auto pts = random_cloud(9 + n, n, vec3(0.0f), vec3(0.2f));
    std::vector<Query> qs;
    for (size_t i = 0; i < 500; ++i) {
      Rng rng(20 + n, 0, i, Stream::Test);
      qs.push_back({random_in(rng, vec3(-0.02f), vec3(0.22f)), 0.01f + 0.1f * rng.next_float()});
    }
    HashGrid grid;
    grid.build(pts, radii_of(qs));
    EXPECT_GT(check_all(grid, pts, qs), 0u);
  }
}

TEST(HashGrid, PlanarPhotonsAndLargeOffset) {
  for (const float offset : {0.0f, 1e4f}) {
    // Photon hits on a tilted plane z = 0.3x - 0.2y + offset, as on a real surface.
    std::vector<vec3> pts(20000);
    for (size_t i = 0; i < pts.size(); ++i) {
      Rng rng(30, 0, i, Stream::Test);
      const float x = rng.next_float() * 2.0f - 1.0f, y = rng.next_float() * 2.0f - 1.0f;
      pts[i] = vec3(x + offset, y + offset, 0.3f * x - 0.2f * y + offset);
    }
    std::vector<Query> qs;
    for (size_t i = 0; i < 1000; ++i) {
      Rng rng(31, 0, i, Stream::Test);
      const float x = rng.next_float() * 2.2f - 1.1f, y = rng.next_float() * 2.2f - 1.1f;
      const float dz = (rng.next_float() - 0.5f) * 0.04f;
      qs.push_back({vec3(x + offset, y + offset, 0.3f * x - 0.2f * y + dz + offset),
                    0.005f + 0.03f * rng.next_float()});
    }
    HashGrid grid;
    grid.build(pts, radii_of(qs));
    EXPECT_GT(check_all(grid, pts, qs), 1000u) << "offset " << offset;
  }
}

std::vector<std::pair<uint32_t, float>> visit_sequence(const HashGrid& grid,
                                                       const std::vector<Query>& qs) {
  std::vector<std::pair<uint32_t, float>> seq;
  for (const Query& q : qs)
    grid.query(q.center, q.radius, [&](uint32_t i, float d2) { seq.emplace_back(i, d2); });
  return seq;
}

TEST(HashGrid, DeterministicAcrossRebuilds) {
  const auto a = random_cloud(40, 20000, vec3(0.0f), vec3(1.0f));
  const auto b = random_cloud(41, 30000, vec3(-2.0f), vec3(0.5f));
  std::vector<Query> qs;
  for (size_t i = 0; i < 1000; ++i) {
    Rng rng(42, 0, i, Stream::Test);
    const vec3 c = random_in(rng, vec3(0.0f), vec3(1.0f));
    qs.push_back({c, 0.01f * std::pow(20.0f, rng.next_float())});
  }
  const auto radii = radii_of(qs);
  HashGrid g1, g2;
  g1.build(a, radii);
  const auto first = visit_sequence(g1, qs);
  const size_t warm_bytes = g1.memory_bytes();
  EXPECT_GT(first.size(), 1000u);
  g1.build(a, radii);
  EXPECT_EQ(visit_sequence(g1, qs), first);
  EXPECT_EQ(g1.memory_bytes(), warm_bytes);  // same input again: vectors reused, no growth

  const std::vector<float> other_radii = {0.003f, 0.3f};
  g1.build(b, other_radii);  // different data, sizes and levels in between
  const size_t bigger = g1.memory_bytes();
  EXPECT_NE(visit_sequence(g1, qs), first);
  g1.build(a, radii);
  EXPECT_EQ(visit_sequence(g1, qs), first);
  EXPECT_GT(bigger, 0u);
  const size_t back = g1.memory_bytes();
  g1.build(a, radii);
  EXPECT_EQ(g1.memory_bytes(), back);  // warm again: no allocation
  g2.build(a, radii);
  EXPECT_EQ(visit_sequence(g2, qs), first);

  // One radius after many levels: every level no longer built gives back its photon entries
  // (16 bytes per photon each), so memory drops by at least that much.
  const size_t many_bytes = g1.memory_bytes();
  const int many_levels = g1.level_count();
  ASSERT_GT(many_levels, 2);
  g1.build(a, std::vector<float>{0.05f});
  EXPECT_EQ(g1.level_count(), 1);
  EXPECT_LE(g1.memory_bytes(),
            many_bytes - size_t(many_levels - 1) * a.size() * sizeof(HashGrid::Entry));
}

TEST(HashGrid, InvalidInputThrows) {
  const std::vector<vec3> pts = {vec3(0.0f), vec3(1.0f)};
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  HashGrid grid;
  const std::vector<float> good = {0.1f};
  grid.build(pts, good);
  for (float bad : {0.0f, -0.0f, -1.0f, nan, inf, -inf}) {
    const std::vector<float> radii = {0.1f, bad, 0.2f};
    EXPECT_THROW(grid.build(pts, radii), std::invalid_argument) << bad;
  }
  const std::vector<vec3> bad_pts = {vec3(0.0f), vec3(nan, 0.0f, 0.0f)};
  EXPECT_THROW(grid.build(bad_pts, good), std::invalid_argument);
  // The failed builds left the previous grid intact.
  std::vector<uint32_t> got;
  grid.query(vec3(0.05f), 0.1f, [&](uint32_t i, float) { got.push_back(i); });
  EXPECT_EQ(got, std::vector<uint32_t>{0});
  // Queries with unusable radii or centres visit nothing.
  for (float r : {0.0f, -1.0f, nan, inf})
    grid.query(vec3(0.0f), r, [&](uint32_t, float) { ADD_FAILURE() << "visited with r " << r; });
  grid.query(vec3(nan), 0.1f, [&](uint32_t, float) { ADD_FAILURE() << "visited NaN centre"; });
}

TEST(HashGrid, EmptyPhotonSetOrNoRadii) {
  HashGrid grid;
  const std::vector<float> radii = {0.1f, 1.0f};
  grid.build(std::span<const vec3>(), radii);
  EXPECT_EQ(grid.level_count(), 0);
  EXPECT_EQ(grid.photon_count(), 0u);
  grid.query(vec3(0.0f), 1.0f, [&](uint32_t, float) { ADD_FAILURE() << "visited empty grid"; });

  HashGrid fresh;  // never built
  fresh.query(vec3(0.0f), 1.0f, [&](uint32_t, float) { ADD_FAILURE() << "visited unbuilt grid"; });

  const std::vector<vec3> pts = {vec3(0.0f)};
  grid.build(pts, radii);
  size_t count = 0;
  grid.query(vec3(0.0f), 1.0f, [&](uint32_t, float) { ++count; });
  EXPECT_EQ(count, 1u);
  grid.build(std::span<const vec3>(), radii);  // back to empty after a non-empty build
  grid.query(vec3(0.0f), 1.0f, [&](uint32_t, float) { ADD_FAILURE() << "visited after rebuild"; });

  // No radii (no visible points this pass): no levels, queries visit nothing, no throw.
  grid.build(pts, std::span<const float>());
  EXPECT_EQ(grid.level_count(), 0);
  EXPECT_EQ(grid.photon_count(), 1u);
  grid.query(vec3(0.0f), 1.0f, [&](uint32_t, float) { ADD_FAILURE() << "visited, no radii"; });
  grid.build(pts, radii);  // and back
  count = 0;
  grid.query(vec3(0.0f), 1.0f, [&](uint32_t, float) { ++count; });
  EXPECT_EQ(count, 1u);
}

// The gather's three kernel sums (pass_stages.cpp, kept two doubles at a time) against their
// definitions over the photons found by brute force: w(t) Phi, w_lap(t) R^2 Phi and, within
// R / 2 only, w(2 t) Phi, with t = |x_p - x| / R. A flat Lambertian plane (every photon on the
// point's side, shading = geometric normal, f = 1), photons of random powers; the sums differ
// from the scalar loop's only in the order of addition (the grid's cells), so 1e-12.
TEST(HashGrid, TheGatherSumsAreTheKernelsOverThePhotonsWithinTheRadius) {
  const double r2 = 0.04;  // R = 0.2
  std::vector<PhotonHit> hits;
  for (size_t i = 0; i < 4000; ++i) {
    Rng rng(41, 0, i, Stream::Test);
    PhotonHit h;
    h.position = vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0.0f);
    h.wi = vec3(0.0f, 0.0f, 1.0f);
    h.normal = vec3(0.0f, 0.0f, 1.0f);
    h.flux = vec3(rng.next_float(), 2.0f * rng.next_float(), 0.5f + rng.next_float());
    hits.push_back(h);
  }
  std::vector<vec3> positions;
  HashGrid grid;
  const float radius = search_radius(r2);
  build_photon_grid(hits, std::vector<float>{radius}, positions, grid);
  for (const vec3 at : {vec3(0.0f), vec3(0.13f, -0.07f, 0.0f), vec3(-0.41f, 0.44f, 0.0f)}) {
    VisiblePoint p;
    p.position = at;
    p.normal = p.shading = vec3(0.0f, 0.0f, 1.0f);
    p.f = vec3(1.0f);
    PassSums got;
    gather_photons<true>(p, r2, grid, hits, got);
    dvec3 phi(0.0), lap(0.0), half(0.0);
    double count = 0.0;
    size_t halves = 0;
    for (const PhotonHit& h : hits) {
      const float d2 = HashGrid::distance2(h.position, at);
      if (!(d2 < radius * radius)) continue;
      const double t = std::min(1.0, std::sqrt(double(d2) / r2));
      const dvec3 flux(h.flux);
      phi += kernel::weight(t) * flux;
      lap += kernel::laplacian_weight_r2(t) * flux;
      if (t < 0.5) {
        half += kernel::weight(2.0 * t) * flux;
        ++halves;
      }
      count += 1.0;
    }
    ASSERT_GT(halves, 10u);  // the half-radius sum is tested on photons, not on none
    EXPECT_EQ(got.count, count);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(got.phi[c], phi[c], 1e-12 * std::abs(phi[c])) << c;
      EXPECT_NEAR(got.phi_lap_r2[c], lap[c], 1e-12 * std::abs(phi[c]) * 105.0) << c;
      EXPECT_NEAR(got.phi_half[c], half[c], 1e-12 * std::abs(half[c])) << c;
    }
  }
}

}  // namespace
}  // namespace pb
