#include "world/boundary.h"

#include "util/counting_sort.h"
#include "util/morton.h"
#include "util/parallel.h"
#include "world/boundary_geometry.h"
#include "world/world.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace pb {

namespace {

using boundary_geometry::clip_to_sphere;
using boundary_geometry::segment_distance2;
using boundary_geometry::triangle_centre;
using boundary_geometry::triangle_reach;

// Two triangles belong to one surface for the gather when its same-side test accepts photons
// on both: normals less than 90 degrees apart (pass_stages.cpp, gather_photons).
bool compatible(const vec3& n, const vec3& m) { return glm::dot(n, m) > 0.0f; }

// An edge by its two corners, in a canonical order, as bit patterns (exact matching: shared
// vertices of one mesh, and of meshes an exporter wrote from the same vertices).
struct EdgeRecord {
  uint32_t key[6];
  uint32_t triangle;
  uint8_t edge;
};

bool key_less(const EdgeRecord& x, const EdgeRecord& y) {
  return std::memcmp(x.key, y.key, sizeof x.key) < 0;
}

void edge_key(const vec3& a, const vec3& b, uint32_t key[6]) {
  uint32_t ka[3], kb[3];
  std::memcpy(ka, &a, 12);
  std::memcpy(kb, &b, 12);
  const bool swap = std::memcmp(ka, kb, 12) > 0;
  std::memcpy(key, swap ? kb : ka, 12);
  std::memcpy(key + 3, swap ? ka : kb, 12);
}

// Whether point q lies on a triangle of `world` facing like n, within `tol` of its plane; adds
// the candidates examined to `work`.
bool covered(const World& world, const vec3& q, const vec3& n, float tol, uint32_t self,
             size_t& work) {
  bool found = false;
  world.accel().query_sphere(q, tol, [&](uint32_t mesh, uint32_t prim) {
    ++work;
    const uint32_t t = world.triangle_index(mesh, prim);
    if (found || t == self) return;
    const vec3& m = world.face_normal(t);
    if (glm::dot(m, n) < 0.99f) return;
    vec3 a, b, c;
    world.triangle(t, a, b, c);
    if (std::fabs(glm::dot(q - a, m)) > tol) return;
    // Barycentric inside test in the triangle's plane.
    const vec3 e1 = b - a, e2 = c - a, w = q - a;
    const float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
    const float w1 = glm::dot(w, e1), w2 = glm::dot(w, e2), den = d11 * d22 - d12 * d12;
    if (!(den > 0.0f)) return;
    const float u = (d22 * w1 - d12 * w2) / den, v = (d11 * w2 - d12 * w1) / den;
    found = u >= -1e-4f && v >= -1e-4f && u + v <= 1.0f + 1e-4f;
  });
  return found;
}

// Sorted by their corners, so that the triangles sharing an edge are neighbours (ESTIMATOR.md
// section 11, "Geometry"). A later copy of a triangle (first_copy) has no edges of its own: it
// would share every edge of the first and hide its borders.
std::vector<EdgeRecord> sorted_edges(const World& world, const std::vector<uint32_t>& first_copy) {
  const uint32_t n = world.triangle_count();
  std::vector<EdgeRecord> edges(size_t(n) * 3);
  parallel_for(n, 4096, [&](size_t b, size_t e) {
    for (size_t t = b; t < e; ++t) {
      vec3 v[3];
      world.triangle(uint32_t(t), v[0], v[1], v[2]);
      for (int k = 0; k < 3; ++k) {
        EdgeRecord& r = edges[3 * t + size_t(k)];
        edge_key(v[k], v[(k + 1) % 3], r.key);
        r.triangle = uint32_t(t);
        r.edge = uint8_t(k);
      }
    }
  });
  if (!first_copy.empty())
    edges.erase(
        std::remove_if(edges.begin(), edges.end(),
                       [&](const EdgeRecord& r) { return first_copy[r.triangle] != r.triangle; }),
        edges.end());
  std::sort(edges.begin(), edges.end(), [](const EdgeRecord& x, const EdgeRecord& y) {
    if (key_less(x, y)) return true;
    if (key_less(y, x)) return false;
    return x.triangle < y.triangle || (x.triangle == y.triangle && x.edge < y.edge);
  });
  return edges;
}

// Whether a coplanar triangle that does not share its corners continues triangle t across its
// unshared edge (a, b), c being t's third corner (ESTIMATOR.md section 11, "Geometry"): probed
// outward in t's plane, a thousandth of the edge's length away.
bool continued_beyond(const World& world, uint32_t t, const vec3& a, const vec3& b, const vec3& c,
                      size_t& work) {
  const vec3& nt = world.face_normal(t);
  const vec3 along = b - a;
  vec3 out = glm::cross(along, nt);
  if (glm::dot(out, c - a) > 0.0f) out = -out;
  const float len = glm::length(along);
  const float tol = 1e-3f * len + 1e-6f * max_component(glm::abs(a));
  if (!(len > 0.0f)) return false;
  out *= tol / glm::length(out);
  return covered(world, a + 0.25f * along + out, nt, 2.0f * tol, t, work) &&
         covered(world, a + 0.5f * along + out, nt, 2.0f * tol, t, work) &&
         covered(world, a + 0.75f * along + out, nt, 2.0f * tol, t, work);
}

// Where triangle w (centre and size: its bounding sphere) crosses the plane of host triangle t
// just above it (ESTIMATOR.md section 11, "Geometry"), at half the crossing tolerance, so that a
// face resting on the plane counts; false where it does not cross, or the two share a corner.
bool crossing(const World& world, const vec3 w[3], const vec3& centre, float size, uint32_t t,
              float max_radius, vec3& from, vec3& to) {
  vec3 v[3];
  world.triangle(t, v[0], v[1], v[2]);
  for (const vec3& x : v)
    for (int k = 0; k < 3; ++k)
      if (x == w[k]) return false;  // neighbours: their shared edge or corner is a crease
  const vec3& nt = world.face_normal(t);
  const float level =
      0.5f * (1e-3f * size + 1e-6f * max_component(glm::abs(centre)));  // half the tolerance
  float d[3];
  for (int k = 0; k < 3; ++k) d[k] = glm::dot(w[k] - v[0], nt) - level;
  if (!(std::min({d[0], d[1], d[2]}) < 0.0f && std::max({d[0], d[1], d[2]}) > 0.0f)) return false;
  // The two points where w's edges cross the level.
  vec3 cut[2];
  int m = 0;
  for (int k = 0; k < 3 && m < 2; ++k) {
    const float d0 = d[k], d1 = d[(k + 1) % 3];
    if ((d0 < 0.0f) == (d1 < 0.0f)) continue;
    const float s = d0 / (d0 - d1);
    cut[m++] = w[k] + s * (w[(k + 1) % 3] - w[k]);
  }
  // Only the part within reach of t's points matters (max_radius past t's bounding sphere):
  // clipped there, so that a wall crossing a small triangle's plane far away adds nothing.
  if (m != 2 || !clip_to_sphere(cut[0], cut[1], triangle_centre(v), triangle_reach(v) + max_radius))
    return false;
  from = cut[0];
  to = cut[1];
  return true;
}

bool debug_boundary() { return std::getenv("PB_BOUNDARY_DEBUG") != nullptr; }

}  // namespace

struct BoundaryIndex::Cut {
  uint32_t triangle;  // the host triangle whose surface ends there
  Segment s;
};

// Every phase counts the candidates its queries return (and the edges it compares) and stops
// once the total passes the budget; the index is then given up. Triangles piled at one place
// that are not exact copies (find_copies) would otherwise make each query return all of them.
struct BoundaryIndex::Work {
  std::atomic<size_t> done{0};
  size_t budget = 0;
  bool over() const { return done.load(std::memory_order_relaxed) > budget; }
  void add(size_t k) { done.fetch_add(k, std::memory_order_relaxed); }
};

// ESTIMATOR.md section 11, "Geometry": the four phases below, then the lists' runs and centres.
BoundaryIndex::BoundaryIndex(const World& world, float max_radius, size_t work_budget) {
  const uint32_t n = world.triangle_count();
  Work work;
  work.budget = work_budget + 256 * size_t(n);
  // Points (and so discs) exist only on surfaces that are not mirrors or glass.
  const std::vector<uint8_t> host = find_copies(world);
  std::vector<Cut> cuts = boundary_edges(world, host, first_copy_, work);
  // Every segment is listed at least for its own triangle (list_near), so more segments than the
  // pair budget there means the index is given up: counted by add_blockers, that is known before
  // a tightly packed assembly (a CAD engine of interpenetrating parts: 4.8M cuts at a preview's
  // radius, 0.9 GB) has listed them all.
  const size_t budget = kPairBudget + 16 * size_t(n);
  truncated_ = add_blockers(world, host, first_copy_, max_radius, budget, work, cuts);
  in_space_order(cuts);
  std::vector<std::pair<uint32_t, uint32_t>> pairs =
      list_near(world, cuts, host, max_radius, budget, work);
  work_ = work.done.load();
  if (debug_boundary())
    std::fprintf(stderr, "boundary: %zu candidates examined, %zu copies\n", work_, coincident_);
  index_pairs(pairs, n);
  bound_runs(n);
  find_centres(world);
}

// Phases 1 and 2 (ESTIMATOR.md section 11, "Geometry"): edges with no neighbour on them whose
// photons the gather would accept. An edge nobody shares may still continue into a coplanar
// triangle that does not share its corners (a T-junction, or two meshes side by side).
std::vector<BoundaryIndex::Cut> BoundaryIndex::boundary_edges(
    const World& world, const std::vector<uint8_t>& host, const std::vector<uint32_t>& first_copy,
    Work& work) {
  const std::vector<EdgeRecord> edges = sorted_edges(world, first_copy);
  std::vector<Cut> found;
  size_t examined = 0;
  for (size_t i = 0; i < edges.size() && !work.over();) {
    size_t j = i + 1;
    while (j < edges.size() && !key_less(edges[i], edges[j])) ++j;
    for (size_t k = i; k < j && !work.over(); ++k) {
      const uint32_t t = edges[k].triangle;
      if (!host[t]) continue;
      const vec3& nt = world.face_normal(t);
      bool shared = false;
      for (size_t q = i; q < j && !shared; ++q, ++examined)
        shared = edges[q].triangle != t && compatible(nt, world.face_normal(edges[q].triangle));
      vec3 v[3];
      world.triangle(t, v[0], v[1], v[2]);
      const int e = edges[k].edge;
      const vec3 a = v[e], b = v[(e + 1) % 3];
      if (!shared && j - i == 1)
        shared = continued_beyond(world, t, a, b, v[(e + 2) % 3], examined);
      if (!shared) found.push_back({t, {a, b}});
      work.add(examined);
      examined = 0;
    }
    i = j;
  }
  if (debug_boundary()) std::fprintf(stderr, "boundary: %zu edge segments\n", found.size());
  return found;
}

// Phase 3 (ESTIMATOR.md section 11, "Geometry"): blockers, added to `found`. A triangle u rising
// through the plane of a triangle t it shares no corner with (a block standing on a floor) ends
// t's reachable surface where it crosses. True when the cuts pass `budget` (the index is given
// up, and `found` emptied).
bool BoundaryIndex::add_blockers(const World& world, const std::vector<uint8_t>& host,
                                 const std::vector<uint32_t>& first_copy, float max_radius,
                                 size_t budget, Work& work, std::vector<Cut>& found) {
  const uint32_t n = world.triangle_count();
  std::atomic<size_t> cuts{found.size()};
  std::vector<std::vector<Cut>> blockers(n);
  parallel_for(n, 256, [&](size_t b, size_t e) {
    for (size_t uu = b; uu < e; ++uu) {
      if (cuts.load(std::memory_order_relaxed) > budget || work.over()) return;
      const uint32_t u = uint32_t(uu);
      if (!first_copy.empty() && first_copy[u] != u) continue;  // its first copy's cuts are its
      size_t examined = 0;
      vec3 w[3];
      world.triangle(u, w[0], w[1], w[2]);
      const vec3 centre = triangle_centre(w);
      const float reach = triangle_reach(w);
      const uint32_t mesh_of_u = world.mesh_of(u);
      world.accel().query_sphere(centre, reach, [&](uint32_t mesh, uint32_t prim) {
        ++examined;
        const uint32_t t = world.triangle_index(mesh, prim);
        if (t == u || !host[t]) return;
        // Only other objects block: a surface folding through its own tangent planes (the
        // bumps of one displaced mesh) is the surface the kernel integrates over, whatever its
        // shape, and a surface bending up through the plane is one whose photons the gather
        // accepts.
        if (mesh_of_u == world.mesh_of(t) || compatible(world.face_normal(t), world.face_normal(u)))
          return;
        Segment s;
        if (crossing(world, w, centre, reach, t, max_radius, s.a, s.b))
          blockers[uu].push_back({t, s});
      });
      cuts.fetch_add(blockers[uu].size(), std::memory_order_relaxed);
      work.add(examined);
    }
  });
  const bool truncated = cuts.load() > budget || work.over();
  if (truncated) {
    found.clear();
    blockers.clear();
  } else {
    found.reserve(cuts.load());  // exactly: no doubling of millions of cuts
  }
  for (std::vector<Cut>& list : blockers) {
    found.insert(found.end(), list.begin(), list.end());
    std::vector<Cut>().swap(list);
  }
  if (debug_boundary())
    std::fprintf(stderr, "boundary: %zu segments with blockers\n", found.size());
  return truncated;
}

// The segments in Morton order of their midpoints (util/morton.h): each triangle's list (in
// segment order, index_pairs) then runs through space, so that the runs of kGroup and kGroup^2
// entries are compact and a point skips all but the runs near it. Found in mesh order, a
// ground's list of every fence picket and baluster standing on it had runs strewn across the
// scene (ESTIMATOR.md section 11: 9% of a pass on a house of separate boards).
void BoundaryIndex::in_space_order(std::vector<Cut>& cuts) {
  if (cuts.size() < 2) return;
  Bounds box;
  for (const Cut& c : cuts) box.extend(0.5f * (c.s.a + c.s.b));
  const vec3 scale = morton_scale(box.lo, box.hi);
  std::vector<uint64_t> keys(cuts.size());  // code << 32 | found order: ties keep that order
  parallel_for(cuts.size(), 16384, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i)
      keys[i] = uint64_t(morton_code(0.5f * (cuts[i].s.a + cuts[i].s.b), box.lo, scale)) << 32 | i;
  });
  std::sort(keys.begin(), keys.end());
  std::vector<Cut> sorted(cuts.size());
  for (size_t i = 0; i < keys.size(); ++i) sorted[i] = cuts[keys[i] & 0xffffffffu];
  cuts.swap(sorted);
}

// Phase 4 (ESTIMATOR.md section 11, "Geometry"): each segment is listed for every triangle of its
// host's surface within max_radius, as (triangle, segment) pairs. A radius far above the
// triangles' size over a mesh with many boundary segments (an unposed skinned character at a
// preview resolution) would list thousands of segments per triangle and take gigabytes: past
// `budget` pairs the index is given up, every disc counts as whole, and the renderer warns
// (truncated()).
std::vector<std::pair<uint32_t, uint32_t>> BoundaryIndex::list_near(
    const World& world, const std::vector<Cut>& found, const std::vector<uint8_t>& host,
    float max_radius, size_t budget, Work& work) {
  segments_.resize(found.size());
  // The pairs of each run of kChunk segments (sorted below, so the runs' order does not matter):
  // one vector per run, not per segment, whose headers alone took 0.3 GB for 4.8M segments.
  constexpr size_t kChunk = 64;
  const size_t chunks = (found.size() + kChunk - 1) / kChunk;
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> near(chunks);
  std::atomic<size_t> listed{0};
  parallel_for(chunks, 1, [&](size_t cb, size_t ce) {
    for (size_t i = cb * kChunk; i < std::min(ce * kChunk, found.size()); ++i) {
      if (listed.load(std::memory_order_relaxed) > budget || work.over()) return;
      std::vector<std::pair<uint32_t, uint32_t>>& out = near[i / kChunk];
      const size_t before = out.size();
      const Cut& f = found[i];
      Segment& s = segments_[i];
      s = f.s;
      s.mid = 0.5f * (s.a + s.b);
      s.half = 0.5f * glm::length(s.b - s.a);
      const vec3& nh = world.face_normal(f.triangle);
      size_t examined = 0;
      world.accel().query_sphere(s.mid, s.half + max_radius, [&](uint32_t mesh, uint32_t prim) {
        ++examined;
        const uint32_t t = world.triangle_index(mesh, prim);
        if (!host[t] || !compatible(world.face_normal(t), nh)) return;
        vec3 v[3];
        world.triangle(t, v[0], v[1], v[2]);
        const double reach = double(triangle_reach(v)) + max_radius;
        if (segment_distance2(triangle_centre(v), f.s.a, f.s.b) < reach * reach)
          out.emplace_back(t, uint32_t(i));
      });
      listed.fetch_add(out.size() - before, std::memory_order_relaxed);
      work.add(examined);
    }
  });
  truncated_ = truncated_ || listed.load() > budget || work.over();
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (auto& v : near) {
    if (!truncated_) pairs.insert(pairs.end(), v.begin(), v.end());
    std::vector<std::pair<uint32_t, uint32_t>>().swap(v);
  }
  if (truncated_) {
    segments_.clear();
    segments_.shrink_to_fit();
  }
  if (debug_boundary()) std::fprintf(stderr, "boundary: %zu pairs\n", pairs.size());
  return pairs;
}

}  // namespace pb
