// The pieces container_check.cpp and container_jpeg.cpp share: bounded reads of a file's
// bytes and the checks of each format (container_check.h says what they refuse).
#pragma once

#include <cstdint>
#include <string>

#include "io/container_check.h"
#include "io/image_io.h"

namespace pb::container {

// Little- or big-endian unsigned integers of 1 to 8 bytes.
inline uint64_t load(const unsigned char* p, int bytes, bool big_endian) {
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
  const std::string& name() const { return name_; }
  [[noreturn]] void refuse(const std::string& what) const {
    throw ImageError(name_ + ": " + what + ": a corrupt or hostile file");
  }

 private:
  const ByteReader& read_;
  uint64_t size_;
  const std::string& name_;
};

// A JPEG (ITU T.81) whose frame header claims more than `max_texels` texels, or whose decoding
// holds every coefficient of the image (progressive, or a first scan without every component)
// in more than max(`max_bytes`, 256 MiB).
void check_jpeg(const Bytes& b, uint64_t max_texels, uint64_t max_bytes);

}  // namespace pb::container
