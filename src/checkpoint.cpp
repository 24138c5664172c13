#include "photonbound/checkpoint.h"

#include "photonbound/rng.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <type_traits>

namespace pb {

namespace {

constexpr char kMagic[8] = {'P', 'B', 'S', 'T', 'A', 'T', 'E', '\0'};
static_assert(std::is_trivially_copyable_v<PointState>);

// 64-bit checksum over 8-byte words: SplitMix64 mixing of each word with its byte position, in
// four independent lanes (word k goes to lane k mod 4) so that consecutive words do not wait
// for each other's mixing: one chain ran at ~1.6 GB/s, four at ~4 on this machine, and a
// checkpoint sums every point state. The bytes may arrive in pieces of any size.
class Checksum {
 public:
  explicit Checksum(uint64_t total_size) {
    for (uint64_t j = 0; j < 4; ++j) lane_[j] = 0x6a09e667f3bcc909ULL ^ total_size ^ (j << 56);
  }
  void add(const char* p, size_t n) {
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
  uint64_t finish() const {
    uint64_t tail = 0;
    std::memcpy(&tail, buf_, fill_);
    uint64_t h = mix64(lane_[0] ^ tail ^ 0x5bd1e995ULL);
    for (int j = 1; j < 4; ++j) h = mix64(h ^ lane_[j]);
    return h;
  }

 private:
  void word(const char* p) {
    uint64_t w;
    std::memcpy(&w, p, 8);
    uint64_t& h = lane_[k_ & 3];
    h = mix64(h ^ (w + 8 * k_));
    ++k_;
  }
  uint64_t lane_[4];
  uint64_t k_ = 0;  // words so far
  char buf_[8] = {};
  size_t fill_ = 0;
};

uint64_t checksum(const char* data, size_t size) {
  Checksum c(size);
  c.add(data, size);
  return c.finish();
}

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
  void opt_u64(const std::optional<uint64_t>& v) {
    u64(v ? 1 : 0);
    u64(v.value_or(0));
  }
  void opt_f64(const std::optional<double>& v) {
    u64(v ? 1 : 0);
    f64(v.value_or(0.0));
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
  std::optional<uint64_t> opt_u64() {
    const bool has = u64() != 0;
    const uint64_t v = u64();
    return has ? std::optional<uint64_t>(v) : std::nullopt;
  }
  std::optional<double> opt_f64() {
    const bool has = u64() != 0;
    const double v = f64();
    return has ? std::optional<double>(v) : std::nullopt;
  }
  size_t remaining() const { return end_ - pos_; }

 private:
  std::string path_;
  const char* data_;
  size_t end_;
  size_t pos_ = 0;
};

// Every option is stored (the stop conditions too, so `resume` without new ones carries on with
// the old plan); read_options reads them back in the same order.
void write_options(Writer& w, const RenderOptions& o) {
  // The scene as an absolute path: `resume` may run from another working directory.
  std::error_code ec;
  const std::filesystem::path scene = std::filesystem::absolute(o.scene, ec);
  w.str(ec ? o.scene : scene.lexically_normal().string());
  w.str(o.output);
  w.opt_u64(o.passes);
  w.opt_f64(o.time_seconds);
  w.opt_f64(o.target_error);
  w.u64(o.photons_per_pass);
  w.f64(o.alpha);
  w.opt_f64(o.radius);
  w.u64(uint64_t(o.max_depth));
  w.u64(o.width ? uint64_t(*o.width) : 0);
  w.u64(o.height ? uint64_t(*o.height) : 0);
  w.str(o.camera);
  w.u64(o.seed);
  w.u64(o.direct == DirectMode::Photons ? 1 : 0);
  w.f64(o.confidence);
  w.u64(o.min_passes);
  w.u64(o.metric == ErrorMetric::Relative ? 1 : 0);
  w.str(o.command_line);
}

RenderOptions read_options(Reader& r) {
  RenderOptions o;
  o.scene = r.str();
  o.output = r.str();
  o.passes = r.opt_u64();
  o.time_seconds = r.opt_f64();
  o.target_error = r.opt_f64();
  o.photons_per_pass = r.u64();
  o.alpha = r.f64();
  o.radius = r.opt_f64();
  o.max_depth = int(r.u64());
  if (const uint64_t w = r.u64()) o.width = int(w);
  if (const uint64_t h = r.u64()) o.height = int(h);
  o.camera = r.str();
  o.seed = r.u64();
  o.direct = r.u64() ? DirectMode::Photons : DirectMode::NextEvent;
  o.confidence = r.f64();
  o.min_passes = r.u64();
  o.metric = r.u64() ? ErrorMetric::Relative : ErrorMetric::Absolute;
  o.command_line = r.str();
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

}  // namespace

void write_file_atomic(const std::string& path, std::initializer_list<std::string_view> pieces) {
  const std::filesystem::path p(path);
  const std::string tmp =
      (p.parent_path() / ("." + p.filename().string() + ".tmp" + std::to_string(::getpid())))
          .string();
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
        ::unlink(tmp.c_str());
        throw StateError(path + ": cannot write (" + err + ")");
      }
      done += size_t(n);
    }
  }
  // The data must be on disk before the rename makes it the file of record.
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    ::unlink(tmp.c_str());
    throw StateError(path + ": cannot flush to disk (" + errno_text() + ")");
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string err = errno_text();
    ::unlink(tmp.c_str());
    throw StateError(path + ": cannot rename into place (" + err + ")");
  }
  const std::string dir = p.parent_path().empty() ? "." : p.parent_path().string();
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);  // make the rename itself durable
    ::close(dfd);
  }
}

void save_state(const std::string& path, const SavedRender& s) {
  Writer w;
  w.raw(kMagic, 8);
  w.u32(kStateVersion);
  w.u32(uint32_t(sizeof(PointState)));
  write_options(w, s.options);
  w.u64(s.scene_hash);
  w.f64(s.initial_radius);
  w.u64(s.loop.passes);
  w.u64(s.loop.photons);
  w.u64(s.loop.rays);
  w.f64(s.loop.seconds);
  w.u64(s.loop.next_check);
  w.u64(s.loop.early_pass);
  w.f64(s.loop.early_bound);
  w.u64(s.states.size());
  // The states go to the file straight from the snapshot, without a copy into the buffer.
  const std::string_view head(w.bytes());
  const std::string_view states(reinterpret_cast<const char*>(s.states.data()),
                                s.states.size() * sizeof(PointState));
  Checksum sum(head.size() + states.size());
  sum.add(head.data(), head.size());
  sum.add(states.data(), states.size());
  const uint64_t stored = sum.finish();
  write_file_atomic(path,
                    {head, states, std::string_view(reinterpret_cast<const char*>(&stored), 8)});
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
    s.options = read_options(r);
    s.scene_hash = r.u64();
    s.initial_radius = r.f64();
    s.loop.passes = r.u64();
    s.loop.photons = r.u64();
    s.loop.rays = r.u64();
    s.loop.seconds = r.f64();
    s.loop.next_check = r.u64();
    s.loop.early_pass = r.u64();
    s.loop.early_bound = r.f64();
    const uint64_t n = r.u64();
    if (n > r.remaining() / sizeof(PointState)) throw StateError(path + ": truncated state file");
    s.states.resize(n);
    r.raw(s.states.data(), n * sizeof(PointState));
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

uint64_t hash_file(const std::string& path) {
  const std::string bytes = read_bytes(path);
  return checksum(bytes.data(), bytes.size());
}

std::vector<std::string> differences(const SavedRender& saved, const RenderOptions& now,
                                     uint64_t scene_hash) {
  std::vector<std::string> d;
  const RenderOptions& a = saved.options;
  if (saved.scene_hash != scene_hash)
    d.push_back("scene: the state was rendered from another scene file (or " + a.scene +
                " has changed since)");
  auto differ = [&](const std::string& name, const std::string& x, const std::string& y) {
    if (x != y) d.push_back(name + ": " + x + " in the state, " + y + " now");
  };
  auto res = [](const RenderOptions& o) {
    return o.width ? std::to_string(*o.width) + "x" + std::to_string(*o.height) : "default";
  };
  differ("photons-per-pass", std::to_string(a.photons_per_pass),
         std::to_string(now.photons_per_pass));
  differ("alpha", number_text(a.alpha), number_text(now.alpha));
  differ("radius", a.radius ? number_text(*a.radius) : "auto",
         now.radius ? number_text(*now.radius) : "auto");
  differ("max-depth", std::to_string(a.max_depth), std::to_string(now.max_depth));
  differ("resolution", res(a), res(now));
  differ("camera", a.camera.empty() ? "first" : a.camera,
         now.camera.empty() ? "first" : now.camera);
  differ("seed", std::to_string(a.seed), std::to_string(now.seed));
  differ("direct", a.direct == DirectMode::Photons ? "photons" : "nee",
         now.direct == DirectMode::Photons ? "photons" : "nee");
  return d;
}

}  // namespace pb
