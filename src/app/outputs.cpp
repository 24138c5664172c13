#include "app/outputs.h"

#include "options/options.h"
#include "util/file_io.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <thread>

namespace pb {

namespace fs = std::filesystem;

namespace {

// A path's identity: where it resolves to, and its device and inode when it exists (a hard
// link resolves elsewhere but is the same file).
struct Identity {
  fs::path resolved;
  bool exists = false;
  dev_t dev = 0;
  ino_t ino = 0;
};

Identity identify(const std::string& path) {
  Identity id;
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  id.resolved = fs::weakly_canonical(absolute, ec);
  if (ec) id.resolved = absolute.lexically_normal();
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.dev = st.st_dev;
    id.ino = st.st_ino;
  }
  return id;
}

bool same_file(const Identity& a, const Identity& b) {
  return a.resolved == b.resolved || (a.exists && b.exists && a.dev == b.dev && a.ino == b.ino);
}

std::string kind_of(fs::file_type t) {
  switch (t) {
    case fs::file_type::directory:
      return "a directory";
    case fs::file_type::block:
    case fs::file_type::character:
      return "a device";
    case fs::file_type::fifo:
      return "a fifo";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

// The pid a lock file holds, read while its holder may still be writing it.
std::string holder_pid(int fd) {
  for (int attempt = 0; attempt < 20; ++attempt) {
    char buf[32] = {};
    const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
    if (n > 0 && buf[n - 1] == '\n') {
      buf[n - 1] = '\0';
      return buf;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return "unknown";
}

}  // namespace

void check_distinct(const std::vector<NamedFile>& outputs, const std::vector<NamedFile>& inputs) {
  std::vector<Identity> in_ids, out_ids;
  for (const NamedFile& f : inputs) in_ids.push_back(identify(f.path));
  for (size_t k = 0; k < outputs.size(); ++k) {
    const NamedFile& out = outputs[k];
    const Identity id = identify(out.path);
    const std::string head = out.role + " " + out.path + " is ";
    for (size_t j = 0; j < inputs.size(); ++j)
      if (same_file(id, in_ids[j]))
        throw UsageError(
            head + inputs[j].role +
            (inputs[j].path == out.path ? "" : " " + inputs[j].path + " (the same file)") +
            ": choose another path");
    for (size_t j = 0; j < k; ++j)
      if (same_file(id, out_ids[j]))
        throw UsageError(
            head + "the path of " + outputs[j].role +
            (outputs[j].path == out.path ? "" : " " + outputs[j].path + " (the same file)") +
            ": choose another path");
    out_ids.push_back(id);
  }
}

void check_output_path(const NamedFile& output) {
  const std::string& path = output.path;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);  // follows a symbolic link
  if (fs::exists(st) && !fs::is_regular_file(st))
    throw FileError(path + ": is " + kind_of(st.type()) + ", not a regular file: " + output.role +
                    " must name a file to write (it is never replaced)");
  const fs::path parent = fs::path(path).parent_path();
  const std::string folder = parent.empty() ? "." : parent.string();
  if (!fs::is_directory(folder, ec))
    throw FileError(path + ": the folder " + folder +
                    (fs::exists(folder, ec) ? " is not a directory" : " does not exist"));
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw FileError(path + ": cannot write in the folder " + folder + " (" + std::strerror(errno) +
                    ")");
  check_writable(path);  // creating a file there really works (a read-only mount says no)
}

std::string lock_path(const std::string& output) { return output + ".lock"; }

struct OutputLock::Held {
  std::string path;
  int fd = -1;
  int slot = -1;
  bool registered = false;
  ~Held() {
    if (fd < 0) return;
    ::unlink(path.c_str());  // while still holding it: a waiter then finds a new inode, and retries
    if (registered) unregister_cleanup(slot);
    ::close(fd);
  }
};

OutputLock::OutputLock(const std::vector<std::string>& paths) {
  for (const std::string& output : paths) {
    auto held = std::make_unique<Held>();
    held->path = lock_path(output);
    for (int attempt = 0;; ++attempt) {
      const int fd =
          ::open(held->path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
      if (fd < 0)
        throw FileError(output + ": cannot create its lock file " + held->path + " (" +
                        std::strerror(errno) + ")");
      struct stat opened {};
      if (::fstat(fd, &opened) != 0 || !S_ISREG(opened.st_mode)) {
        ::close(fd);
        throw FileError(output + ": its lock file " + held->path + " is not a regular file");
      }
      if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        const std::string pid = err == EWOULDBLOCK ? holder_pid(fd) : "";
        ::close(fd);
        if (err == EWOULDBLOCK)
          throw FileError(output + ": another photonbound render is writing it (pid " + pid + ")");
        throw FileError(output + ": cannot lock " + held->path + " (" + std::strerror(err) + ")");
      }
      // The holder before us may have removed the file between our open and our lock: then
      // this lock is on a file no one else will find; start again on the path's file.
      struct stat now {};
      if (::stat(held->path.c_str(), &now) != 0 || now.st_dev != opened.st_dev ||
          now.st_ino != opened.st_ino) {
        ::close(fd);
        if (attempt < 100) continue;
        throw FileError(output + ": cannot lock " + held->path + " (it keeps being replaced)");
      }
      held->fd = fd;
      break;
    }
    held->registered = register_cleanup(held->path, held->slot);
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(held->fd, 0) != 0 ||
        ::pwrite(held->fd, pid.data(), pid.size(), 0) != ssize_t(pid.size()))
      throw FileError(output + ": cannot write its lock file " + held->path + " (" +
                      std::strerror(errno) + ")");
    held_.push_back(std::move(held));
  }
}

OutputLock::~OutputLock() {
  while (!held_.empty()) held_.pop_back();
}

}  // namespace pb
