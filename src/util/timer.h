// Wall-clock time for budgets and phase timings: the steady clock (never CPU time, never the
// adjustable system clock).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <optional>

namespace pb {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// What ends a pass before it is whole: Ctrl-C or SIGTERM (a flag), the end of --time (a
// deadline), or any test (thread-safe). The threads of a pass poll it between batches of photons
// and of points; a pass cut short is discarded whole (render/renderer.h, Renderer::step).
struct Cutoff {
  std::function<bool()> test;  // empty: never
  bool reached() const { return test && test(); }
};

// The cutoff of a render: `flag` set, or `deadline` passed.
inline Cutoff flag_or_deadline(const std::atomic<bool>* flag,
                               std::optional<Clock::time_point> deadline) {
  return {[flag, deadline] {
    return (flag && flag->load(std::memory_order_relaxed)) ||
           (deadline && Clock::now() >= *deadline);
  }};
}

}  // namespace pb
