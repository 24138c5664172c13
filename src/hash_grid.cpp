// Build of the multi-level counting-sort hash grid (design notes in hash_grid.h).
//
// Single-threaded on purpose: per level it is one pass to hash, one prefix sum over the bucket
// table and one scatter, milliseconds for a few million photons, and a serial scatter is
// trivially stable (entries of a bucket in ascending photon index) and so deterministic.
#include "photonbound/hash_grid.h"

#include <limits>
#include <stdexcept>
#include <string>

namespace pb {

namespace {

// Bucket-table bits: the smallest b >= 1 with 2^b >= 2 * n, so the table is at most half full
// and two cells of a query rarely share a bucket.
int table_bits(size_t n) {
  int b = 1;
  while ((size_t(1) << b) < 2 * n) ++b;
  return b;
}

}  // namespace

// level_of() is exact: r_min * 2^k >= r  <=>  r / r_min <= 2^k, and the double quotient of two
// floats cannot round across a power of two (a ratio of 24-bit mantissas above 1 exceeds it by
// at least 2^-24), so frexp() of the quotient gives the exact smallest k. With all radii equal
// every radius maps to level 0 and exactly one level is built.
void HashGrid::build(std::span<const vec3> positions, std::span<const float> radii) {
  // Validate everything before touching state, so a throw leaves the previous grid usable.
  float r_min = std::numeric_limits<float>::infinity(), r_max = 0.0f;
  for (const float r : radii) {
    if (!(r > 0.0f) || !std::isfinite(r))
      throw std::invalid_argument("HashGrid::build: query radius " + std::to_string(r) +
                                  " is not finite and > 0");
    r_min = std::min(r_min, r);
    r_max = std::max(r_max, r);
  }
  // Bucket indices are stored as uint32 and a table holds 2^b >= 2n buckets.
  if (positions.size() > (size_t(1) << 31))
    throw std::length_error("HashGrid::build: more than 2^31 photons");
  Bounds bounds;
  for (const vec3& p : positions) {
    if (!is_finite(p)) throw std::invalid_argument("HashGrid::build: non-finite photon position");
    bounds.extend(p);
  }

  const size_t n = positions.size();
  photon_count_ = n;
  r_min_ = r_min;
  level_count_ = 0;
  level_map_.clear();
  if (n == 0 || radii.empty()) return;

  // Mark the levels the radii use; build those, in ascending k, into slots 0, 1, ...
  const int top = level_of(r_max, r_min);
  used_.assign(size_t(top) + 1, 0);
  for (const float r : radii) used_[size_t(level_of(r, r_min))] = 1;
  level_map_.assign(size_t(top) + 1, -1);
  for (int k = 0; k <= top; ++k)
    if (used_[size_t(k)]) level_map_[size_t(k)] = level_count_++;
  // An unused level k maps to the next built level above (cells still >= 2r; the top level is
  // always built since r_max maps to it).
  for (int k = top - 1; k >= 0; --k)
    if (level_map_[size_t(k)] < 0) level_map_[size_t(k)] = level_map_[size_t(k) + 1];
  if (levels_.size() < size_t(level_count_)) levels_.resize(size_t(level_count_));

  const int bits = table_bits(n);
  const size_t table = size_t(1) << bits;
  buckets_.resize(n);
  const double s0 = 2.0 * double(r_min);

  for (int k = 0; k <= top; ++k) {
    if (!used_[size_t(k)]) continue;
    Level& lv = levels_[size_t(level_map_[size_t(k)])];
    lv.inv_cell = 1.0 / std::ldexp(s0, k);
    lv.shift = 64 - bits;
    const double blo[3] = {bounds.lo.x, bounds.lo.y, bounds.lo.z};
    const double bhi[3] = {bounds.hi.x, bounds.hi.y, bounds.hi.z};
    for (int a = 0; a < 3; ++a) {
      lv.lo[a] = cell_coord(blo[a], lv.inv_cell);
      lv.hi[a] = cell_coord(bhi[a], lv.inv_cell);
    }

    // Counting sort: count per bucket, inclusive prefix sum (start[h] = end of bucket h), then
    // scatter in descending photon index with --start[h], which fills each bucket from its end:
    // entries come out in ascending index and start[h] ends up at the bucket's beginning.
    // Hashing and counting are separate loops: the count's increments are random accesses to
    // a table of ~8n bytes, and without the hash arithmetic in between many of those cache
    // misses overlap (measured ~2.5x faster for 3M photons).
    for (size_t i = 0; i < n; ++i) {
      const vec3& p = positions[i];
      buckets_[i] = uint32_t(bucket_of(cell_coord(p.x, lv.inv_cell), cell_coord(p.y, lv.inv_cell),
                                       cell_coord(p.z, lv.inv_cell), lv.shift));
    }
    lv.start.assign(table + 1, 0);  // assign() keeps the capacity: no allocation once warm
    for (size_t i = 0; i < n; ++i) ++lv.start[buckets_[i]];
    for (size_t h = 1; h < table; ++h) lv.start[h] += lv.start[h - 1];
    lv.start[table] = uint32_t(n);
    lv.entries.resize(n);
    for (size_t i = n; i-- > 0;) {
      const uint32_t slot = --lv.start[buckets_[i]];
      lv.entries[slot] = Entry{positions[i], uint32_t(i)};
    }
  }
}

size_t HashGrid::memory_bytes() const {
  size_t bytes = levels_.capacity() * sizeof(Level) + level_map_.capacity() * sizeof(int) +
                 used_.capacity() * sizeof(uint8_t) + buckets_.capacity() * sizeof(uint32_t);
  for (const Level& lv : levels_)
    bytes += lv.start.capacity() * sizeof(uint32_t) + lv.entries.capacity() * sizeof(Entry);
  return bytes;
}

}  // namespace pb
