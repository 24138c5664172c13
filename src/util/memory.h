// Memory budgets (docs/usage.md "Memory"): what a render, its textures and the images it reads
// may take, checked from sizes known before anything large is allocated.
#pragma once

#include <cstdint>
#include <string>

namespace pb {

// The machine's memory: physical RAM (sysconf), or the cgroup v2 limit of this process's group
// when that is lower (a container's). 0 when neither can be read.
uint64_t machine_memory();

// --max-memory's default: 3/4 of machine_memory() (the rest is the system's and other
// programs'); 8 GiB when the machine's memory cannot be read.
uint64_t default_memory_budget();

// "1.5 GiB", "300 MiB", "12 KiB", "100 bytes": for messages.
std::string bytes_text(uint64_t bytes);

// a * b saturated at UINT64_MAX (sizes from untrusted headers).
inline uint64_t saturating_mul(uint64_t a, uint64_t b) {
  return a != 0 && b > UINT64_MAX / a ? UINT64_MAX : a * b;
}
inline uint64_t saturating_add(uint64_t a, uint64_t b) {
  return b > UINT64_MAX - a ? UINT64_MAX : a + b;
}

}  // namespace pb
