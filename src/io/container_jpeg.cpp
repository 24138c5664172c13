// The JPEG walk of check_container (container_bytes.h): the frame header's size and, for the
// images libjpeg decodes through a buffer of every coefficient, that buffer, before libjpeg
// allocates it. OpenImageIO's JPEG reader calls jpeg_start_decompress when it opens a file,
// and libjpeg allocates there, for a progressive image or one whose first scan lacks a
// component, 64 coefficients of 2 bytes for every 8x8 block of every component (jdcoefct.c,
// "full-image" buffer): a 387-byte progressive JPEG claiming 65296x65496 made it take 9.6 GB
// (tools/fuzz.sh image).
#include <algorithm>
#include <cstring>
#include <vector>

#include "io/container_bytes.h"
#include "util/memory.h"

namespace pb::container {

void check_jpeg(const Bytes& b, uint64_t max_texels, uint64_t max_bytes) {
  struct Component {
    uint64_t h, v;  // sampling factors, 1 to 4
  };
  std::vector<Component> components;
  uint64_t width = 0, height = 0;
  bool progressive = false, all_coefficients = false;
  // Markers (T.81 B.1.1.2): 0xFF, any number of fill 0xFF, a code; SOI, EOI, RSTn and TEM
  // stand alone, the others carry a big-endian length that counts itself. libjpeg's
  // jpeg_read_header reads up to the first scan header (SOS), where it decides; it skips
  // bytes that are not a marker where one should be (jdmarker.c next_marker, with a warning),
  // and so does this walk.
  for (uint64_t at = 2;;) {
    unsigned char m[2];
    if (!b.get(at, 2, m)) return;
    const unsigned code = m[1];
    if (m[0] != 0xff) {  // to the next 0xFF, a block at a time
      unsigned char block[4096];
      const uint64_t n = std::min<uint64_t>(sizeof block, b.size() - at);
      if (!b.get(at, n, block)) return;
      const void* next = std::memchr(block, 0xff, size_t(n));
      at += next ? uint64_t(static_cast<const unsigned char*>(next) - block) : n;
      continue;
    }
    if (code == 0xff || code == 0x00) {
      ++at;
      continue;
    }
    if (code == 0x01 || (code >= 0xd0 && code <= 0xd8)) {
      at += 2;
      continue;
    }
    uint64_t length = 0;
    if (code == 0xd9 || !b.uint(at + 2, 2, true, length) || length < 2) return;
    // SOF0-SOF15 but DHT (C4), JPG (C8) and DAC (CC): P, Y, X, Nf, then Ci, Hi:Vi, Tqi.
    const bool frame = code >= 0xc0 && code <= 0xcf && code != 0xc4 && code != 0xc8 && code != 0xcc;
    if (frame && components.empty()) {
      uint64_t count = 0;
      if (!b.uint(at + 5, 2, true, height) || !b.uint(at + 7, 2, true, width) ||
          !b.uint(at + 9, 1, true, count))
        return;
      progressive = code == 0xc2 || code == 0xc6 || code == 0xca || code == 0xce;
      for (uint64_t k = 0; k < count; ++k) {
        uint64_t hv = 0;
        if (!b.uint(at + 11 + 3 * k, 1, true, hv)) return;
        if (hv >> 4 < 1 || hv >> 4 > 4 || (hv & 15) < 1 || (hv & 15) > 4) return;
        components.push_back({hv >> 4, hv & 15});
      }
    }
    if (code == 0xda) {  // SOS: Ns, the components of the first scan
      uint64_t in_scan = 0;
      if (components.empty() || !b.uint(at + 4, 1, true, in_scan)) return;
      all_coefficients = progressive || in_scan < components.size();
      break;
    }
    at += 2 + length;
  }
  if (width == 0 || height == 0) return;  // libjpeg refuses (no DNL support)
  const std::string claim = std::to_string(width) + "x" + std::to_string(height);
  if (width * height > max_texels)
    throw ImageError(b.name() + ": the JPEG's frame header claims " + claim + ", over the " +
                     std::to_string(max_texels) + " texels this read allows");
  if (!all_coefficients) return;
  // jdinput.c initial_setup and jdcoefct.c: each component's blocks, rounded up to whole
  // sampling factors, 128 bytes each. A decoder's own buffer, like an EXR chunk's, may take at
  // least 256 MiB (a 2^28-texel 4:2:0 image needs 768 MiB; the texels are checked apart, against
  // the budget itself), so that a small budget does not refuse a small image for it.
  uint64_t hmax = 1, vmax = 1;
  for (const Component& c : components) {
    hmax = std::max(hmax, c.h);
    vmax = std::max(vmax, c.v);
  }
  uint64_t blocks = 0;
  for (const Component& c : components) {
    const uint64_t across = (width * c.h + 8 * hmax - 1) / (8 * hmax);
    const uint64_t down = (height * c.v + 8 * vmax - 1) / (8 * vmax);
    blocks += (across + c.h - 1) / c.h * c.h * ((down + c.v - 1) / c.v * c.v);
  }
  const uint64_t coefficients = blocks * 128;
  const uint64_t allowed = std::max(max_bytes, uint64_t(256) << 20);
  if (coefficients > allowed)
    throw ImageTooLarge(b.name() + ": the image is a " + claim + " JPEG whose decoding holds " +
                            bytes_text(coefficients) + " of coefficients, over the " +
                            bytes_text(allowed) + " this read may take",
                        coefficients);
}

}  // namespace pb::container
