// Multi-level spatial hash over photon positions, for fixed-radius gathers whose radii differ
// per visible point and shrink over passes.
//
// Why this shape:
// - Counting-sort hash grid after SmallVCM (Davidovic, "HashGrid" in SmallVCM's hashgrid.hxx):
//   cells hashed into a bucket table, photons sorted by bucket with one counting sort, so a
//   query scans contiguous memory and the build is O(N) with no per-cell allocation.
// - Several levels instead of one: the cells are sized to the QUERY radius (>= 2r, so a sphere's
//   bounding box meets at most 2 cells per axis). Radii across a scene may span 1000x; a single
//   level sized to the smallest radius would put the largest query into ~10^9 cells. Level k has
//   cells s_k = s_0 * 2^k, s_0 = 2 * (smallest radius), and a query uses the smallest level whose
//   cells are at least 2r. Only levels some build radius maps to are built.
// - Deterministic: within a bucket entries are in ascending photon index (stable sort), and a
//   query walks its cells in ascending (z, y, x), so the visit order depends only on the input.
//
// Queries are const and may run concurrently; build() must not overlap with queries.
#pragma once

#include "util/math.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace pb {

class HashGrid {
 public:
  // Builds over `positions` for queries whose radii are `radii` (every radius queries will use;
  // duplicates are fine). Throws std::invalid_argument when a radius is not finite and > 0 or a
  // position is not finite; std::length_error beyond 2^31 photons. On a throw the grid is
  // unchanged. Empty positions, or empty radii (no queries expected, e.g. no measurement
  // points), give a grid whose queries visit nothing. Vectors are reused across builds, so
  // once warm a rebuild of the same size does not allocate; only the levels a build no longer
  // uses are freed.
  void build(std::span<const vec3> positions, std::span<const float> radii);

  // Calls visit(uint32_t photon_index, float dist2) once for every photon with
  // dist2 = |p - center|^2 < radius^2 (strict; dist2 is HashGrid::distance2(p, center)).
  // Any finite radius > 0 is exact, including radii larger than every build radius; a radius
  // that is not finite and > 0, or a non-finite center, visits nothing. Order: cells in ascending
  // (z, y, x) cell coordinates, entries in bucket order; a query covering more cells than its
  // level has photons scans the level's entries in storage order instead. No allocation.
  template <class Visit>
  void query(const vec3& center, float radius, Visit&& visit) const;

  // Heap bytes held (capacities, including vectors kept for reuse).
  size_t memory_bytes() const;
  // Levels built by the last build (0 when it had no photons or no radii).
  int level_count() const { return level_count_; }
  size_t photon_count() const { return photon_count_; }

  // The distance test's arithmetic, exposed so brute-force checks can match it bit for bit.
  static float distance2(const vec3& p, const vec3& c) {
    const float dx = p.x - c.x, dy = p.y - c.y, dz = p.z - c.z;
    return dx * dx + dy * dy + dz * dz;
  }

  struct Entry {
    vec3 position;
    uint32_t index;
  };
  static_assert(sizeof(Entry) == 16);

 private:
  struct Level {
    double inv_cell = 0.0;  // 1 / s_k; photons and queries use the same cell_coord()
    int shift = 63;         // 64 - table bits: a bucket is the top bits of the hash
    int64_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // cell range of the photons' bounds
    std::vector<uint32_t> start;  // 2^b + 1 offsets: bucket h is entries[start[h], start[h+1])
    std::vector<Entry> entries;   // every photon once, sorted by bucket, stable in photon index
  };

  // Query boxes are widened by this relative amount so a photon that passes the float distance
  // test despite rounding (true distance up to ~r * (1 + 2e-7)) always lies in a covered cell.
  static constexpr double kBoxPad = 1e-5;
  // Buckets remembered per query for dedupe; the usual query covers 8 cells (27 at most when
  // the padded box is exactly at the cell-size limit).
  static constexpr int kSeenCapacity = 64;
  static constexpr double kCellLimit = 0x1p62;  // keeps floor(x / s) inside int64

  // floor(x * inv_cell) clamped to +-2^62, as truncation and a correction below zero: the same
  // value, and cheaper than std::floor's inline expansion on the x86-64 baseline (no SSE4.1
  // rounding instruction); about 10% of a grid build.
  static int64_t cell_coord(double x, double inv_cell) {
    const double f = std::clamp(x * inv_cell, -kCellLimit, kCellLimit);
    const int64_t t = int64_t(f);
    return t - (double(t) > f ? 1 : 0);
  }
  static size_t bucket_of(int64_t x, int64_t y, int64_t z, int shift) {
    uint64_t h = uint64_t(x) * 0x9e3779b97f4a7c15ULL + uint64_t(y) * 0xc2b2ae3d27d4eb4fULL +
                 uint64_t(z) * 0x165667b19e3779f9ULL;
    // SplitMix64 finaliser: the top bits then depend on every input bit.
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ULL;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebULL;
    return size_t((h ^ (h >> 31)) >> shift);
  }
  // Smallest k >= 0 with r_min * 2^k >= r, i.e. s_k >= 2r; exact (see hash_grid.cpp).
  static int level_of(float r, float r_min) {
    const double q = double(r) / double(r_min);
    if (!(q > 1.0)) return 0;
    int e = 0;
    const double m = std::frexp(q, &e);  // q = m * 2^e, m in [0.5, 1)
    return m == 0.5 ? e - 1 : e;
  }

  // The distance test over entries [e, end), in their order. Four at a time where SSE2 is (the
  // x86-64 baseline): on a surface most entries of the cells a query covers lie outside its
  // sphere (the 8 cells of side >= 2r hold about 10 times the disc's photons), and one branch
  // per entry on the test mispredicted often; a mask of four tests and a walk over its set
  // bits does not. The arithmetic is distance2's, operation for operation (no contraction on
  // this target), so the visits and their dist2 are the scalar loop's, bit for bit.
  template <class Visit>
  static void scan_entries(const Entry* e, const Entry* end, const vec3& c, float r2,
                           Visit& visit) {
#if defined(__SSE2__)
    const __m128 cx = _mm_set1_ps(c.x), cy = _mm_set1_ps(c.y), cz = _mm_set1_ps(c.z);
    const __m128 rr = _mm_set1_ps(r2);
    for (; end - e >= 4; e += 4) {
      __m128 x = _mm_loadu_ps(&e[0].position.x), y = _mm_loadu_ps(&e[1].position.x);
      __m128 z = _mm_loadu_ps(&e[2].position.x), w = _mm_loadu_ps(&e[3].position.x);
      _MM_TRANSPOSE4_PS(x, y, z, w);  // x, y, z: the four positions' coordinates
      const __m128 dx = _mm_sub_ps(x, cx), dy = _mm_sub_ps(y, cy), dz = _mm_sub_ps(z, cz);
      const __m128 d2 =
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
      int inside = _mm_movemask_ps(_mm_cmplt_ps(d2, rr));
      if (inside == 0) continue;
      alignas(16) float d2s[4];
      _mm_store_ps(d2s, d2);
      for (; inside != 0; inside &= inside - 1) {
        const int i = __builtin_ctz(unsigned(inside));
        visit(e[i].index, d2s[i]);
      }
    }
#endif
    for (; e != end; ++e) {
      const float d2 = distance2(e->position, c);
      if (d2 < r2) visit(e->index, d2);
    }
  }
  template <class Visit>
  static void scan(const Level& lv, size_t bucket, const vec3& c, float r2, Visit& visit) {
    const Entry* e = lv.entries.data() + lv.start[bucket];
    scan_entries(e, lv.entries.data() + lv.start[bucket + 1], c, r2, visit);
  }

  // build()'s phases after validation (hash_grid.cpp): the levels the radii use, a level's
  // cells, and every photon hashed and sorted into one level.
  int choose_levels(std::span<const float> radii, float r_min, float r_max);
  static void size_level(Level& lv, double cell, int bits, const Bounds& bounds);
  void build_level(Level& lv, std::span<const vec3> positions, int bits);

  std::vector<Level> levels_;      // [0, level_count_) in use; the rest empty
  std::vector<int> level_map_;     // level k (0..L-1) -> slot of the smallest built level >= k
  std::vector<uint8_t> used_;      // build scratch: level k is used by some radius
  std::vector<uint32_t> buckets_;  // build scratch: bucket of each photon
  std::vector<Entry> staged_;      // build scratch: entries by super-bucket
  std::vector<uint32_t> staged_buckets_;           // build scratch: their buckets
  std::vector<uint32_t> histogram_, super_start_;  // build scratch of the first sort round
  int level_count_ = 0;
  size_t photon_count_ = 0;
  float r_min_ = 1.0f;
};

template <class Visit>
void HashGrid::query(const vec3& center, float radius, Visit&& visit) const {
  if (level_count_ == 0 || !(radius > 0.0f) || !std::isfinite(radius) || !is_finite(center)) return;
  // Radii above every build radius clamp to the top level; the cell loop below stays exact.
  const int k = std::min(level_of(radius, r_min_), int(level_map_.size()) - 1);
  const Level& lv = levels_[size_t(level_map_[size_t(k)])];
  const float r2 = radius * radius;

  // Cells overlapped by the padded box [c - r, c + r], clipped to the photons' cell range.
  const double h = double(radius) * (1.0 + kBoxPad);
  const float c3[3] = {center.x, center.y, center.z};
  int64_t lo[3], hi[3];
  double cells = 1.0;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max(cell_coord(double(c3[a]) - h, lv.inv_cell), lv.lo[a]);
    hi[a] = std::min(cell_coord(double(c3[a]) + h, lv.inv_cell), lv.hi[a]);
    if (lo[a] > hi[a]) return;
    cells *= double(hi[a] - lo[a]) + 1.0;
  }

  if (cells > double(lv.entries.size())) {
    // More cells than photons (a radius far above the build radii): every photon of the level
    // is in entries exactly once, so one linear scan is exact and cheaper than the cell walk.
    scan_entries(lv.entries.data(), lv.entries.data() + lv.entries.size(), center, r2, visit);
    return;
  }

  if (cells <= double(kSeenCapacity)) {
    // Usual path. Two cells may share a bucket: scanning it once visits the photons of both
    // (entries of uncovered cells fail the distance test, as the padded box contains every
    // passing photon), so a repeated bucket is skipped.
    size_t seen[kSeenCapacity];
    int n_seen = 0;
    for (int64_t z = lo[2]; z <= hi[2]; ++z)
      for (int64_t y = lo[1]; y <= hi[1]; ++y)
        for (int64_t x = lo[0]; x <= hi[0]; ++x) {
          const size_t b = bucket_of(x, y, z, lv.shift);
          if (std::find(seen, seen + n_seen, b) != seen + n_seen) continue;
          seen[n_seen++] = b;
          scan(lv, b, center, r2, visit);
        }
    return;
  }

  // Too many cells to remember their buckets: visit, in each cell's bucket, only the entries
  // whose own cell is that cell. Cells are distinct, so each photon is visited once; a bucket
  // shared by several cells is merely scanned several times.
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const size_t b = bucket_of(x, y, z, lv.shift);
        const Entry* e = lv.entries.data() + lv.start[b];
        const Entry* end = lv.entries.data() + lv.start[b + 1];
        for (; e != end; ++e) {
          const vec3& p = e->position;
          if (cell_coord(p.x, lv.inv_cell) != x || cell_coord(p.y, lv.inv_cell) != y ||
              cell_coord(p.z, lv.inv_cell) != z)
            continue;
          const float d2 = distance2(p, center);
          if (d2 < r2) visit(e->index, d2);
        }
      }
}

}  // namespace pb
