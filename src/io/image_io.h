// EXR reading and writing, and decoding the images of glTF textures. EXRs are written through
// OpenEXR's core library, their ZIP chunks deflated by libdeflate (exr_write.cpp); everything that
// needs OpenImageIO (reads, texture decoding, PNG) is in the module src/io/oiio/, which
// image_io.cpp loads on first use (io/oiio_codec.h).
#pragma once

#include "scene/scene.h"

#include <cstdint>
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
// ZIP shrinks little (the 20 channels of a 16-pass 512x512 render of the default scene: 30% in
// all, for 0.26 s of CPU at libdeflate's fastest level), so checkpoints, which are rewritten
// every few seconds to minutes, are written uncompressed; the final image uses ZIP.
enum class ExrCompression { Zip, None };

// An image as write_exr reads it: channel c of pixel p (row-major) is
// planes[c].data[p * planes[c].stride]. A render's film is written from its own planes through
// one, with no interleaved copy of the image first (21 MB at 512x512, 166 MB at 1920x1080, and
// 0.02 s of a 16-pass 512x512 render's 0.23 s outside its pass loop); an ExrImage converts to
// one. A view holds pointers into the image it was made from, which must outlive it.
struct ExrView {
  struct Plane {
    const float* data = nullptr;
    size_t stride = 1;
  };
  int width = 0, height = 0;
  std::vector<std::string> channels;
  std::vector<Plane> planes;  // one per channel
  std::vector<std::pair<std::string, std::string>> metadata;

  ExrView() = default;
  ExrView(const ExrImage& image);  // NOLINT(google-explicit-constructor): write_exr takes either
  int channel_index(const std::string& name) const;  // -1 when absent
  float at(size_t c, size_t p) const { return planes[c].data[p * planes[c].stride]; }
};

// The view's pixels interleaved, as read_exr returns an image (none where a plane is missing).
ExrImage packed(const ExrView& view);

// Writes float32 EXR atomically (file_io.h write_atomically): a reader never sees a partial
// image. Throws ImageError naming the file.
void write_exr(const std::string& path, const ExrView& image,
               ExrCompression compression = ExrCompression::Zip);

// How much a file read whole may take (its header's width x height x channels as floats), and
// what sets it, for the message: "--max-memory", "3/4 of the machine's memory".
struct ReadLimit {
  uint64_t max_bytes = UINT64_MAX;
  std::string source = "--max-memory";
};

// Reads an EXR whole, as floats. Throws ImageError naming the file when it cannot, when it is
// a deep image (several samples per pixel), when the decoder reports any error (a short file),
// or, from the header and before any pixel is allocated, when it passes `limit`.
ExrImage read_exr(const std::string& path, const ReadLimit& limit = {});

// An image's colour as linear RGB floats, for environment maps: any format OpenImageIO reads
// (.exr, .hdr), its first three channels (one channel: grey). Throws ImageError naming the file,
// as read_exr does.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 floats per pixel, row-major, row 0 at the top
};
RgbImage read_rgb_image(const std::string& path, const ReadLimit& limit = {});

// Writes an 8-bit RGB PNG (rgb: 3 bytes per pixel, row-major), atomically like write_exr.
void write_png(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb);

// Decodes an image file held in memory (PNG, JPEG, WebP; with ImageFormats::Any whatever else
// OpenImageIO reads, the format recognised from the bytes, else from `name`'s extension) into
// texels as stored: 8-bit images as 8-bit values, others as floats in [0, 1], colour not
// premultiplied by alpha (glTF's images are unassociated). At most 4 channels are kept. Throws
// ImageError naming `name` when the bytes are not an image it can read, the decoder reports any
// error (a truncated or corrupt file), the image is beyond 2^28 texels, or its header claims more
// texels than its bytes can hold (PNG: deflate expands at most 1032:1); ImageTooLarge, from the
// header and before any texel is decoded, when the texels would take more than `max_bytes`.
class ImageTooLarge : public ImageError {
 public:
  ImageTooLarge(const std::string& what, uint64_t bytes) : ImageError(what), bytes(bytes) {}
  uint64_t bytes;  // what the decoded texels would take
};
// Which formats decode_image takes. A scene's textures default to glTF's own (PNG, JPEG and
// EXT_texture_webp's WebP: each read only by the reader its signature names), so that an
// untrusted scene reaches none of the other decoders (OpenEXR, libtiff, ...), whose headers
// made them allocate what they claimed again and again under the fuzzer (docs/testing.md);
// Any is --texture-formats any, for trusted files.
enum class ImageFormats { Gltf, Any };
// Thrown under ImageFormats::Gltf for bytes in another format; `format` names it when its
// signature (or, for TGA, which has none, `name`'s extension) is recognised, else is empty.
class ImageFormatRefused : public ImageError {
 public:
  ImageFormatRefused(const std::string& what, std::string format)
      : ImageError(what), format(std::move(format)) {}
  std::string format;
};
Image decode_image(const unsigned char* data, size_t size, const std::string& name,
                   uint64_t max_bytes = UINT64_MAX, ImageFormats formats = ImageFormats::Any);
// What decode_image's image takes: 1 byte per value for 8-bit images, 4 (a float) otherwise.
uint64_t image_bytes(const Image& image);
// The bytes begin with KTX2's identifier (KHR_texture_basisu's container), which no reader here
// decodes.
bool is_ktx2(const unsigned char* data, size_t size);

}  // namespace pb
