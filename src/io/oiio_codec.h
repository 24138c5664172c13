// The part of image_io that needs OpenImageIO, as a table of functions in a module of its own
// (build/photonbound_oiio.so, src/io/oiio/), loaded on first use. Why: OpenImageIO links 261
// shared libraries, and a process that links it spends 0.3-0.35 s in the dynamic loader before
// main (bench/README.md "Outside the pass loop"), a tenth of a 16-pass 512x512 render and a
// third of a small one, whether it reads an image or not. A render of a scene without textures
// writes its EXR through OpenEXR (exr_write.cpp) and never loads the module.
//
// Exceptions do not cross the module's edge: each call reports a CodecFailure, and image_io.cpp
// throws the ImageError it describes. Both sides are built from these declarations by the same
// compiler in the same build; kOiioCodecAbi guards against a stale module beside a new binary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "io/image_io.h"

namespace pb {

inline constexpr int kOiioCodecAbi = 1;

// The most texels a texture may have (decode_image's messages say 2^28): the container walk in
// image_io.cpp and the module's header check both hold images to it.
inline constexpr uint64_t kMaxTexels = uint64_t(1) << 28;

struct CodecFailure {
  enum class Kind { None, Image, TooLarge, FormatRefused };
  Kind kind = Kind::None;
  std::string message;
  uint64_t bytes = 0;  // TooLarge: what the decoded texels would take
  std::string format;  // FormatRefused: the format recognised, or empty
};

struct OiioCodec {
  int abi = kOiioCodecAbi;
  // read_exr and read_rgb_image after image_io.cpp's container walk of the file.
  void (*read_exr)(const std::string& path, const ReadLimit& limit, ExrImage& out,
                   CodecFailure& failure);
  void (*read_rgb_image)(const std::string& path, const ReadLimit& limit, RgbImage& out,
                         CodecFailure& failure);
  // decode_image after image_io.cpp's signature and container checks; `file` is the made-up
  // name whose extension names the format, `gltf` the reader glTF's signature names ("" when
  // none) and `gltf_only` whether only that reader may see the bytes.
  void (*decode_image)(const unsigned char* data, size_t size, const std::string& name,
                       const std::string& file, const std::string& gltf, bool gltf_only,
                       uint64_t max_bytes, Image& out, CodecFailure& failure);
  // An 8-bit RGB PNG written to `tmp` (write_atomically's temporary; `path` for messages).
  void (*write_png)(const std::string& path, const std::string& tmp, int width, int height,
                    const unsigned char* rgb, CodecFailure& failure);
};

}  // namespace pb

// The module's one exported symbol. image_io.cpp declares it weak: where the module's sources
// are linked in (the fuzz targets), that definition is used and nothing is loaded.
extern "C" const pb::OiioCodec* photonbound_oiio_codec();
