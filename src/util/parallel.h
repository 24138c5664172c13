// The one parallel facade over oneTBB. Results never depend on how work is split: callers key
// randomness by work item and write outputs by item or by fixed-size chunk index.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

namespace pb {

// Limits the worker threads for its lifetime (0 = all hardware threads).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;
  int threads() const { return threads_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int threads_;
};

// Calls body(begin, end) over [0, n) in ranges of about `grain` items, in parallel.
template <class Body>
void parallel_for(size_t n, size_t grain, Body&& body) {
  if (n == 0) return;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain == 0 ? 1 : grain),
                    [&](const tbb::blocked_range<size_t>& r) { body(r.begin(), r.end()); });
}

// Calls body(chunk, begin, end) for the fixed chunks [k*chunk_size, min(n, (k+1)*chunk_size)),
// in parallel. Chunk boundaries depend only on n and chunk_size, so per-chunk outputs
// concatenated in chunk order are the same for every thread count.
template <class Body>
void parallel_chunks(size_t n, size_t chunk_size, Body&& body) {
  const size_t chunks = (n + chunk_size - 1) / chunk_size;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t k = r.begin(); k < r.end(); ++k)
                        body(k, k * chunk_size, std::min(n, (k + 1) * chunk_size));
                    });
}

// Runs the calls, possibly at once; returns when all have. Each call's own arithmetic is
// sequential, so its result does not depend on the threads.
template <class... Calls>
void parallel_invoke(Calls&&... calls) {
  tbb::parallel_invoke(std::forward<Calls>(calls)...);
}

}  // namespace pb
