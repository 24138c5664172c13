#include "util/file_io.h"

#include "util/rng.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace pb {

namespace {

// The registry of files a dying process removes (register_cleanup): a slot is free (0), being
// filled (1) or holds a path (2); the handler reads only slots in state 2.
constexpr int kCleanupSlots = 16;
constexpr size_t kCleanupPathMax = 4096;
struct CleanupSlot {
  std::atomic<int> state{0};
  char path[kCleanupPathMax];
};
CleanupSlot g_cleanup[kCleanupSlots];
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads these");

std::string errno_text() { return std::strerror(errno); }

void fsync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

// ".NAME.tmpPID.EXT" beside `path`: hidden, unique to this process, with path's extension.
std::string temporary_name(const std::string& path, const std::string& extension_if_none) {
  const std::filesystem::path p(path);
  std::string name = ".";  // appended piecewise: GCC 12 misreports operator+ chains (-Wrestrict)
  name.append(p.stem().string()).append(".tmp").append(std::to_string(::getpid()));
  name.append(p.extension().empty() ? extension_if_none : p.extension().string());
  return (p.parent_path() / name).string();
}

bool register_cleanup(const std::string& path, int& slot) {
  if (path.size() >= kCleanupPathMax) return false;
  for (int k = 0; k < kCleanupSlots; ++k) {
    int free = 0;
    if (!g_cleanup[k].state.compare_exchange_strong(free, 1)) continue;
    std::memcpy(g_cleanup[k].path, path.c_str(), path.size() + 1);
    g_cleanup[k].state.store(2, std::memory_order_release);
    slot = k;
    return true;
  }
  return false;
}

void unregister_cleanup(int slot) {
  if (slot >= 0 && slot < kCleanupSlots) g_cleanup[slot].state.store(0, std::memory_order_release);
}

void unlink_registered_files() noexcept {
  for (CleanupSlot& s : g_cleanup)
    if (s.state.load(std::memory_order_acquire) == 2) ::unlink(s.path);
}

int remove_stale_temporaries(const std::string& path, const std::string& extension_if_none) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const std::string prefix = "." + p.stem().string() + ".tmp";
  const std::string ext = p.extension().empty() ? extension_if_none : p.extension().string();
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() + ext.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
      continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - ext.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = pid_t(std::stol(digits));
    std::error_code sec;
    if (pid <= 0 || pid == ::getpid() || !it->is_regular_file(sec)) continue;
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to judge)
    if (fs::remove(it->path(), sec)) ++removed;
  }
  return removed;
}

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write,
                      const std::string& extension_if_none) {
  const std::string tmp = temporary_name(path, extension_if_none);
  const CleanupGuard cleanup(tmp);  // a second Ctrl-C while writing removes it
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
  const CleanupGuard cleanup(tmp);
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
