// EXR reading and writing, and decoding the images of glTF textures. The only file that
// includes OpenImageIO is src/io/image_io.cpp.
#pragma once

#include "scene/scene.h"

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pb {

class ImageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ExrImage {
  int width = 0, height = 0;
  std::vector<std::string> channels;  // names, e.g. R, G, B, ErrorBound.R
  std::vector<float> pixels;          // interleaved: channels.size() floats per pixel, row-major
  std::vector<std::pair<std::string, std::string>> metadata;  // stored as string attributes

  int channel_index(const std::string& name) const;  // -1 when absent
};

// How write_exr compresses. The bound, noise and variance channels are noise-like floats that
// ZIP shrinks by only ~6% (512x512 default scene) for ~0.45 s of CPU, so checkpoints, which are
// rewritten every few seconds to minutes, are written uncompressed; the final image uses ZIP.
enum class ExrCompression { Zip, None };

// Writes float32 EXR atomically (file_io.h write_atomically): a reader never sees a partial
// image. Throws ImageError naming the file.
void write_exr(const std::string& path, const ExrImage& image,
               ExrCompression compression = ExrCompression::Zip);

ExrImage read_exr(const std::string& path);

// An image's colour as linear RGB floats, for environment maps: any format OpenImageIO reads
// (.exr, .hdr), its first three channels (one channel: grey). Throws ImageError naming the file.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 floats per pixel, row-major, row 0 at the top
};
RgbImage read_rgb_image(const std::string& path);

// Writes an 8-bit RGB PNG (rgb: 3 bytes per pixel, row-major), atomically like write_exr.
void write_png(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb);

// Decodes an image file held in memory (PNG, JPEG and whatever else OpenImageIO reads; the
// format is recognised from the bytes, else from `name`'s extension) into texels as stored:
// 8-bit images as 8-bit values, others as floats in [0, 1], colour not premultiplied by alpha
// (glTF's images are unassociated). At most 4 channels are kept. Throws ImageError naming
// `name` when the bytes are not an image it can read, or the image is beyond 2^28 texels.
Image decode_image(const unsigned char* data, size_t size, const std::string& name);
// The bytes begin with KTX2's identifier (KHR_texture_basisu's container), which no reader here
// decodes.
bool is_ktx2(const unsigned char* data, size_t size);

}  // namespace pb
