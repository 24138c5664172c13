// Structural checks of EXR and TIFF files before OpenImageIO opens them (issue 36). OpenEXR
// and libtiff trust what a header says about sizes: an EXR attribute that claims 1.9 GB in a
// 200-byte file is allocated while the header is parsed, a chunk offset table as long as the
// data window claims is allocated on open, and a TIFF tag's data may lie past the end of the
// file. The libFuzzer run of the image decoders (tools/fuzz.sh image, docs/testing.md) found
// such files within minutes. Each check here walks the container's own structure (the OpenEXR
// file layout; TIFF 6.0 section 2, and BigTIFF) and refuses a size that the file's bytes cannot
// hold, which no valid file has. A JPEG's header is read by libjpeg itself first
// (jpeg_header.h): libjpeg allocates every coefficient of a progressive image when it is opened.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace pb {

// Reads `n` bytes at `offset` into `out`; false when they are not all there.
using ByteReader = std::function<bool(uint64_t offset, uint64_t n, unsigned char* out)>;

// Throws ImageError (io/image_io.h) starting with `name` when the bytes (`size` of them, read
// through `read`) are an EXR or TIFF file whose structure claims more than they hold, more
// than `max_texels` texels (a TIFF: or 4 x max_texels samples), or an EXR chunk whose decoding
// buffers take more than `max_bytes`; a JPEG over `max_texels`, or whose coefficient buffer
// takes more than max(`max_bytes`, 256 MiB) (ImageTooLarge; jpeg_header.h). Other formats, and
// structures it does not know, pass unchecked: the decoder's own checks apply to them.
void check_container(const ByteReader& read, uint64_t size, const std::string& name,
                     uint64_t max_texels, uint64_t max_bytes);

// The same for bytes in memory.
void check_container(const unsigned char* data, uint64_t size, const std::string& name,
                     uint64_t max_texels, uint64_t max_bytes);

// The same for a file (read in pieces; an unreadable file passes, for the reader to report).
void check_container_file(const std::string& path, uint64_t max_texels, uint64_t max_bytes);

}  // namespace pb
