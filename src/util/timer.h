// Wall-clock time for budgets and phase timings: the steady clock (never CPU time, never the
// adjustable system clock).
#pragma once

#include <chrono>

namespace pb {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace pb
