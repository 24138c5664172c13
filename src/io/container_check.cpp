#include "io/container_check.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <set>
#include <vector>

#include "io/image_io.h"
#include "io/jpeg_header.h"
#include "util/memory.h"

namespace pb {

namespace {

// Little- or big-endian unsigned integers of 1 to 8 bytes.
uint64_t load(const unsigned char* p, int bytes, bool big_endian) {
  uint64_t v = 0;
  for (int k = 0; k < bytes; ++k) v |= uint64_t(p[big_endian ? bytes - 1 - k : k]) << (8 * k);
  return v;
}

// Pieces of the file read through a ByteReader, each checked to lie inside it.
class Bytes {
 public:
  Bytes(const ByteReader& read, uint64_t size, const std::string& name)
      : read_(read), size_(size), name_(name) {}
  uint64_t size() const { return size_; }
  bool holds(uint64_t offset, uint64_t n) const { return offset <= size_ && n <= size_ - offset; }
  // Unsigned integer of `bytes` bytes at `offset`; false past the end.
  bool uint(uint64_t offset, int bytes, bool big_endian, uint64_t& v) const {
    unsigned char b[8];
    if (!holds(offset, uint64_t(bytes)) || !read_(offset, uint64_t(bytes), b)) return false;
    v = load(b, bytes, big_endian);
    return true;
  }
  bool get(uint64_t offset, uint64_t n, unsigned char* out) const {
    return holds(offset, n) && read_(offset, n, out);
  }
  [[noreturn]] void refuse(const std::string& what) const {
    throw ImageError(name_ + ": " + what + ": a corrupt or hostile file");
  }

 private:
  const ByteReader& read_;
  uint64_t size_;
  const std::string& name_;
};

// ---- OpenEXR (the "OpenEXR File Layout" document: magic, version, headers, offset tables) ----

// Scan lines in one chunk, by compression (ImfCompression.h's order); 256 (DWAB's, the most)
// for a code OpenEXR does not know, which OpenEXR refuses itself.
uint64_t exr_lines_per_chunk(unsigned code) {
  static const uint64_t lines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  return code < 10 ? lines[code] : 256;
}

// The bytes OpenEXR reads for a value of a type whose length is fixed (ImfStandardAttributes,
// the Typed attributes' readValueFrom); 0 for the others.
uint64_t exr_fixed_size(const std::string& type) {
  // clang-format off
  static const std::pair<const char*, uint64_t> sizes[] = {
      {"box2i", 16},  {"box2f", 16},    {"int", 4},           {"float", 4},
      {"double", 8},  {"compression", 1}, {"lineOrder", 1},   {"envmap", 1},
      {"v2i", 8},     {"v2f", 8},       {"v2d", 16},          {"v3i", 12},
      {"v3f", 12},    {"v3d", 24},      {"m33f", 36},         {"m33d", 72},
      {"m44f", 64},   {"m44d", 128},    {"tiledesc", 9},      {"rational", 8},
      {"keycode", 28}, {"timecode", 8}, {"chromaticities", 32}, {"deepImageState", 1}};
  // clang-format on
  for (const auto& [name, size] : sizes)
    if (type == name) return size;
  return 0;
}

// OpenEXR reads a value of a known type by what the type says, not by the size the attribute
// declares (a channel list up to its empty name, a box as 16 bytes), and goes on reading the
// header from where that ends: a file whose declared size differs would be read one way here
// and another way there (the fuzzer's second run found two such, each then allocating 1.9 GB
// for a string this walk never saw). So the declared size must be what the type reads.
// Returns, for a channel list, the bytes of one pixel of all its channels (UINT and FLOAT 4,
// HALF 2); 0 for other types.
uint64_t check_exr_value(const Bytes& b, const std::string& name, const std::string& type,
                         uint64_t at, uint64_t size, uint64_t max_name) {
  auto mismatch = [&](uint64_t reads) {
    b.refuse("EXR attribute '" + name + "' of type " + type + " declares " + std::to_string(size) +
             " bytes where its value reads " + std::to_string(reads));
  };
  if (const uint64_t fixed = exr_fixed_size(type)) {
    if (size != fixed) mismatch(fixed);
  } else if (type == "chlist") {
    // Channels: a name (up to max_name bytes and a null), then the pixel type (int: 0 UINT,
    // 1 HALF, 2 FLOAT) and 12 bytes more; an empty name ends it.
    uint64_t p = at, pixel_bytes = 0;
    for (;;) {
      uint64_t k = 0;
      unsigned char c = 1;
      for (; k <= max_name && b.get(p + k, 1, &c) && c != 0; ++k) {
      }
      if (c != 0) b.refuse("EXR attribute '" + name + "' holds a channel name that does not end");
      p += k + 1;
      if (k == 0) break;
      uint64_t pixel_type = 2;
      b.uint(p, 4, false, pixel_type);
      pixel_bytes += pixel_type == 1 ? 2 : 4;
      p += 16;
      if (p > at + size) break;
    }
    if (p - at != size) mismatch(p - at);
    return pixel_bytes;
  } else if (type == "preview") {
    // Width and height, then 4 bytes per pixel: OpenEXR allocates them from the two ints.
    uint64_t w = 0, h = 0;
    if (size < 8 || !b.uint(at, 4, false, w) || !b.uint(at + 4, 4, false, h) ||
        saturating_add(8, saturating_mul(saturating_mul(w, h), 4)) != size)
      mismatch(8 + 4 * w * h);
  }
  return 0;
}

void check_exr(const Bytes& b, uint64_t max_texels, uint64_t max_bytes) {
  uint64_t version = 0;
  if (!b.uint(4, 4, false, version)) b.refuse("the EXR file ends inside its version field");
  const bool long_names = version & 0x400, multipart = version & 0x1000;
  const bool single_tiled = version & 0x200;
  const uint64_t max_name = long_names ? 255 : 31;  // bytes, before the terminating null
  // A name or type name: up to max_name bytes and a null; the offset after it.
  auto text = [&](uint64_t at, std::string& out) {
    out.clear();
    for (uint64_t k = 0;; ++k) {
      unsigned char c;
      if (!b.get(at + k, 1, &c)) b.refuse("the EXR header ends inside an attribute name");
      if (c == 0) return at + k + 1;
      if (k == max_name)
        b.refuse("an EXR attribute name is longer than " + std::to_string(max_name) + " bytes");
      out.push_back(c >= 0x20 && c < 0x7f ? char(c) : '?');  // it may be quoted in a message
    }
  };
  uint64_t at = 8, chunks = 0;
  for (int part = 0;; ++part) {
    unsigned char first;
    if (!b.get(at, 1, &first)) b.refuse("the EXR file ends inside its header");
    if (first == 0 && part > 0) {  // the empty header that ends a multi-part file's headers
      ++at;
      break;
    }
    int64_t window[4] = {0, 0, -1, -1};
    bool has_window = false, tiled = single_tiled;
    unsigned compression = 0;
    uint64_t tile_x = 0, tile_y = 0, chunk_count = 0, pixel_bytes = 0;
    bool has_chunk_count = false;
    std::string name, type;
    for (;;) {
      at = text(at, name);
      if (name.empty()) break;
      at = text(at, type);
      uint64_t size = 0;
      if (!b.uint(at, 4, false, size)) b.refuse("the EXR header ends inside attribute " + name);
      at += 4;
      if (size > 0x7fffffff || !b.holds(at, size))
        b.refuse("EXR attribute '" + name + "' claims " + bytes_text(size) + ", more than the " +
                 std::to_string(b.size() - std::min(at, b.size())) + " bytes after it");
      const uint64_t channel_bytes = check_exr_value(b, name, type, at, size, max_name);
      if (name == "channels") pixel_bytes = channel_bytes;
      uint64_t v = 0;
      if (name == "dataWindow" && type == "box2i" && size == 16) {
        for (int k = 0; k < 4; ++k) {
          b.uint(at + 4 * uint64_t(k), 4, false, v);
          window[k] = int64_t(int32_t(uint32_t(v)));
        }
        has_window = true;
      } else if (name == "compression" && type == "compression" && size == 1) {
        b.uint(at, 1, false, v);
        compression = unsigned(v);
      } else if (name == "tiles" && type == "tiledesc" && size == 9) {
        b.uint(at, 4, false, tile_x);
        b.uint(at + 4, 4, false, tile_y);
        tiled = true;
      } else if (name == "chunkCount" && type == "int" && size == 4) {
        b.uint(at, 4, false, chunk_count);
        has_chunk_count = true;
      } else if (name == "type" && type == "string") {
        std::string kind(size_t(std::min<uint64_t>(size, 16)), '\0');
        b.get(at, kind.size(), reinterpret_cast<unsigned char*>(kind.data()));
        tiled = kind == "tiledimage" || kind == "deeptile";
      }
      at += size;
    }
    if (has_window) {
      const int64_t w = window[2] - window[0] + 1, h = window[3] - window[1] + 1;
      if (w < 1 || h < 1)
        b.refuse("the EXR data window is empty or inverted (" + std::to_string(w) + "x" +
                 std::to_string(h) + ")");
      if (uint64_t(w) * uint64_t(h) > max_texels)  // each below 2^32: no overflow
        b.refuse("the EXR data window is " + std::to_string(w) + "x" + std::to_string(h) +
                 " pixels, over the " + std::to_string(max_texels) + " this read allows");
      // Every chunk has an 8-byte entry in the offset table after the headers: the chunks of
      // level 0 alone are a lower bound on the table's length. And OpenEXR allocates the
      // buffers of one whole chunk (every line of it, however few the image has) when it
      // opens the file: 6 million pixels wide and 1 high, in 32-line chunks, 3 GB for a file
      // of 490 bytes (the fuzzer's third run). That must fit in what the read may take.
      uint64_t n, chunk_pixels;
      if (tiled) {
        if (tile_x == 0 || tile_y == 0) b.refuse("an EXR tile size is 0");
        n = ((uint64_t(w) + tile_x - 1) / tile_x) * ((uint64_t(h) + tile_y - 1) / tile_y);
        chunk_pixels = saturating_mul(tile_x, tile_y);
      } else {
        const uint64_t lines = exr_lines_per_chunk(compression);
        n = (uint64_t(h) + lines - 1) / lines;
        chunk_pixels = uint64_t(w) * lines;
      }
      // At least 256 MiB (a 16384-pixel line of 4 floats in DWAB's 256-line chunks takes
      // 64 MiB), so that a small budget does not refuse a small image for its chunk's lines.
      const uint64_t chunk_bytes = saturating_mul(chunk_pixels, pixel_bytes);
      const uint64_t allowed = std::max(max_bytes, uint64_t(256) << 20);
      if (chunk_bytes > allowed)
        b.refuse("one EXR chunk of " + std::to_string(chunk_pixels) + " pixels takes " +
                 bytes_text(chunk_bytes) + " to decode, over the " + bytes_text(allowed) +
                 " this read may take");
      chunks = saturating_add(chunks, n);
    }
    if (has_chunk_count) chunks = saturating_add(chunks, chunk_count);
    if (!multipart) break;  // one header, ended by the null `text` read
  }
  if (!b.holds(at, saturating_mul(chunks, 8)))
    b.refuse("the EXR header needs an offset table of " + std::to_string(chunks) +
             " chunks, more than the file's " + std::to_string(b.size()) + " bytes hold");
}

// ---- TIFF (TIFF 6.0 section 2; BigTIFF: 8-byte counts and offsets) ----

uint64_t tiff_type_size(uint64_t type) {
  // By type code: 1 BYTE, 2 ASCII, 3 SHORT, 4 LONG, 5 RATIONAL, 6 SBYTE, 7 UNDEFINED, 8 SSHORT,
  // 9 SLONG, 10 SRATIONAL, 11 FLOAT, 12 DOUBLE, 13 IFD, 16 LONG8, 17 SLONG8, 18 IFD8; 0 for a
  // code libtiff does not know, whose entry it skips.
  static const uint8_t sizes[] = {0, 1, 1, 2, 4, 8, 1, 1, 2, 4, 8, 4, 8, 4, 0, 0, 8, 8, 8};
  return type < sizeof sizes ? sizes[type] : 0;
}

void check_tiff(const Bytes& b, bool big_endian, uint64_t max_texels) {
  uint64_t magic = 0;
  b.uint(2, 2, big_endian, magic);
  const bool big = magic == 43;
  const int word = big ? 8 : 4;  // offsets, counts and inline values
  const uint64_t entry = big ? 20 : 12, count_bytes = big ? 8 : 2;
  uint64_t ifd = 0;
  if (!b.uint(big ? 8 : 4, word, big_endian, ifd)) b.refuse("the TIFF file ends in its header");
  std::set<uint64_t> seen;
  for (int index = 0; ifd != 0 && index < 1024; ++index) {
    if (!seen.insert(ifd).second) break;  // a loop of directories: libtiff stops there too
    uint64_t n = 0;
    if (!b.uint(ifd, int(count_bytes), big_endian, n) ||
        !b.holds(ifd + count_bytes, saturating_add(saturating_mul(n, entry), uint64_t(word))))
      b.refuse("TIFF directory " + std::to_string(index) + " lies past the end of the file");
    uint64_t width = 0, height = 0, samples = 1;
    uint64_t offsets_at = 0, offsets_n = 0, offsets_type = 0;
    uint64_t counts_at = 0, counts_n = 0, counts_type = 0;
    for (uint64_t k = 0; k < n; ++k) {
      const uint64_t e = ifd + count_bytes + k * entry;
      uint64_t tag = 0, type = 0, count = 0, value = 0;
      b.uint(e, 2, big_endian, tag);
      b.uint(e + 2, 2, big_endian, type);
      b.uint(e + 4, word, big_endian, count);
      const uint64_t field = e + 4 + uint64_t(word);  // the value, or the offset of the values
      const uint64_t unit = tiff_type_size(type);
      if (unit == 0) continue;
      const uint64_t bytes = saturating_mul(count, unit);
      uint64_t data = field;
      if (bytes > uint64_t(word)) {
        b.uint(field, word, big_endian, data);
        if (!b.holds(data, bytes))
          b.refuse("TIFF tag " + std::to_string(tag) + " claims " + bytes_text(bytes) +
                   " at offset " + std::to_string(data) + ", past the end of the file's " +
                   std::to_string(b.size()) + " bytes");
      }
      if (count == 1 && (type == 3 || type == 4 || type == 16))
        b.uint(field, int(unit), big_endian, value);
      if (tag == 256) width = value;
      if (tag == 257) height = value;
      if (tag == 277) samples = std::max<uint64_t>(value, 1);
      if (tag == 273 || tag == 324) offsets_at = data, offsets_n = count, offsets_type = type;
      if (tag == 279 || tag == 325) counts_at = data, counts_n = count, counts_type = type;
    }
    if (index == 0) {
      const uint64_t texels = saturating_mul(width, height);
      if (texels > max_texels || saturating_mul(texels, samples) > saturating_mul(max_texels, 4))
        b.refuse("the TIFF header claims " + std::to_string(width) + "x" + std::to_string(height) +
                 " pixels of " + std::to_string(samples) + " samples, over the " +
                 std::to_string(max_texels) + " texels this read allows");
    }
    // Each strip or tile lies inside the file (read only for tables of a sane length: a valid
    // file's table is inside it, which the loop above checked).
    const uint64_t strips = std::min(offsets_n, counts_n);
    const uint64_t ou = tiff_type_size(offsets_type), cu = tiff_type_size(counts_type);
    if (strips > 0 && strips <= (uint64_t(1) << 20) && (ou == 2 || ou == 4 || ou == 8) &&
        (cu == 2 || cu == 4 || cu == 8)) {
      std::vector<unsigned char> o(size_t(strips * ou)), c(size_t(strips * cu));
      if (b.get(offsets_at, o.size(), o.data()) && b.get(counts_at, c.size(), c.data()))
        for (uint64_t s = 0; s < strips; ++s) {
          const uint64_t off = load(&o[size_t(s * ou)], int(ou), big_endian);
          const uint64_t len = load(&c[size_t(s * cu)], int(cu), big_endian);
          if (!b.holds(off, len))
            b.refuse("TIFF strip or tile " + std::to_string(s) + " claims " + bytes_text(len) +
                     " at offset " + std::to_string(off) + ", past the end of the file's " +
                     std::to_string(b.size()) + " bytes");
        }
    }
    uint64_t next = 0;
    b.uint(ifd + count_bytes + n * entry, word, big_endian, next);
    ifd = next;
  }
}

}  // namespace

void check_container(const ByteReader& read, uint64_t size, const std::string& name,
                     uint64_t max_texels, uint64_t max_bytes) {
  const Bytes b(read, size, name);
  unsigned char head[4];
  if (!b.get(0, 4, head)) return;
  if (std::memcmp(head, "\x76\x2f\x31\x01", 4) == 0) check_exr(b, max_texels, max_bytes);
  const bool le = std::memcmp(head, "II", 2) == 0, be = std::memcmp(head, "MM", 2) == 0;
  if (le || be) {
    uint64_t magic = 0;
    b.uint(2, 2, be, magic);
    if (magic == 42 || magic == 43) check_tiff(b, be, max_texels);
  }
  if (head[0] == 0xff && head[1] == 0xd8) {
    // libjpeg reads the header from bytes in memory: the first 16 MiB hold it in any real file
    // (its markers before the first scan are tables and APPn segments of at most 64 KiB).
    std::vector<unsigned char> start(size_t(std::min<uint64_t>(size, uint64_t(16) << 20)));
    if (!b.get(0, start.size(), start.data())) return;
    check_jpeg(start.data(), start.size(), start.size() < size, name, max_texels, max_bytes);
  }
}

void check_container(const unsigned char* data, uint64_t size, const std::string& name,
                     uint64_t max_texels, uint64_t max_bytes) {
  if (size >= 2 && data[0] == 0xff && data[1] == 0xd8) {  // in memory already: no copy
    check_jpeg(data, size_t(size), false, name, max_texels, max_bytes);
    return;
  }
  const ByteReader read = [&](uint64_t offset, uint64_t n, unsigned char* out) {
    if (offset > size || n > size - offset) return false;
    if (n) std::memcpy(out, data + offset, size_t(n));
    return true;
  };
  check_container(read, size, name, max_texels, max_bytes);
}

void check_container_file(const std::string& path, uint64_t max_texels, uint64_t max_bytes) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return;
  f.seekg(0, std::ios::end);
  const std::streamoff end = f.tellg();
  if (end <= 0) return;
  const ByteReader read = [&](uint64_t offset, uint64_t n, unsigned char* out) {
    f.clear();
    f.seekg(std::streamoff(offset));
    f.read(reinterpret_cast<char*>(out), std::streamsize(n));
    return f.good() || uint64_t(f.gcount()) == n;
  };
  check_container(read, uint64_t(end), path, max_texels, max_bytes);
}

}  // namespace pb
