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

// The temporary name write_atomically gives `path`: ".NAME.tmpPID.EXT" beside it (EXT: path's
// extension, or `extension_if_none`).
std::string temporary_name(const std::string& path, const std::string& extension_if_none = "");

// Files to remove when the process dies at once (a second Ctrl-C): the temporaries being
// written and the lock files held. A fixed-size registry that a signal handler can read:
// register_cleanup copies `path` into a free slot (false when none is free or it is too long)
// and returns the slot in `slot`; unlink_registered_files() is async-signal-safe and unlinks
// every registered path.
bool register_cleanup(const std::string& path, int& slot);
void unregister_cleanup(int slot);
void unlink_registered_files() noexcept;

// Registers `path` for as long as it lives (no-op when the registry is full).
class CleanupGuard {
 public:
  explicit CleanupGuard(const std::string& path) { registered_ = register_cleanup(path, slot_); }
  ~CleanupGuard() {
    if (registered_) unregister_cleanup(slot_);
  }
  CleanupGuard(const CleanupGuard&) = delete;
  CleanupGuard& operator=(const CleanupGuard&) = delete;

 private:
  int slot_ = -1;
  bool registered_ = false;
};

// Removes ".NAME.tmpPID.EXT" files beside `path` (see temporary_name) that a process no longer
// alive left behind (a crash or a kill -9 while writing); returns how many.
int remove_stale_temporaries(const std::string& path, const std::string& extension_if_none = "");

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
