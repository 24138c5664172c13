// Render state files: everything needed to continue a render exactly where it stopped, so that a
// resumed render is bit-identical to an uninterrupted one with the same seed.
//
// Format (little-endian): "PBSTATE\0", u32 version, u32 sizeof(PointState), then fields (u64,
// f64, strings as u64 length + bytes), the per-point states as raw PointState records, and last
// a u64 checksum of every byte before it. Written to a temporary name, fsynced, renamed.
#pragma once

#include "photonbound/estimator.h"
#include "photonbound/options.h"

#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace pb {

class StateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr uint32_t kStateVersion = 2;  // 2: PointState without direct_sum (160 B)

// The pass loop's own progress, so that a resumed render checks its target on the same schedule.
struct LoopState {
  uint64_t passes = 0;
  uint64_t photons = 0;
  uint64_t rays = 0;
  double seconds = 0.0;  // wall clock of all runs so far
  uint64_t next_check = 0;
  uint64_t early_pass = 0;
  double early_bound = 0.0;
};

struct SavedRender {
  RenderOptions options;    // as rendered (scene path, everything that shapes the image)
  uint64_t scene_hash = 0;  // of the scene file's bytes
  double initial_radius = 0.0;
  LoopState loop;
  std::vector<PointState> states;
};

void save_state(const std::string& path, const SavedRender& saved);
SavedRender load_state(const std::string& path);  // throws StateError("<path>: ...")

// Hash of a file's bytes (throws StateError if it cannot be read).
uint64_t hash_file(const std::string& path);

// What differs between a saved render and the options and scene of a new run, in the options
// that change the image (one "name: saved X, now Y" entry each); empty when it may continue.
std::vector<std::string> differences(const SavedRender& saved, const RenderOptions& now,
                                     uint64_t scene_hash);

// Writes the pieces, one after the other, to `path` atomically and durably: temporary file,
// fsync, rename, fsync of the folder. Throws StateError naming the file.
void write_file_atomic(const std::string& path, std::initializer_list<std::string_view> pieces);

}  // namespace pb
