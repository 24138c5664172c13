// Render state files: everything needed to continue a render exactly where it stopped, so that a
// resumed render is bit-identical to an uninterrupted one with the same seed.
//
// Format (little-endian): "PBSTATE\0", u32 version, u32 sizeof(PointState), then the scene path
// and command line, the options block (u64 count, then key and value strings written by the
// option table's format(), strings as u64 length + bytes), the scene hash, the render's counters
// and initial radius, the driver's schedule, SPPM's per-pixel visible-pass counters (u64 count +
// u32 each), the per-point states as raw PointState records, and
// last a u64 checksum of every byte before it. Written atomically (file_io.h).
#pragma once

#include "app/driver.h"
#include "estimator/estimator.h"
#include "options/options.h"
#include "render/renderer.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb {

// 2: PointState without direct_sum (160 B); 3: options as key/value text from the option table;
// 4: glTF's metallic-roughness materials (a version 3 state was rendered with other ones), the
// sparse-photon bound's SPPM kernel masses, largest photon power and glossy caps;
// 5: PointState with the alternating sums of the noise replica (192 B); 6: with the two-scale
// check's moments (208 B); 7: SPPM's glossy caps as f / c, not f; 8: the photon guide;
// 9: the camera paths' history (--adaptive paths); 10: the two-scale spread in units of the state's
// mean (section 6c).
inline constexpr uint32_t kStateVersion = 10;

struct SavedRender {
  RenderOptions options;    // as rendered (scene path, everything that shapes the image)
  uint64_t scene_hash = 0;  // Scene::content_hash
  RenderState render;
  DriverState schedule;
};

void save_state(const std::string& path, const SavedRender& saved);
SavedRender load_state(const std::string& path);  // throws StateError("<path>: ...")

// What differs between a saved render and the options and scene of a new run, in what changes
// the image (one "name: saved X, now Y" entry each); empty when it may continue.
std::vector<std::string> differences(const SavedRender& saved, const RenderOptions& now,
                                     uint64_t scene_hash);

}  // namespace pb
