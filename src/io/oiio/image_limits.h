// Checks of an opened image before its pixels are read (issue 36): what the header claims
// against the read's budget and against what the file's bytes can hold, and the buffers
// OpenImageIO will allocate to read it. Each throws ImageError naming the file. Used by
// the OpenImageIO module (src/io/oiio/codec.cpp) only.
#pragma once

#include <OpenImageIO/imageio.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "io/image_io.h"

namespace pb {

// A file about to be read whole as floats: refused when deep, past `limit`, or (an EXR whose
// compression bounds its ratio) when its pixels cannot fit in the file, all from its header.
void check_whole_read(const std::string& path, const OIIO::ImageInput& in, const ReadLimit& limit);

// Refused when OpenImageIO's conversion buffer for reading `spec`'s rows as `to` passes
// max(max_bytes, 256 MiB).
void check_read_chunk(const std::string& name, const OIIO::ImageSpec& spec, OIIO::TypeDesc to,
                      uint64_t max_bytes);

// A PNG whose header claims more rows than its `size` bytes can make (deflate: 1032:1) is
// refused; other formats pass. `claim` is the dimensions as the message states them.
void check_plausible(const OIIO::ImageInput& in, const unsigned char* data, size_t size,
                     const std::string& name, const std::string& claim);

}  // namespace pb
