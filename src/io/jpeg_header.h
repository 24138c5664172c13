// A JPEG's header as libjpeg reads it, before OpenImageIO opens the file (issue 36).
// OpenImageIO's JPEG reader calls jpeg_start_decompress when it opens a file, and libjpeg
// allocates there, for an image it decodes in several scans (progressive, or a first scan
// without every component), 64 coefficients of 2 bytes for every 8x8 block of every component
// (jdcoefct.c, "full-image" buffer): progressive JPEGs of 240-523 bytes claiming up to
// 65296x65496 made it take 9.6 GB under the image fuzzer. A walk of our own over the markers
// parted ways with libjpeg's (an APP1 of length 0, which libjpeg reads past); libjpeg's own
// jpeg_read_header, which allocates only the tables, gives the frame as the decoder will see it.
// Used by container_check.cpp only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace pb {

// Throws ImageError naming `name` when the JPEG in `data` claims more than `max_texels`
// texels, ImageTooLarge when libjpeg would hold its coefficients whole in more than
// max(`max_bytes`, 256 MiB). A header libjpeg cannot read passes (the decoder then refuses it
// itself), unless `truncated` (only the first `size` bytes of a longer file are here).
void check_jpeg(const unsigned char* data, size_t size, bool truncated, const std::string& name,
                uint64_t max_texels, uint64_t max_bytes);

}  // namespace pb
