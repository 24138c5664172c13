#include "world/boundary.h"

#include "util/counting_sort.h"
#include "util/parallel.h"
#include "world/world.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace pb {

// Closed forms of the radial integrals for the quintic kernel (kernel.h, ESTIMATOR.md section 2):
// kappa(t) = 7/(2 pi) (1 - 10 t^3 + 15 t^4 - 6 t^5), lap kappa(t) = 105/pi (-3 t + 8 t^2 - 5 t^3).
// Each G is integral_0^a g(t) t dt; over the whole disc 2 pi G(1) gives 1, 5/24, 0 and 4.
double kernel_mass_to(double a) {
  const double a2 = a * a, a5 = a2 * a2 * a;
  return 7.0 / (2.0 * kPiD) * (a2 / 2.0 + a5 * (-2.0 + a * (2.5 - a * 6.0 / 7.0)));
}
double kernel_second_to(double a) {
  const double a2 = a * a, a4 = a2 * a2, a7 = a4 * a2 * a;
  return 7.0 / (2.0 * kPiD) * (a4 / 4.0 + a7 * (-10.0 / 7.0 + a * (15.0 / 8.0 - a * 2.0 / 3.0)));
}
double laplacian_mass_to(double a) {
  const double a3 = a * a * a;
  return 105.0 / kPiD * a3 * (-1.0 + a * (2.0 - a));
}
double laplacian_second_to(double a) {
  const double a5 = a * a * a * a * a;
  return 105.0 / kPiD * a5 * (-3.0 / 5.0 + a * (4.0 / 3.0 - a * 5.0 / 7.0));
}

namespace {

constexpr int kK = BoundaryIndex::kDirections;

struct Directions {
  double c[kK], s[kK];
  Directions() {
    for (int k = 0; k < kK; ++k) {
      const double th = (double(k) + 0.5) * 2.0 * kPiD / kK;
      c[k] = std::cos(th);
      s[k] = std::sin(th);
    }
  }
};
const Directions& directions() {
  static const Directions d;
  return d;
}

// Two triangles belong to one surface for the gather when its same-side test accepts photons
// on both: normals less than 90 degrees apart (pass_stages.cpp, gather_photons).
bool compatible(const vec3& n, const vec3& m) { return glm::dot(n, m) > 0.0f; }

double segment_distance2(const vec3& p, const vec3& a, const vec3& b) {
  const dvec3 ab = dvec3(b) - dvec3(a), ap = dvec3(p) - dvec3(a);
  const double len2 = glm::dot(ab, ab);
  const double s = len2 > 0.0 ? std::clamp(glm::dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
  const dvec3 d = ap - s * ab;
  return glm::dot(d, d);
}

vec3 triangle_centre(const vec3 v[3]) { return (v[0] + v[1] + v[2]) / 3.0f; }

float triangle_reach(const vec3 v[3]) {
  const vec3 c = triangle_centre(v);
  return std::sqrt(std::max(
      {glm::dot(v[0] - c, v[0] - c), glm::dot(v[1] - c, v[1] - c), glm::dot(v[2] - c, v[2] - c)}));
}

// Clips segment [a, b] to the ball (c, r); false when they do not meet.
bool clip_to_sphere(vec3& a, vec3& b, const vec3& c, float r) {
  const dvec3 d = dvec3(b) - dvec3(a), f = dvec3(a) - dvec3(c);
  const double qa = glm::dot(d, d), qb = 2.0 * glm::dot(f, d), qc = glm::dot(f, f) - double(r) * r;
  if (!(qa > 0.0)) return qc <= 0.0;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  const double s0 = std::max(0.0, (-qb - sq) / (2.0 * qa)),
               s1 = std::min(1.0, (-qb + sq) / (2.0 * qa));
  if (s0 > s1) return false;
  const dvec3 a0(a);
  a = vec3(a0 + s0 * d);
  b = vec3(a0 + s1 * d);
  return true;
}

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

// Whether point q lies on a triangle of `world` facing like n, within `tol` of its plane.
bool covered(const World& world, const vec3& q, const vec3& n, float tol, uint32_t self) {
  bool found = false;
  world.accel().query_sphere(q, tol, [&](uint32_t mesh, uint32_t prim) {
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

}  // namespace

BoundaryIndex::BoundaryIndex(const World& world, float max_radius) {
  const uint32_t n = world.triangle_count();
  // 1. Edges: sorted by their corners, so that the triangles sharing one are neighbours.
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
  std::sort(edges.begin(), edges.end(), [](const EdgeRecord& x, const EdgeRecord& y) {
    if (key_less(x, y)) return true;
    if (key_less(y, x)) return false;
    return x.triangle < y.triangle || (x.triangle == y.triangle && x.edge < y.edge);
  });

  // 2. Boundary edges: no neighbour on the edge whose photons the gather would accept. An edge
  // nobody shares may still continue into a coplanar triangle that does not share its corners
  // (a T-junction, or two meshes side by side): probed just outside the edge.
  struct Pending {
    uint32_t triangle;
    Segment s;
  };
  std::vector<Pending> found;
  // Points (and so discs) exist only on surfaces that are not mirrors or glass.
  std::vector<uint8_t> host(n);
  for (uint32_t t = 0; t < n; ++t) host[t] = world.may_hold_points(world.material_of(t));
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && !key_less(edges[i], edges[j])) ++j;
    for (size_t k = i; k < j; ++k) {
      const uint32_t t = edges[k].triangle;
      if (!host[t]) continue;
      const vec3& nt = world.face_normal(t);
      bool shared = false;
      for (size_t q = i; q < j && !shared; ++q)
        shared = edges[q].triangle != t && compatible(nt, world.face_normal(edges[q].triangle));
      vec3 v[3];
      world.triangle(t, v[0], v[1], v[2]);
      const vec3 a = v[edges[k].edge], b = v[(edges[k].edge + 1) % 3];
      if (!shared && j - i == 1) {
        // Outward in the triangle's plane, a thousandth of the edge's length away.
        const vec3 c = v[(edges[k].edge + 2) % 3];
        const vec3 along = b - a;
        vec3 out = glm::cross(along, nt);
        if (glm::dot(out, c - a) > 0.0f) out = -out;
        const float len = glm::length(along);
        const float tol = 1e-3f * len + 1e-6f * max_component(glm::abs(a));
        if (len > 0.0f) {
          out *= tol / glm::length(out);
          shared = covered(world, a + 0.25f * along + out, nt, 2.0f * tol, t) &&
                   covered(world, a + 0.5f * along + out, nt, 2.0f * tol, t) &&
                   covered(world, a + 0.75f * along + out, nt, 2.0f * tol, t);
        }
      }
      if (!shared) found.push_back({t, {a, b}});
    }
    i = j;
  }
  std::vector<EdgeRecord>().swap(edges);
  if (std::getenv("PB_BOUNDARY_DEBUG"))
    std::fprintf(stderr, "boundary: %zu edge segments\n", found.size());

  // 3. Blockers: a triangle u rising through the plane of a triangle t it shares no corner
  // with (a block standing on a floor) ends t's reachable surface where it crosses, just above
  // the plane (at half the crossing tolerance: a face resting on the plane counts).
  // Every segment is listed at least for its own triangle (step 4), so more segments than the
  // pair budget there means the index is given up: counted here, that is known before a
  // tightly packed assembly (a CAD engine of interpenetrating parts: 4.8M cuts at a preview's
  // radius, 0.9 GB) has listed them all.
  const size_t budget = kPairBudget + 16 * size_t(n);
  std::atomic<size_t> cuts{found.size()};
  std::vector<std::vector<Pending>> blockers(n);
  parallel_for(n, 256, [&](size_t b, size_t e) {
    for (size_t uu = b; uu < e; ++uu) {
      if (cuts.load(std::memory_order_relaxed) > budget) return;
      const uint32_t u = uint32_t(uu);
      vec3 w[3];
      world.triangle(u, w[0], w[1], w[2]);
      const vec3 centre = triangle_centre(w);
      const float reach = triangle_reach(w), size = reach;
      const uint32_t mesh_of_u = world.mesh_of(u);
      world.accel().query_sphere(centre, reach, [&](uint32_t mesh, uint32_t prim) {
        const uint32_t t = world.triangle_index(mesh, prim);
        if (t == u || !host[t]) return;
        // Only other objects block: a surface folding through its own tangent planes (the
        // bumps of one displaced mesh) is the surface the kernel integrates over, whatever its
        // shape, and a surface bending up through the plane is one whose photons the gather
        // accepts.
        if (mesh_of_u == world.mesh_of(t) || compatible(world.face_normal(t), world.face_normal(u)))
          return;
        vec3 v[3];
        world.triangle(t, v[0], v[1], v[2]);
        for (const vec3& x : v)
          for (const vec3& y : w)
            if (x == y) return;  // neighbours: their shared edge or corner is a crease
        const vec3& nt = world.face_normal(t);
        const float level =
            0.5f * (1e-3f * size + 1e-6f * max_component(glm::abs(centre)));  // half the tolerance
        float d[3];
        for (int k = 0; k < 3; ++k) d[k] = glm::dot(w[k] - v[0], nt) - level;
        if (!(std::min({d[0], d[1], d[2]}) < 0.0f && std::max({d[0], d[1], d[2]}) > 0.0f)) return;
        // The two points where u's edges cross the level.
        vec3 cut[2];
        int m = 0;
        for (int k = 0; k < 3 && m < 2; ++k) {
          const float d0 = d[k], d1 = d[(k + 1) % 3];
          if ((d0 < 0.0f) == (d1 < 0.0f)) continue;
          const float s = d0 / (d0 - d1);
          cut[m++] = w[k] + s * (w[(k + 1) % 3] - w[k]);
        }
        // Only the part within reach of t's points matters (max_radius past t's bounding
        // sphere): clipped there, so that a wall crossing a small triangle's plane far away
        // adds nothing.
        if (m == 2 &&
            clip_to_sphere(cut[0], cut[1], triangle_centre(v), triangle_reach(v) + max_radius))
          blockers[uu].push_back({t, {cut[0], cut[1]}});
      });
      cuts.fetch_add(blockers[uu].size(), std::memory_order_relaxed);
    }
  });
  if (cuts.load() > budget) {
    truncated_ = true;
    found.clear();
    blockers.clear();
  } else {
    found.reserve(cuts.load());  // exactly: no doubling of millions of cuts
  }
  for (std::vector<Pending>& list : blockers) {
    found.insert(found.end(), list.begin(), list.end());
    std::vector<Pending>().swap(list);
  }

  if (std::getenv("PB_BOUNDARY_DEBUG"))
    std::fprintf(stderr, "boundary: %zu segments with blockers\n", found.size());
  // 4. Each segment is listed for every triangle of its host's surface within max_radius.
  // A radius far above the triangles' size over a mesh with many boundary segments (an unposed
  // skinned character at a preview resolution) would list thousands of segments per triangle
  // and take gigabytes: past kPairBudget pairs plus 16 per triangle the index is given up, every
  // disc counts as whole, and the renderer warns (truncated()).
  segments_.resize(found.size());
  // The pairs of each run of kChunk segments (sorted below, so the runs' order does not matter):
  // one vector per run, not per segment, whose headers alone took 0.3 GB for 4.8M segments.
  constexpr size_t kChunk = 64;
  const size_t chunks = (found.size() + kChunk - 1) / kChunk;
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> near(chunks);
  std::atomic<size_t> listed{0};
  parallel_for(chunks, 1, [&](size_t cb, size_t ce) {
    for (size_t i = cb * kChunk; i < std::min(ce * kChunk, found.size()); ++i) {
      if (listed.load(std::memory_order_relaxed) > budget) return;
      std::vector<std::pair<uint32_t, uint32_t>>& out = near[i / kChunk];
      const size_t before = out.size();
      const Pending& f = found[i];
      Segment& s = segments_[i];
      s = f.s;
      s.mid = 0.5f * (s.a + s.b);
      s.half = 0.5f * glm::length(s.b - s.a);
      const vec3& nh = world.face_normal(f.triangle);
      world.accel().query_sphere(s.mid, s.half + max_radius, [&](uint32_t mesh, uint32_t prim) {
        const uint32_t t = world.triangle_index(mesh, prim);
        if (!host[t] || !compatible(world.face_normal(t), nh)) return;
        vec3 v[3];
        world.triangle(t, v[0], v[1], v[2]);
        const double reach = double(triangle_reach(v)) + max_radius;
        if (segment_distance2(triangle_centre(v), f.s.a, f.s.b) < reach * reach)
          out.emplace_back(t, uint32_t(i));
      });
      listed.fetch_add(out.size() - before, std::memory_order_relaxed);
    }
  });
  truncated_ = truncated_ || listed.load() > budget;
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (auto& v : near) {
    if (!truncated_) pairs.insert(pairs.end(), v.begin(), v.end());
    std::vector<std::pair<uint32_t, uint32_t>>().swap(v);
  }
  if (truncated_) {
    segments_.clear();
    segments_.shrink_to_fit();
  }
  if (std::getenv("PB_BOUNDARY_DEBUG")) std::fprintf(stderr, "boundary: %zu pairs\n", pairs.size());
  // Sorted by (triangle, segment): the runs were concatenated in segment order, so a stable
  // counting sort by triangle gives std::sort's order in O(pairs + triangles) (at a 4x4 preview,
  // whose radius spans the scene, scenes/unlit.gltf lists 10.7M pairs: 1 s of std::sort).
  {
    std::vector<uint32_t> at(size_t(n) + 1, 0u);
    for (const auto& pr : pairs) ++at[size_t(pr.first) + 1];
    for (uint32_t t = 0; t < n; ++t) at[t + 1] += at[t];
    std::vector<std::pair<uint32_t, uint32_t>> sorted(pairs.size());
    for (const auto& pr : pairs) sorted[at[pr.first]++] = pr;
    pairs.swap(sorted);
  }
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  start_.assign(size_t(n) + 1, 0);
  for (const auto& [t, s] : pairs) ++start_[t + 1];
  for (uint32_t t = 0; t < n; ++t) start_[t + 1] += start_[t];
  list_.resize(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) list_[k] = pairs[k].second;
  for (int level = 0; level < 2; ++level) {
    const uint32_t span = level == 0 ? kGroup : kGroup * kGroup;  // list entries per run
    std::vector<uint32_t>& gs = group_start_[level];
    gs.assign(size_t(n) + 1, 0);
    for (uint32_t t = 0; t < n; ++t)
      gs[t + 1] = gs[t] + (start_[t + 1] - start_[t] + span - 1) / span;
    groups_[level].resize(gs[n]);
    parallel_for(n, 4096, [&](size_t b, size_t e) {
      for (size_t t = b; t < e; ++t) {
        for (uint32_t g = gs[t]; g < gs[t + 1]; ++g) {
          const uint32_t first = start_[t] + (g - gs[t]) * span;
          const uint32_t last = std::min(first + span, start_[t + 1]);
          Bounds box;
          for (uint32_t k = first; k < last; ++k) {
            box.extend(segments_[list_[k]].a);
            box.extend(segments_[list_[k]].b);
          }
          const vec3 c = 0.5f * (box.lo + box.hi);
          float radius = 0.0f;
          for (uint32_t k = first; k < last; ++k) {
            const Segment& sg = segments_[list_[k]];
            radius = std::max(radius, glm::length(sg.mid - c) + sg.half);
          }
          groups_[level][g] = {c, radius};
        }
      }
    });
  }
  // Centres of the triangles with segments, to tell which side of a segment through a point is
  // its surface (moments()).
  centre_.assign(n, vec3(0.0f));
  parallel_for(n, 4096, [&](size_t b, size_t e) {
    for (size_t t = b; t < e; ++t) {
      if (start_[t + 1] == start_[t]) continue;
      vec3 v[3];
      world.triangle(uint32_t(t), v[0], v[1], v[2]);
      centre_[t] = triangle_centre(v);
    }
  });
}

size_t BoundaryIndex::memory_bytes() const {
  return segments_.capacity() * sizeof(Segment) + start_.capacity() * sizeof(uint32_t) +
         (group_start_[0].capacity() + group_start_[1].capacity()) * sizeof(uint32_t) +
         (groups_[0].capacity() + groups_[1].capacity()) * sizeof(Group) +
         list_.capacity() * sizeof(uint32_t) + centre_.capacity() * sizeof(vec3);
}

template <class Skip, class Visit>
void BoundaryIndex::scan(uint32_t triangle, Skip&& skip, Visit&& visit) const {
  const uint32_t begin = start_[triangle], end = start_[triangle + 1];
  for (uint32_t k = begin; k < end; ++k) {
    const uint32_t at = k - begin;
    if (at % (kGroup * kGroup) == 0 &&
        skip(groups_[1][group_start_[1][triangle] + at / (kGroup * kGroup)])) {
      k += kGroup * kGroup - 1;  // the run's last entry; the loop's ++k starts the next run
      continue;
    }
    if (at % kGroup == 0 && skip(groups_[0][group_start_[0][triangle] + at / kGroup])) {
      k += kGroup - 1;
      continue;
    }
    if (!visit(segments_[list_[k]])) return;
  }
}

float BoundaryIndex::clearance(uint32_t triangle, const vec3& p, float r) const {
  if (start_.empty()) return r;
  double nearest = double(r) * double(r);
  // A run whose bounding sphere is farther than the nearest segment so far holds none nearer
  // (with a 1e-4 relative margin for float rounding).
  scan(
      triangle,
      [&](const Group& g) {
        const float d = glm::length(p - g.centre) - g.radius;
        return d > 0.0f && double(d) * double(d) > nearest * 1.0002;
      },
      [&](const Segment& s) {
        nearest = std::min(nearest, segment_distance2(p, s.a, s.b));
        return true;
      });
  if (nearest >= double(r) * double(r)) return r;
  // Rounded down, so that a radius at or below it squares to less than every segment's
  // distance squared, as moments() tests.
  return std::nextafter(float(std::sqrt(nearest)), 0.0f) * (1.0f - 1e-6f);
}

DiscMoments BoundaryIndex::moments(uint32_t triangle, const vec3& p, const vec3& n, float r) const {
  DiscMoments m;
  if (start_.empty()) return m;
  // The segments within r of p, projected into p's tangent plane.
  constexpr int kMaxNear = 64;
  double ax[kMaxNear], ay[kMaxNear], ex[kMaxNear], ey[kMaxNear];
  int count = 0;
  const double r2 = double(r) * double(r);
  vec3 t1, t2;
  orthonormal_basis(n, t1, t2);
  // Beyond radius + r from a bounding sphere's centre nothing inside it is within r (a 1e-4
  // relative margin covers float rounding; the exact distance decides the rest).
  const auto far = [&](const vec3& c, float radius) {
    const vec3 d = p - c;
    const float reach = (radius + r) * 1.0001f;
    return glm::dot(d, d) > reach * reach;
  };
  scan(
      triangle, [&](const Group& g) { return far(g.centre, g.radius); },
      [&](const Segment& s) {
        if (far(s.mid, s.half) || segment_distance2(p, s.a, s.b) >= r2) return true;
        const dvec3 a = dvec3(s.a) - dvec3(p), b = dvec3(s.b) - dvec3(p);
        ax[count] = glm::dot(a, dvec3(t1));
        ay[count] = glm::dot(a, dvec3(t2));
        ex[count] = glm::dot(b, dvec3(t1)) - ax[count];
        ey[count] = glm::dot(b, dvec3(t2)) - ay[count];
        return ++count < kMaxNear;
      });
  if (count == 0) return m;
  // A point on a segment (a pixel centre that sees exactly the line where two walls meet) sees
  // nothing along it: every ray meets the segment at t = 0. Such a point belongs to the side of
  // its own triangle, so the quadrature's centre moves 1e-3 r towards that triangle's centre;
  // the moments change by O(1e-3) (the disc's part beyond the segment is then about half).
  double min_d2 = INFINITY;
  for (int i = 0; i < count; ++i) {
    const double len2 = ex[i] * ex[i] + ey[i] * ey[i];
    const double s =
        len2 > 0.0 ? std::clamp(-(ax[i] * ex[i] + ay[i] * ey[i]) / len2, 0.0, 1.0) : 0.0;
    const double qx = ax[i] + s * ex[i], qy = ay[i] + s * ey[i];
    min_d2 = std::min(min_d2, qx * qx + qy * qy);
  }
  if (min_d2 < 1e-8 * r2) {
    const dvec3 toward = dvec3(centre_[triangle]) - dvec3(p);
    const double cx = glm::dot(toward, dvec3(t1)), cy = glm::dot(toward, dvec3(t2));
    const double len = std::sqrt(cx * cx + cy * cy);
    if (len > 0.0) {
      const double shift = std::min(1e-3 * double(r), len);
      for (int i = 0; i < count; ++i) {
        ax[i] -= shift * cx / len;
        ay[i] -= shift * cy / len;
      }
    }
  }
  // Polar quadrature about p: in each direction the visible extent rho (the first segment the
  // ray meets, or r), and the radial integrals to rho / r (midpoint rule in the angle). A segment
  // not through p subtends less than pi, so only the directions within the arc between its end
  // points' angles (one more each side, for rounding) can meet it; the exact test decides.
  const Directions& dir = directions();
  double rho[kK];
  std::fill(rho, rho + kK, double(r));
  constexpr double step = 2.0 * kPiD / kK;
  for (int i = 0; i < count; ++i) {
    const double ta = std::atan2(ay[i], ax[i]), tb = std::atan2(ay[i] + ey[i], ax[i] + ex[i]);
    double width = tb - ta;
    if (width > kPiD) width -= 2.0 * kPiD;
    if (width < -kPiD) width += 2.0 * kPiD;
    const double from = width >= 0.0 ? ta : tb;
    // Direction k sits at (k + 0.5) step.
    const int k0 = int(std::floor(from / step - 0.5)) - 1;
    const int k1 = int(std::ceil((from + std::fabs(width)) / step - 0.5)) + 1;
    for (int kk = k0; kk <= k1 && kk < k0 + kK; ++kk) {
      const int k = ((kk % kK) + kK) % kK;
      const double dx = dir.c[k], dy = dir.s[k];
      // p + t d = a + s e: t = cross(a, e) / cross(d, e), s = cross(a, d) / cross(d, e).
      const double den = dx * ey[i] - dy * ex[i];
      if (std::fabs(den) < 1e-300) continue;
      const double t = (ax[i] * ey[i] - ay[i] * ex[i]) / den;
      const double s = (ax[i] * dy - ay[i] * dx) / den;
      if (t >= 0.0 && s >= 0.0 && s <= 1.0) rho[k] = std::min(rho[k], t);
    }
  }
  static const double full[4] = {kernel_mass_to(1.0), kernel_second_to(1.0), laplacian_mass_to(1.0),
                                 laplacian_second_to(1.0)};
  double mass = 0.0, second = 0.0, lap = 0.0, lap2 = 0.0;
  for (int k = 0; k < kK; ++k) {
    if (rho[k] >= double(r)) {
      mass += full[0];
      second += full[1];
      lap += full[2];
      lap2 += full[3];
      continue;
    }
    const double a = rho[k] / double(r);
    mass += kernel_mass_to(a);
    second += kernel_second_to(a);
    lap += laplacian_mass_to(a);
    lap2 += laplacian_second_to(a);
  }
  const double w = 2.0 * kPiD / kK;
  m.mass = mass * w;
  m.second = second * w;
  m.lap_mass = lap * w;
  m.lap_second = lap2 * w;
  m.full = false;
  return m;
}

}  // namespace pb
