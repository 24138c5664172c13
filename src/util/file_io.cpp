#include "util/file_io.h"

#include "util/rng.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace pb {

namespace {

// ".NAME.tmpPID.EXT" beside `path`: hidden, unique to this process, with path's extension.
std::string temporary_name(const std::string& path, const std::string& extension_if_none = "") {
  const std::filesystem::path p(path);
  std::string name = ".";  // appended piecewise: GCC 12 misreports operator+ chains (-Wrestrict)
  name.append(p.stem().string()).append(".tmp").append(std::to_string(::getpid()));
  name.append(p.extension().empty() ? extension_if_none : p.extension().string());
  return (p.parent_path() / name).string();
}

std::string errno_text() { return std::strerror(errno); }

void fsync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write,
                      const std::string& extension_if_none) {
  const std::string tmp = temporary_name(path, extension_if_none);
  try {
    write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  // The data must be on disk before the rename makes it the file of record (checkpoints must
  // survive a crash), then the rename itself is made durable.
  const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const std::string err = errno_text();
    if (fd >= 0) ::close(fd);
    std::remove(tmp.c_str());
    throw FileError(path + ": cannot flush to disk (" + err + ")");
  }
  ::close(fd);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string err = errno_text();
    std::remove(tmp.c_str());
    throw FileError(path + ": cannot rename into place (" + err + ")");
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  fsync_path(parent.empty() ? "." : parent.string(), O_RDONLY | O_DIRECTORY);
}

void check_writable(const std::string& path) {
  if (std::filesystem::is_directory(path)) throw FileError(path + ": is a directory");
  const std::string tmp = temporary_name(path);
  std::ofstream f(tmp, std::ios::binary);
  if (!f) throw FileError(path + ": cannot write here (" + errno_text() + ")");
  f.close();
  std::remove(tmp.c_str());
}

Checksum::Checksum(uint64_t total_size) {
  for (uint64_t j = 0; j < 4; ++j) lane_[j] = 0x6a09e667f3bcc909ULL ^ total_size ^ (j << 56);
}

void Checksum::add(const void* data, size_t n) {
  if (n == 0) return;  // an empty piece's data() may be null, which memcpy may not take
  const char* p = static_cast<const char*>(data);
  if (fill_ > 0) {  // complete the word a previous piece left open
    const size_t take = std::min(n, 8 - fill_);
    std::memcpy(buf_ + fill_, p, take);
    fill_ += take;
    p += take;
    n -= take;
    if (fill_ < 8) return;
    word(buf_);
    fill_ = 0;
  }
  for (; n >= 8 && (k_ & 3) != 0; p += 8, n -= 8) word(p);
  for (; n >= 32; p += 32, n -= 32) {  // one word per lane, independent chains
    for (uint64_t j = 0; j < 4; ++j) {
      uint64_t w;
      std::memcpy(&w, p + 8 * j, 8);
      lane_[j] = mix64(lane_[j] ^ (w + 8 * (k_ + j)));
    }
    k_ += 4;
  }
  for (; n >= 8; p += 8, n -= 8) word(p);
  std::memcpy(buf_, p, n);
  fill_ = n;
}

uint64_t Checksum::finish() const {
  uint64_t tail = 0;
  std::memcpy(&tail, buf_, fill_);
  uint64_t h = mix64(lane_[0] ^ tail ^ 0x5bd1e995ULL);
  for (int j = 1; j < 4; ++j) h = mix64(h ^ lane_[j]);
  return h;
}

void Checksum::word(const char* p) {
  uint64_t w;
  std::memcpy(&w, p, 8);
  uint64_t& h = lane_[k_ & 3];
  h = mix64(h ^ (w + 8 * k_));
  ++k_;
}

}  // namespace pb
