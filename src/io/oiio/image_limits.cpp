#include "io/oiio/image_limits.h"

#include <algorithm>
#include <cstring>
#include <filesystem>

#include "util/memory.h"
#include "util/message_text.h"

namespace pb {

namespace {

// deflate's largest expansion: a 258-byte match costs at least 2 bits, about 1032:1 (zlib's
// "Maximum compression factor", zlib.net/zlib_tech.html).
constexpr uint64_t kDeflateMaxRatio = 1032;

// The most an EXR's compression can shrink its pixels: none stores them as they are, ZIP is
// deflate (1032:1, see kDeflateMaxRatio), RLE a run of at most 128 bytes in 2 (OpenEXR's
// ImfRle.cpp); 0 for the others (PIZ, PXR24, B44, DWA), which have no bound used here.
uint64_t exr_max_ratio(const std::string& compression) {
  if (compression == "none") return 1;
  if (compression == "zip" || compression == "zips") return kDeflateMaxRatio;
  if (compression == "rle") return 64;
  return 0;
}

}  // namespace

void check_whole_read(const std::string& path, const OIIO::ImageInput& in, const ReadLimit& limit) {
  const OIIO::ImageSpec& spec = in.spec();
  if (spec.deep)
    throw ImageError(path +
                     ": is a deep image (several samples per pixel), which photonbound does "
                     "not read; flatten it first");
  const uint64_t values = saturating_mul(
      saturating_mul(uint64_t(std::max(spec.width, 0)), uint64_t(std::max(spec.height, 0))),
      uint64_t(std::max(spec.nchannels, 0)));
  const uint64_t bytes = saturating_mul(values, sizeof(float));
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 || bytes > limit.max_bytes)
    throw ImageError(path + ": the header claims " + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + " pixels of " + std::to_string(spec.nchannels) +
                     " channels" +
                     (spec.width < 1 || spec.height < 1 || spec.nchannels < 1
                          ? ""
                          : ", " + bytes_text(bytes) + " as floats, over the " +
                                bytes_text(limit.max_bytes) + " of " + limit.source));
  if (std::string(in.format_name()) != "openexr") return;
  const uint64_t ratio = exr_max_ratio(spec.get_string_attribute("compression", "none"));
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  const uint64_t stored = spec.image_bytes(/*native=*/true);  // each channel in its own type
  if (ratio > 0 && !ec && stored / ratio > size)
    throw ImageError(path + ": the header claims " + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + " pixels of " + std::to_string(spec.nchannels) +
                     " channels (" + bytes_text(stored) + " stored), more than its " +
                     std::to_string(size) + " bytes can hold: a corrupt or hostile file");
}

// OpenImageIO reads scan lines it must convert (half or 16-bit to float, or with per-channel
// formats) through one buffer of round_up(max(2^26 / scanline bytes, 256), rows per strip) rows,
// however few the image has (ImageInput::read_scanlines; 256 is its "read_chunk", the rows per
// strip TIFF's tag or 64): an EXR 1,048,592 pixels wide and one high took 2 GiB for 481 bytes, a
// TIFF 65,526 wide claiming 24,946 rows per strip 13 GB (tools/fuzz.sh image, fourth run).
// Refused when that buffer is over what the read may take (at least 256 MiB: a 16384-pixel row
// of 4 floats takes 64 MiB in 256 rows).
void check_read_chunk(const std::string& name, const OIIO::ImageSpec& spec, OIIO::TypeDesc to,
                      uint64_t max_bytes) {
  if (spec.tile_width > 0) return;                               // tiles are read one at a time
  if (to == spec.format && spec.channelformats.empty()) return;  // read in place
  const uint64_t scanline = std::max<uint64_t>(spec.scanline_bytes(/*native=*/true), 1);
  const uint64_t rps = uint64_t(std::max(spec.get_int_attribute("tiff:RowsPerStrip", 64), 1));
  const uint64_t rows = std::max<uint64_t>((uint64_t(1) << 26) / scanline, 256);
  const uint64_t buffer = saturating_mul((rows + rps - 1) / rps * rps, scanline);
  const uint64_t allowed = std::max(max_bytes, uint64_t(256) << 20);
  if (buffer > allowed)
    throw ImageError(name + ": the image is " + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + " pixels of " + bytes_text(scanline) +
                     " a row; OpenImageIO would decode it through a buffer of " +
                     bytes_text(buffer) + ", over the " + bytes_text(allowed) +
                     " this read may take");
}

// A header that claims more texels than the file's bytes can hold is refused before anything
// is allocated for them (a 69-byte PNG can claim 16384x16384). PNG only: its filtered rows
// (one filter byte each) are one deflate stream, so they are at most 1032 times the file. JPEG
// and the others have no such bound worth the name (a progressive JPEG's end-of-band runs
// cover any number of blocks); their size is checked against the budget alone.
void check_plausible(const OIIO::ImageInput& in, const unsigned char* data, size_t size,
                     const std::string& name, const std::string& claim) {
  // IHDR as stored (PNG specification 11.2.2), not as the reader expands it: a palette image's
  // rows hold one index of `depth` bits per pixel, though it is read as RGB.
  if (std::string(in.format_name()) != "png" || size < 26 || std::memcmp(data + 12, "IHDR", 4) != 0)
    return;
  auto be32 = [&](size_t at) {
    return uint64_t(data[at]) << 24 | uint64_t(data[at + 1]) << 16 | uint64_t(data[at + 2]) << 8 |
           uint64_t(data[at + 3]);
  };
  const uint64_t width = be32(16), height = be32(20), depth = data[24];
  const int colour = data[25];
  const uint64_t samples = colour == 2 ? 3 : colour == 4 ? 2 : colour == 6 ? 4 : 1;
  const uint64_t raw = height * (1 + (width * samples * depth + 7) / 8);
  if (raw / kDeflateMaxRatio > uint64_t(size))
    throw ImageError(name + ": the PNG header claims " + claim + " (" + bytes_text(raw) +
                     " of rows), more than its " + std::to_string(size) +
                     " bytes can hold (deflate expands at most 1032:1): a corrupt or "
                     "hostile file");
}

}  // namespace pb
