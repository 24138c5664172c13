// Which files a scene may read; see gltf_files.h.
#include "gltf/gltf_files.h"

#include "scene/scene.h"
#include "util/memory.h"
#include "util/message_text.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstring>

namespace pb::gltf {

namespace fs = std::filesystem;

namespace {

// Component by component, so that /a/bc is not inside /a/b.
bool within(const fs::path& p, const fs::path& root) {
  auto q = p.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++q)
    if (q == p.end() || *q != *r) return false;
  return true;
}

// RFC 3986 "scheme:": a letter, then letters, digits, '+', '-' or '.', before any '/'.
bool has_scheme(const std::string& name) {
  const size_t colon = name.find(':');
  if (colon == std::string::npos || colon == 0 || name.find('/') < colon) return false;
  if (!std::isalpha(static_cast<unsigned char>(name[0]))) return false;
  for (size_t i = 1; i < colon; ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (!std::isalnum(c) && c != '+' && c != '-' && c != '.') return false;
  }
  return true;
}

const char* type_of(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory, not a file";
  if (S_ISFIFO(mode)) return "is a named pipe, not a regular file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "is a device, not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  return "is not a regular file";
}

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

AssetFiles::AssetFiles(const std::string& scene_path, const std::vector<std::string>& asset_dirs,
                       uint64_t max_bytes, uint64_t scene_bytes)
    : max_bytes_(max_bytes), read_bytes_(std::min(scene_bytes, max_bytes)) {
  std::error_code ec;
  fs::path dir = fs::path(scene_path).parent_path();
  if (dir.empty()) dir = ".";
  // weakly: load_gltf_bytes may name a file that is not on disk (the fuzz target).
  fs::path canon = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (ec) canon = fs::absolute(dir).lexically_normal();
  base_ = canon.string();
  roots_.push_back(canon);
  for (const std::string& d : asset_dirs) {
    const fs::path root = fs::canonical(d, ec);
    if (ec || !fs::is_directory(root, ec))
      throw SceneError(d + ": --asset-dir names no folder" +
                       (ec ? " (" + ec.message() + ")" : std::string()));
    roots_.push_back(root);
  }
}

void AssetFiles::refuse(const std::string& name, const std::string& why) {
  if (!refusal_) refusal_ = std::make_pair(name, why);
}

AssetFiles::Resolved AssetFiles::resolve(const std::string& name) {
  if (name.find('\0') != std::string::npos) {
    refuse(name, "holds a NUL byte, which no file name can");
    return {};
  }
  if (has_scheme(name)) {
    refuse(name, "is not a file name (photonbound fetches no network or other URI scheme)");
    return {};
  }
  const std::string outside =
      roots_.size() > 1
          ? "is outside the scene's folder and the --asset-dir folders (allow its folder with "
            "--asset-dir)"
          : "is outside the scene's folder (allow its folder with --asset-dir)";
  std::error_code ec;
  const fs::path given(name);
  const fs::path full = given.is_absolute() ? given : fs::path(base_) / given;
  // Symlinks followed, ".." resolved. An error here says the same as outside: it may come from
  // a folder the scene may not look into.
  const fs::path canon = fs::weakly_canonical(full, ec);
  bool inside = false;
  if (!ec)
    for (const fs::path& root : roots_) inside = inside || within(canon, root);
  if (!inside) {
    refuse(name, outside);
    return {};
  }
  struct stat st;
  if (::stat(canon.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return {Verdict::Missing, canon};
    return {Verdict::Readable, canon};  // read() reports the error
  }
  if (!S_ISREG(st.st_mode)) {
    refuse(name, type_of(st.st_mode));
    return {};
  }
  return {Verdict::Readable, canon};
}

AssetFiles::Verdict AssetFiles::check(const std::string& name) { return resolve(name).verdict; }

bool AssetFiles::read(const std::string& name, std::vector<unsigned char>& out, std::string& err) {
  const Resolved r = resolve(name);
  if (r.verdict != Verdict::Readable) {
    err = "refused";
    return false;
  }
  // Not following a symlink put there since the check, and checked again once open.
  const uint64_t left = max_bytes_ - read_bytes_;
  if (const std::optional<ReadFailure> f = read_regular_file(r.path, false, out, left)) {
    err = f->why;
    if (f->stage == ReadFailure::NotRegular) {
      refuse(name, f->why);
      err = "refused";
    } else if (f->stage == ReadFailure::TooLarge && left < UINT32_MAX) {
      refuse(name, "is " + f->why + ", more than the " + bytes_text(left) +
                       " --max-memory leaves for the scene's files");
      err = "refused";
    }
    return false;
  }
  read_bytes_ += out.size();
  read_.push_back(r.path.string());
  return true;
}

std::optional<ReadFailure> read_regular_file(const fs::path& path, bool follow_last_link,
                                             std::vector<unsigned char>& out, uint64_t max_size) {
  // O_NONBLOCK: a named pipe is refused below, never waited on in open().
  errno = 0;
  const Fd fd(::open(path.c_str(),
                     O_RDONLY | O_NONBLOCK | O_CLOEXEC | (follow_last_link ? 0 : O_NOFOLLOW)));
  if (fd.get() < 0) return ReadFailure{ReadFailure::Open, std::strerror(errno)};
  struct stat st;
  if (::fstat(fd.get(), &st) != 0) return ReadFailure{ReadFailure::Open, std::strerror(errno)};
  if (!S_ISREG(st.st_mode)) return ReadFailure{ReadFailure::NotRegular, type_of(st.st_mode)};
  max_size = std::min<uint64_t>(max_size, UINT32_MAX);
  const ReadFailure too_large{ReadFailure::TooLarge, "larger than " + bytes_text(max_size)};
  if (uint64_t(st.st_size) > max_size) return too_large;
  out.clear();
  out.reserve(size_t(st.st_size));
  unsigned char chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd.get(), chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return ReadFailure{ReadFailure::Read, std::strerror(errno)};
    if (n == 0) return std::nullopt;
    out.insert(out.end(), chunk, chunk + n);
    if (out.size() > max_size) return too_large;
  }
}

std::string tinygltf_decoded(const std::string& uri) {
  auto hex = [](unsigned char c) -> unsigned char {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return 0;
  };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      out += char(hex(static_cast<unsigned char>(uri[i + 1])) << 4 |
                  hex(static_cast<unsigned char>(uri[i + 2])));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

namespace {

// The name under the scene's folder that tinygltf joined to it, or none.
std::optional<std::string> name_under(const AssetFiles& files, const std::string& joined) {
  const std::string& base = files.base();
  const std::string prefix = !base.empty() && base.back() == '/' ? base : base + "/";
  if (joined.rfind(prefix, 0) != 0) return std::nullopt;
  return joined.substr(prefix.size());
}

}  // namespace

bool fs_exists(const std::string& joined, void* user) {
  auto& files = *static_cast<AssetFiles*>(user);
  const std::optional<std::string> name = name_under(files, joined);
  return name && files.check(*name) == AssetFiles::Verdict::Readable;
}
std::string fs_expand(const std::string& path, void*) { return path; }
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& joined,
             void* user) {
  auto& files = *static_cast<AssetFiles*>(user);
  const std::optional<std::string> name = name_under(files, joined);
  std::string why = "refused";
  const bool ok = name && files.read(*name, *out, why);
  if (!ok && err) *err = why;
  return ok;
}
bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "the loader writes no files";
  return false;
}

}  // namespace pb::gltf
