// The render's memory, estimated before it starts (docs/usage.md "Memory"), so that a render
// that cannot fit is refused with the estimate in one line instead of failing with
// std::bad_alloc minutes in (--resolution 16384x16384 did after 9 s).
#pragma once

#include "options/options.h"
#include "scene/scene.h"

#include <cstdint>
#include <stdexcept>
#include <string>

namespace pb {

// What a render is estimated to need, by part. The figures per pixel and per photon are peak
// resident sizes measured on scenes/cornell.gltf (1 pass, tools' build, see the coefficients in
// render_memory.cpp); the scene part is its textures and triangles. An estimate, not a bound: a
// scene whose photons bounce more than the Cornell box's keeps more photon hits.
struct MemoryEstimate {
  uint64_t pixels = 0;    // per-pixel states, films, the image written (and checkpoint copies)
  uint64_t photons = 0;   // one pass's photon hits and their grid
  uint64_t scene = 0;     // decoded textures, triangles and their acceleration structure
  uint64_t baseline = 0;  // the program and its libraries
  uint64_t total() const;
  std::string text() const;  // "about 151 GiB (150 GiB for 268435456 pixels, ...)"
  uint64_t pixel_count = 0;
};

// The estimate for `options` at width x height pixels; `scene` may be null (before loading it).
MemoryEstimate estimate_render_memory(const RenderOptions& options, uint64_t width, uint64_t height,
                                      const Scene* scene);

// Throws UsageError "the render needs about X (...), over the Y of --max-memory; ..." when the
// estimate passes memory_budget(options). Before the scene is loaded (`scene` null) only an
// explicit --resolution is known; after, the camera's image size and the scene's own part.
void check_render_memory(const RenderOptions& options, const Scene* scene);

}  // namespace pb
