// Build of the multi-level counting-sort hash grid (design notes in hash_grid.h).
//
// Per level: hash every photon to its bucket (in parallel), then a two-round stable counting
// sort. A single counting sort scatters into the whole bucket table at random, a cache miss per
// photon once the cells are small enough that neighbouring photons land in different buckets
// (after the radii have shrunk); that scatter was about half of the build. So round 1
// partitions the entries by the bucket's top bits into at most 256 super-buckets (a small
// histogram, sequential output streams), and round 2 counting-sorts each super-bucket within
// its own slice of the table, which fits in L2. Both rounds are stable and work over a fixed
// number of blocks, so entries come out exactly as the single serial sort made them (bucket
// order, ascending photon index within a bucket) for every thread count. Scratch: 24 bytes per
// photon, kept for the next build.
#include "render/hash_grid.h"

#include "util/counting_sort.h"
#include "util/parallel.h"

#include <limits>
#include <stdexcept>
#include <string>

namespace pb {

namespace {

// Bucket-table bits: the smallest b >= 1 with 2^b >= n. A table is at most full even if every
// photon had a cell of its own; in practice cells hold several photons each (a query disc
// gathers tens), so the occupied buckets are a small fraction and collisions are rare. Against
// a table of 2n buckets, the gather per pass (`photonbound-bench --profile pass`, 512x512, 1M
// photons) differed by less than the run-to-run noise (+-5%), and 2n cost 6 more bytes per
// visible point at 1080p (issue 5's memory budget).
int table_bits(size_t n) {
  int b = 1;
  while ((size_t(1) << b) < n) ++b;
  return b;
}

constexpr int kSuperBits = 8;         // round 1 fans out into at most 2^8 super-buckets
constexpr size_t kBlocks = 16;        // fixed blocks of the validation scans
constexpr size_t kHashGrain = 16384;  // photons per parallel hashing task

}  // namespace

void HashGrid::build_level(Level& lv, std::span<const vec3> positions, int bits) {
  const size_t n = positions.size();
  const size_t table = size_t(1) << bits;
  parallel_for(n, kHashGrain, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const vec3& p = positions[i];
      buckets_[i] = uint32_t(bucket_of(cell_coord(p.x, lv.inv_cell), cell_coord(p.y, lv.inv_cell),
                                       cell_coord(p.z, lv.inv_cell), lv.shift));
    }
  });

  // Round 1: stable partition of the entries by super-bucket = bucket >> super_shift.
  const int super_bits = std::min(kSuperBits, bits);
  const int super_shift = bits - super_bits;
  const size_t supers = size_t(1) << super_bits;
  staged_.resize(n);
  staged_buckets_.resize(n);
  stable_counting_sort(
      n, supers, [&](size_t i) { return size_t(buckets_[i] >> super_shift); },
      [&](size_t i, uint32_t slot) {
        staged_[slot] = Entry{positions[i], uint32_t(i)};
        staged_buckets_[slot] = buckets_[i];
      },
      histogram_, &super_start_);

  // Round 2: per super-bucket, a counting sort over its slice of the table: count, inclusive
  // prefix (start[h] = end of bucket h), then scatter in descending photon index with --start[h],
  // which leaves start[h] at the bucket's beginning and the entries in ascending index.
  lv.start.resize(table + 1);
  lv.entries.resize(n);
  parallel_for(supers, 1, [&](size_t s0, size_t s1) {
    for (size_t s = s0; s < s1; ++s) {
      const size_t h0 = s << super_shift, h1 = (s + 1) << super_shift;
      uint32_t* start = lv.start.data();
      std::fill(start + h0, start + h1, 0u);
      const size_t first = super_start_[s], last = super_start_[s + 1];
      for (size_t q = first; q != last; ++q) ++start[staged_buckets_[q]];
      uint32_t acc = super_start_[s];
      for (size_t h = h0; h < h1; ++h) start[h] = acc += start[h];
      for (size_t q = last; q-- != first;) lv.entries[--start[staged_buckets_[q]]] = staged_[q];
    }
  });
  lv.start[table] = uint32_t(n);
}

namespace {

// What validate_inputs() finds: the radii's range and the photons' bounds.
struct InputRange {
  float r_min = std::numeric_limits<float>::infinity(), r_max = 0.0f;
  Bounds bounds;
};

// The radii's range and the photons' bounds, or a throw before any state is touched.
InputRange validate_inputs(std::span<const vec3> positions, std::span<const float> radii) {
  struct Scan {
    float r_min = std::numeric_limits<float>::infinity(), r_max = 0.0f;
    bool bad_radius = false, bad_position = false;
    float first_bad = 0.0f;
    Bounds bounds;
  };
  // A throw leaves the previous grid usable. The scans run over fixed blocks in parallel (min,
  // max and the bounds do not depend on order).
  Scan scans[kBlocks];
  const size_t rblock = (radii.size() + kBlocks - 1) / kBlocks;
  const size_t pblock = (positions.size() + kBlocks - 1) / kBlocks;
  parallel_for(kBlocks, 1, [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      Scan& sc = scans[b];
      for (size_t i = b * rblock; i < std::min(radii.size(), (b + 1) * rblock); ++i) {
        const float r = radii[i];
        if (!(r > 0.0f) || !std::isfinite(r)) {
          if (!sc.bad_radius) sc.first_bad = r;
          sc.bad_radius = true;
        }
        sc.r_min = std::min(sc.r_min, r);
        sc.r_max = std::max(sc.r_max, r);
      }
      for (size_t i = b * pblock; i < std::min(positions.size(), (b + 1) * pblock); ++i) {
        sc.bad_position |= !is_finite(positions[i]);
        sc.bounds.extend(positions[i]);
      }
    }
  });
  InputRange in;
  for (const Scan& sc : scans) {
    if (sc.bad_radius)
      throw std::invalid_argument("HashGrid::build: query radius " + std::to_string(sc.first_bad) +
                                  " is not finite and > 0");
    in.r_min = std::min(in.r_min, sc.r_min);
    in.r_max = std::max(in.r_max, sc.r_max);
    in.bounds.lo = glm::min(in.bounds.lo, sc.bounds.lo);
    in.bounds.hi = glm::max(in.bounds.hi, sc.bounds.hi);
  }
  // Bucket indices are stored as uint32 and a table holds 2^b >= n buckets.
  if (positions.size() > (size_t(1) << 31))
    throw std::length_error("HashGrid::build: more than 2^31 photons");
  for (const Scan& sc : scans)
    if (sc.bad_position) throw std::invalid_argument("HashGrid::build: non-finite photon position");
  return in;
}

}  // namespace

// level_of() is exact: r_min * 2^k >= r  <=>  r / r_min <= 2^k, and the double quotient of two
// floats cannot round across a power of two (a ratio of 24-bit mantissas above 1 exceeds it by
// at least 2^-24), so frexp() of the quotient gives the exact smallest k. With all radii equal
// every radius maps to level 0 and exactly one level is built.

// Which levels the radii R_j (ESTIMATOR.md section 3) use, in used_ and level_map_; the top one.
int HashGrid::choose_levels(std::span<const float> radii, float r_min, float r_max) {
  const size_t rblock = (radii.size() + kBlocks - 1) / kBlocks;
  const int top = level_of(r_max, r_min);
  const size_t levels = size_t(top) + 1;
  // Mark the levels the radii use; build those, in ascending k, into slots 0, 1, ...
  used_.assign(kBlocks * levels, 0);  // per block, then merged into the first block's row
  parallel_for(kBlocks, 1, [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b)
      for (size_t i = b * rblock; i < std::min(radii.size(), (b + 1) * rblock); ++i)
        used_[b * levels + size_t(level_of(radii[i], r_min))] = 1;
  });
  for (size_t b = 1; b < kBlocks; ++b)
    for (size_t k = 0; k < levels; ++k) used_[k] |= used_[b * levels + k];
  level_map_.assign(size_t(top) + 1, -1);
  for (int k = 0; k <= top; ++k)
    if (used_[size_t(k)]) level_map_[size_t(k)] = level_count_++;
  // An unused level k maps to the next built level above (cells still >= 2r; the top level is
  // always built since r_max maps to it).
  for (int k = top - 1; k >= 0; --k)
    if (level_map_[size_t(k)] < 0) level_map_[size_t(k)] = level_map_[size_t(k) + 1];
  if (levels_.size() < size_t(level_count_)) levels_.resize(size_t(level_count_));
  // Slots beyond this build's levels give their memory back: a render that once used more
  // levels (radii spread wider) must not keep a photon array per level it no longer has.
  for (size_t i = size_t(level_count_); i < levels_.size(); ++i) levels_[i] = Level{};
  return top;
}

// A level's cells: their size, the hash's shift and the cell range of the photons' bounds.
void HashGrid::size_level(Level& lv, double cell, int bits, const Bounds& bounds) {
  lv.inv_cell = 1.0 / cell;
  lv.shift = 64 - bits;
  const double blo[3] = {bounds.lo.x, bounds.lo.y, bounds.lo.z};
  const double bhi[3] = {bounds.hi.x, bounds.hi.y, bounds.hi.z};
  for (int a = 0; a < 3; ++a) {
    lv.lo[a] = cell_coord(blo[a], lv.inv_cell);
    lv.hi[a] = cell_coord(bhi[a], lv.inv_cell);
  }
}

// The grid, by phases: validate, choose the levels, then per built level its cells and photons.
void HashGrid::build(std::span<const vec3> positions, std::span<const float> radii) {
  const InputRange in = validate_inputs(positions, radii);
  const size_t n = positions.size();
  photon_count_ = n;
  r_min_ = in.r_min;
  level_count_ = 0;
  level_map_.clear();
  if (n == 0 || radii.empty()) return;

  const int top = choose_levels(radii, in.r_min, in.r_max);
  const int bits = table_bits(n);
  buckets_.resize(n);
  const double s0 = 2.0 * double(in.r_min);
  for (int k = 0; k <= top; ++k) {
    if (!used_[size_t(k)]) continue;
    Level& lv = levels_[size_t(level_map_[size_t(k)])];
    size_level(lv, std::ldexp(s0, k), bits, in.bounds);
    build_level(lv, positions, bits);
  }
}

size_t HashGrid::memory_bytes() const {
  size_t bytes =
      levels_.capacity() * sizeof(Level) + level_map_.capacity() * sizeof(int) +
      used_.capacity() * sizeof(uint8_t) + buckets_.capacity() * sizeof(uint32_t) +
      staged_.capacity() * sizeof(Entry) + staged_buckets_.capacity() * sizeof(uint32_t) +
      histogram_.capacity() * sizeof(uint32_t) + super_start_.capacity() * sizeof(uint32_t);
  for (const Level& lv : levels_)
    bytes += lv.start.capacity() * sizeof(uint32_t) + lv.entries.capacity() * sizeof(Entry);
  return bytes;
}

}  // namespace pb
