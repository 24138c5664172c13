#include "render/render_memory.h"

#include "io/image_io.h"
#include "render/camera_choice.h"
#include "util/memory.h"

namespace pb {

namespace {

// Peak resident bytes, measured with /usr/bin/time -v on scenes/cornell.gltf, 1 pass, above the
// 140 MiB the program takes with a 16x16 image: SPPM 626 bytes per pixel at 1024^2, PPM 778 (its
// visible points and their pass; both with the two-scale bias's prior, ESTIMATOR.md section 6c,
// 24 more than --bias-model laplacian), a pass of photons 166 bytes per photon emitted (1e5 and
// 1e6 photons). Rounded up a little; a checkpoint copies each 208-byte state.
constexpr uint64_t kSppmPixelBytes = 640;
constexpr uint64_t kPpmPixelBytes = 800;
constexpr uint64_t kCheckpointPixelBytes = 208;
constexpr uint64_t kPhotonBytes = 170;
// A triangle's share of the World (positions, normals, precomputed face normals) and Embree's
// BVH (Embree's documentation: about 64 bytes per triangle for its default build).
constexpr uint64_t kTriangleBytes = 160;
constexpr uint64_t kBaselineBytes = uint64_t(140) << 20;

}  // namespace

uint64_t MemoryEstimate::total() const {
  return saturating_add(saturating_add(pixels, photons), saturating_add(scene, baseline));
}

std::string MemoryEstimate::text() const {
  std::string t = "about " + bytes_text(total()) + " (" + bytes_text(pixels) + " for " +
                  std::to_string(pixel_count) + " pixels, " + bytes_text(photons) +
                  " for a pass of photons";
  if (scene > 0) t += ", " + bytes_text(scene) + " for the scene";
  return t + ", " + bytes_text(baseline) + " for the program)";
}

// --adaptive paths (sppm.h, path_allocation.h): a pixel's number of paths (1 byte), its
// history (12) and the allocation's variance model during a pass (20), counted, not measured.
constexpr uint64_t kPathPixelBytes = 33;

MemoryEstimate estimate_render_memory(const RenderOptions& o, uint64_t width, uint64_t height,
                                      const Scene* scene) {
  MemoryEstimate e;
  e.pixel_count = width * height;
  const uint64_t per_pixel = (o.method == Method::PPM ? kPpmPixelBytes : kSppmPixelBytes) +
                             (o.checkpoint_every ? kCheckpointPixelBytes : 0) +
                             (o.adaptive_paths && o.method == Method::SPPM ? kPathPixelBytes : 0);
  e.pixels = saturating_mul(e.pixel_count, per_pixel);
  e.photons = saturating_mul(o.photons_per_pass, kPhotonBytes);
  if (scene) {
    uint64_t textures = 0;
    for (const Image& im : scene->images) textures += image_bytes(im);
    e.scene = textures + saturating_mul(scene->triangle_count(), kTriangleBytes);
  }
  e.baseline = kBaselineBytes;
  return e;
}

void check_render_memory(const RenderOptions& o, const Scene* scene) {
  uint64_t width = 0, height = 0;
  if (scene) {
    const PinholeCamera camera = choose_camera(*scene, o);
    width = uint64_t(camera.width());
    height = uint64_t(camera.height());
  } else if (o.width && o.height) {
    width = uint64_t(*o.width);
    height = uint64_t(*o.height);
  } else {
    return;  // the image size comes from the scene's camera
  }
  const MemoryEstimate e = estimate_render_memory(o, width, height, scene);
  const uint64_t budget = memory_budget(o);
  if (e.total() > budget)
    throw UsageError("the render needs " + e.text() + ", over the " + bytes_text(budget) +
                     " of --max-memory" + (o.max_memory ? "" : " (3/4 of this machine's memory)") +
                     "; lower --resolution or --photons-per-pass");
}

}  // namespace pb
