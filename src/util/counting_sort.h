// The one stable parallel counting sort (photon hits into Morton order, photons into grid
// buckets). Items are split into a fixed number of blocks whatever the thread count; each block
// counts its digits, the offsets are laid out in (digit, block) order, and every block then
// places its items in order. The output is therefore the serial stable sort's, bit for bit, for
// every thread count.
#pragma once

#include "util/parallel.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pb {

inline constexpr size_t kSortBlocks = 16;

// Sorts items [0, n) stably by digit(i) in [0, radix): calls place(i, slot) once per item with
// its position in the sorted order. `histogram` is scratch (kSortBlocks x radix counters, kept
// for reuse). With `starts`, also returns where each digit's run begins (radix + 1 offsets).
template <class Digit, class Place>
void stable_counting_sort(size_t n, size_t radix, Digit&& digit, Place&& place,
                          std::vector<uint32_t>& histogram,
                          std::vector<uint32_t>* starts = nullptr) {
  const size_t block = (n + kSortBlocks - 1) / kSortBlocks;
  histogram.assign(kSortBlocks * radix, 0u);
  parallel_for(kSortBlocks, 1, [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      uint32_t* h = histogram.data() + b * radix;
      for (size_t i = b * block; i < std::min(n, (b + 1) * block); ++i) ++h[digit(i)];
    }
  });
  if (starts) starts->resize(radix + 1);
  uint32_t sum = 0;
  for (size_t d = 0; d < radix; ++d) {
    if (starts) (*starts)[d] = sum;
    for (size_t b = 0; b < kSortBlocks; ++b) {
      uint32_t& c = histogram[b * radix + d];
      const uint32_t count = c;
      c = sum;
      sum += count;
    }
  }
  if (starts) (*starts)[radix] = sum;
  parallel_for(kSortBlocks, 1, [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      uint32_t* h = histogram.data() + b * radix;
      for (size_t i = b * block; i < std::min(n, (b + 1) * block); ++i) place(i, h[digit(i)]++);
    }
  });
}

}  // namespace pb
