#include "app/checkpoint.h"

#include "util/file_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string_view>
#include <type_traits>

namespace pb {

namespace {

constexpr char kMagic[8] = {'P', 'B', 'S', 'T', 'A', 'T', 'E', '\0'};
static_assert(std::is_trivially_copyable_v<PointState>);

class Writer {
 public:
  void raw(const void* p, size_t n) { out_.append(static_cast<const char*>(p), n); }
  void u32(uint32_t v) { raw(&v, 4); }
  void u64(uint64_t v) { raw(&v, 8); }
  void f64(double v) { raw(&v, 8); }
  void str(const std::string& s) {
    u64(s.size());
    raw(s.data(), s.size());
  }
  std::string& bytes() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  Reader(const std::string& path, const std::string& bytes, size_t end)
      : path_(path), data_(bytes.data()), end_(end) {}
  void raw(void* p, size_t n) {
    if (n > end_ - pos_) throw StateError(path_ + ": truncated state file");
    if (n == 0) return;  // an empty vector's data() may be null, which memcpy may not take
    std::memcpy(p, data_ + pos_, n);
    pos_ += n;
  }
  uint32_t u32() {
    uint32_t v;
    raw(&v, 4);
    return v;
  }
  uint64_t u64() {
    uint64_t v;
    raw(&v, 8);
    return v;
  }
  double f64() {
    double v;
    raw(&v, 8);
    return v;
  }
  std::string str() {
    const uint64_t n = u64();
    if (n > end_ - pos_) throw StateError(path_ + ": truncated state file");
    std::string s(data_ + pos_, n);
    pos_ += n;
    return s;
  }
  size_t remaining() const { return end_ - pos_; }

 private:
  std::string path_;
  const char* data_;
  size_t end_;
  size_t pos_ = 0;
};

// The scene (as an absolute path: `resume` may run from another working directory), the
// command line, then every option of the table as key and text; read_options reads them back
// through the same table, so an option added to the table is saved with no change here.
void write_options(Writer& w, const RenderOptions& o) {
  std::error_code ec;
  const std::filesystem::path scene = std::filesystem::absolute(o.scene, ec);
  w.str(ec ? o.scene : scene.lexically_normal().string());
  w.str(o.command_line);
  w.u64(option_table().size());
  for (const OptionSpec& spec : option_table()) {
    w.str(std::string(spec.key));
    w.str(spec.format(o));
  }
}

RenderOptions read_options(Reader& r, const std::string& path) {
  RenderOptions o;
  o.scene = r.str();
  o.command_line = r.str();
  const uint64_t n = r.u64();
  for (uint64_t k = 0; k < n; ++k) {
    const std::string key = r.str(), value = r.str();
    const OptionSpec* spec = nullptr;
    for (const OptionSpec& s : option_table())
      if (s.key == key) spec = &s;
    if (!spec)
      throw StateError(path + ": the state has an option '" + key +
                       "' this photonbound does not know");
    if (value.empty()) continue;  // unset: the default
    try {
      spec->parse(o, value);
    } catch (const UsageError& e) {
      throw StateError(path + ": corrupted state file (" + e.what() + ")");
    }
  }
  return o;
}

std::string errno_text() { return std::strerror(errno); }

// The whole file; StateError "<path>: cannot open (...)" when it cannot be read.
std::string read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw StateError(path + ": cannot open (" + errno_text() + ")");
  std::ostringstream buf;
  buf << f.rdbuf();
  return buf.str();
}

// Writes the pieces one after the other into the temporary file `tmp` of `path`.
void write_pieces(const std::string& path, const std::string& tmp,
                  std::initializer_list<std::string_view> pieces) {
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw StateError(path + ": cannot write (" + errno_text() + ")");
  for (const std::string_view bytes : pieces) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const std::string err = errno_text();
        ::close(fd);
        throw StateError(path + ": cannot write (" + err + ")");
      }
      done += size_t(n);
    }
  }
  if (::close(fd) != 0) throw StateError(path + ": cannot write (" + errno_text() + ")");
}

}  // namespace

void save_state(const std::string& path, const SavedRender& s) {
  Writer w;
  w.raw(kMagic, 8);
  w.u32(kStateVersion);
  w.u32(uint32_t(sizeof(PointState)));
  write_options(w, s.options);
  w.u64(s.scene_hash);
  w.f64(s.render.initial_radius);
  w.u64(s.render.work.passes);
  w.u64(s.render.work.photons);
  w.u64(s.render.work.rays);
  w.f64(s.schedule.seconds);
  w.u64(s.schedule.next_check);
  w.u64(s.schedule.early_pass);
  w.f64(s.schedule.early_value);
  w.u64(s.render.visible.size());
  w.raw(s.render.visible.data(), s.render.visible.size() * sizeof(uint32_t));
  w.u64(s.render.min_mass.size());
  w.raw(s.render.min_mass.data(), s.render.min_mass.size() * sizeof(float));
  w.f64(s.render.max_photon_power);
  w.u64(s.render.glossy_f.size());
  w.raw(s.render.glossy_f.data(), s.render.glossy_f.size() * sizeof(float));
  w.u64(s.render.guide_learnt);
  w.u64(s.render.guide.size());
  w.raw(s.render.guide.data(), s.render.guide.size() * sizeof(double));
  w.u64(s.render.path_history.size());
  w.raw(s.render.path_history.data(), s.render.path_history.size() * sizeof(float));
  const std::vector<PointState>& states = s.render.states;
  w.u64(states.size());
  // The states go to the file straight from the snapshot, without a copy into the buffer.
  const std::string_view head(w.bytes());
  const std::string_view body(reinterpret_cast<const char*>(states.data()),
                              states.size() * sizeof(PointState));
  Checksum sum(head.size() + body.size());
  sum.add(head.data(), head.size());
  sum.add(body.data(), body.size());
  const uint64_t stored = sum.finish();
  try {
    write_atomically(path, [&](const std::string& tmp) {
      write_pieces(path, tmp,
                   {head, body, std::string_view(reinterpret_cast<const char*>(&stored), 8)});
    });
  } catch (const FileError& e) {
    throw StateError(e.what());
  }
}

SavedRender load_state(const std::string& path) {
  const std::string bytes = read_bytes(path);
  if (bytes.size() < 16 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    throw StateError(path + ": not a photonbound state file");
  uint32_t version, record;
  std::memcpy(&version, bytes.data() + 8, 4);
  std::memcpy(&record, bytes.data() + 12, 4);
  if (version != kStateVersion)
    throw StateError(path + ": state format version " + std::to_string(version) +
                     ", this photonbound reads version " + std::to_string(kStateVersion));
  if (record != sizeof(PointState))
    throw StateError(path + ": written by a photonbound with another point record layout");
  if (bytes.size() < 24) throw StateError(path + ": truncated state file");
  const size_t body = bytes.size() - 8;
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + body, 8);

  Reader r(path, bytes, body);
  SavedRender s;
  try {
    char head[16];
    r.raw(head, 16);
    s.options = read_options(r, path);
    s.scene_hash = r.u64();
    s.render.initial_radius = r.f64();
    s.render.work.passes = r.u64();
    s.render.work.photons = r.u64();
    s.render.work.rays = r.u64();
    s.schedule.seconds = r.f64();
    s.schedule.next_check = r.u64();
    s.schedule.early_pass = r.u64();
    s.schedule.early_value = r.f64();
    const uint64_t v = r.u64();
    if (v > r.remaining() / sizeof(uint32_t)) throw StateError(path + ": truncated state file");
    s.render.visible.resize(v);
    r.raw(s.render.visible.data(), v * sizeof(uint32_t));
    const uint64_t mm = r.u64();
    if (mm > r.remaining() / sizeof(float)) throw StateError(path + ": truncated state file");
    s.render.min_mass.resize(mm);
    r.raw(s.render.min_mass.data(), mm * sizeof(float));
    s.render.max_photon_power = r.f64();
    const uint64_t gf = r.u64();
    if (gf > r.remaining() / sizeof(float)) throw StateError(path + ": truncated state file");
    s.render.glossy_f.resize(gf);
    r.raw(s.render.glossy_f.data(), gf * sizeof(float));
    s.render.guide_learnt = r.u64();
    const uint64_t gc = r.u64();
    if (gc > r.remaining() / sizeof(double)) throw StateError(path + ": truncated state file");
    s.render.guide.resize(gc);
    r.raw(s.render.guide.data(), gc * sizeof(double));
    const uint64_t ip = r.u64();
    if (ip > r.remaining() / sizeof(float)) throw StateError(path + ": truncated state file");
    s.render.path_history.resize(ip);
    r.raw(s.render.path_history.data(), ip * sizeof(float));
    const uint64_t n = r.u64();
    if (n > r.remaining() / sizeof(PointState)) throw StateError(path + ": truncated state file");
    s.render.states.resize(n);
    r.raw(s.render.states.data(), n * sizeof(PointState));
  } catch (const StateError&) {
    // A short file also fails its checksum; say which of the two it most likely is.
    if (checksum(bytes.data(), body) != stored)
      throw StateError(path + ": truncated or corrupted state file (checksum mismatch)");
    throw;
  }
  if (checksum(bytes.data(), body) != stored)
    throw StateError(path + ": corrupted state file (checksum mismatch)");
  if (r.remaining() != 0) throw StateError(path + ": corrupted state file (trailing bytes)");
  return s;
}

std::vector<std::string> differences(const SavedRender& saved, const RenderOptions& now,
                                     uint64_t scene_hash) {
  std::vector<std::string> d;
  if (saved.scene_hash != scene_hash)
    d.push_back("scene: the state was rendered from another scene (or " + saved.options.scene +
                " or a file it loads has changed since)");
  for (std::string& x : image_differences(saved.options, now)) d.push_back(std::move(x));
  return d;
}

}  // namespace pb
