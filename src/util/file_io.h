// Files written whole or not at all, and the checksum the state file and the scene identity use.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>

namespace pb {

// A file that cannot be created, written, flushed or renamed; the message names it.
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Creates `path` atomically and durably: `write` fills a temporary file beside it (the name it
// is given keeps path's extension, or takes `extension_if_none`, for writers that choose a
// format by it), which is then
// fsynced, renamed over `path`, and the folder fsynced. A reader never sees a partial file. On
// any failure the temporary is removed; the helper's own failures throw FileError naming `path`,
// and what `write` throws is rethrown.
void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write,
                      const std::string& extension_if_none = "");

// Fails early (FileError) when `path` cannot be created, before any rendering starts.
void check_writable(const std::string& path);

// 64-bit checksum over 8-byte words: SplitMix64 mixing of each word with its byte position, in
// four independent lanes (word k goes to lane k mod 4) so that consecutive words do not wait
// for each other's mixing: one chain ran at ~1.6 GB/s, four at ~4 on this machine, and a
// checkpoint sums every point state. The bytes may arrive in pieces of any size.
class Checksum {
 public:
  explicit Checksum(uint64_t total_size);
  void add(const void* data, size_t n);
  uint64_t finish() const;

 private:
  void word(const char* p);
  uint64_t lane_[4];
  uint64_t k_ = 0;  // words so far
  char buf_[8] = {};
  size_t fill_ = 0;
};

inline uint64_t checksum(const void* data, size_t size) {
  Checksum c(size);
  c.add(data, size);
  return c.finish();
}

}  // namespace pb
