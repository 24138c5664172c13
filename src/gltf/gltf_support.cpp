// tinygltf-free helpers of the glTF loader; see gltf_support.h.
#include "gltf/gltf_support.h"

#include "gltf/gltf_files.h"
#include "gltf/gltf_loader.h"

#include <algorithm>
#include <climits>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>

namespace pb::gltf {

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string label(const char* kind, const std::string& name, size_t index) {
  return name.empty() ? std::string(kind) + " " + std::to_string(index)
                      : std::string(kind) + " '" + one_line(name) + "'";
}

std::string absent(const std::string& kind, double index, size_t count) {
  return kind + " " + num(index) + ", which does not exist (the file has " + std::to_string(count) +
         " " + kind +
         (count == 1           ? ")"
          : kind.back() == 'h' ? "es)"
                               : "s)");
}

std::string mode_name(int mode) {
  static const char* names[] = {"POINTS",    "LINES",          "LINE_LOOP",   "LINE_STRIP",
                                "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
  return mode >= 0 && mode < 7 ? names[mode] : std::to_string(mode);
}

std::string type_name(int type) {  // glTF/tinygltf codes: SCALAR 65, VECn n, MATn 32 + n
  if (type == 65) return "SCALAR";
  if (type >= 2 && type <= 4) return "VEC" + std::to_string(type);
  if (type >= 34 && type <= 36) return "MAT" + std::to_string(type - 32);
  return std::to_string(type);
}

std::string component_name(int c) {
  static const char* names[] = {"BYTE", "UNSIGNED_BYTE", "SHORT", "UNSIGNED_SHORT",
                                "INT",  "UNSIGNED_INT",  "FLOAT"};
  return c >= 5120 && c <= 5126 ? names[c - 5120] : c == 5130 ? "DOUBLE" : std::to_string(c);
}

std::vector<unsigned char> read_file(const std::string& path, uint64_t max_size) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw SceneError(path + ": cannot open (Is a directory)");
  std::vector<unsigned char> data;
  if (const std::optional<ReadFailure> f = read_regular_file(path, true, data, max_size)) {
    switch (f->stage) {
      case ReadFailure::Open:
        throw SceneError(path + ": cannot open (" + f->why + ")");
      case ReadFailure::NotRegular:
        throw SceneError(path + ": " + f->why);
      case ReadFailure::Read:
        throw SceneError(path + ": cannot read (" + f->why + ")");
      case ReadFailure::TooLarge:
        throw SceneError(path + ": file is " + f->why +
                         (max_size < UINT32_MAX ? " (--max-memory)" : ""));
    }
  }
  return data;
}

namespace {
uint64_t le32(const std::vector<unsigned char>& d, uint64_t at) {
  return uint64_t(d[at]) | uint64_t(d[at + 1]) << 8 | uint64_t(d[at + 2]) << 16 |
         uint64_t(d[at + 3]) << 24;
}
}  // namespace

// Layout: "glTF", version, length; then chunks of (length, type, data): JSON first, BIN next.
uint32_t check_glb(const std::string& path, const std::vector<unsigned char>& d) {
  auto bad = [&](const std::string& what) { throw SceneError(path + ": malformed glTF: " + what); };
  if (d.size() < 20) bad("truncated GLB header (" + std::to_string(d.size()) + " bytes)");
  if (std::memcmp(d.data(), "glTF", 4) != 0) bad("bad GLB magic (expected 'glTF')");
  if (le32(d, 4) != 2) bad("GLB version " + std::to_string(le32(d, 4)) + "; only 2 is supported");
  const uint64_t length = le32(d, 8), json = le32(d, 12);
  if (length > d.size())
    bad("truncated GLB: the header declares " + std::to_string(length) + " bytes, the file has " +
        std::to_string(d.size()));
  if (le32(d, 16) != 0x4E4F534Au) bad("the first GLB chunk is not JSON");
  if (20 + json > length)
    bad("the GLB JSON chunk (" + std::to_string(json) + " bytes) is truncated");
  if (20 + json + 8 <= length && 28 + json + le32(d, 20 + json) > length)
    bad("the GLB BIN chunk (" + std::to_string(le32(d, 20 + json)) + " bytes) is truncated");
  return uint32_t(length);
}

std::string_view glb_json(const std::vector<unsigned char>& glb) {
  return std::string_view(reinterpret_cast<const char*>(glb.data()) + 20, size_t(le32(glb, 12)));
}

std::vector<unsigned char> replace_glb_json(const std::vector<unsigned char>& glb, uint32_t length,
                                            const std::string& json) {
  std::vector<unsigned char> out(glb.begin(), glb.begin() + 12);
  std::string chunk = json;
  while (chunk.size() % 4) chunk += ' ';  // chunks are 4-byte aligned
  const uint64_t rest = 20 + le32(glb, 12), total = 20 + chunk.size() + (length - rest);
  auto put32 = [&](size_t at, uint64_t v) {
    for (int k = 0; k < 4; ++k) out[at + size_t(k)] = uint8_t(v >> (8 * k));
  };
  put32(8, total);
  out.resize(20);
  put32(12, chunk.size());
  put32(16, 0x4E4F534Au);  // "JSON"
  out.insert(out.end(), chunk.begin(), chunk.end());
  out.insert(out.end(), glb.begin() + int64_t(rest), glb.begin() + int64_t(length));
  return out;
}

std::optional<std::vector<unsigned char>> align_glb(const std::vector<unsigned char>& glb,
                                                    uint32_t length) {
  const uint64_t json = le32(glb, 12), bin_at = 20 + json;
  const bool has_bin = bin_at + 8 <= length;
  const uint64_t bin = has_bin ? le32(glb, bin_at) : 0;
  if (json % 4 == 0 && bin % 4 == 0) return std::nullopt;
  std::vector<unsigned char> out(glb.begin(), glb.begin() + 20);
  auto put32 = [&](size_t at, uint64_t v) {
    for (int k = 0; k < 4; ++k) out[at + size_t(k)] = uint8_t(v >> (8 * k));
  };
  out.insert(out.end(), glb.begin() + 20, glb.begin() + int64_t(bin_at));
  while (out.size() % 4) out.push_back(' ');  // JSON is padded with spaces
  put32(12, out.size() - 20);
  if (has_bin) {
    const size_t at = out.size();
    out.insert(out.end(), glb.begin() + int64_t(bin_at), glb.begin() + int64_t(bin_at + 8 + bin));
    while (out.size() % 4) out.push_back(0);  // BIN with zeros
    put32(at, out.size() - at - 8);
    out.insert(out.end(), glb.begin() + int64_t(bin_at + 8 + bin), glb.begin() + int64_t(length));
  }
  put32(8, out.size());
  return out;
}

Xform::Xform(const glm::dmat4& world)
    : m(world), linear(world), det(glm::determinant(glm::dmat3(world))) {}

bool Xform::finite() const {
  for (int c = 0; c < 4; ++c)
    if (!std::isfinite(glm::dot(m[c], m[c]))) return false;
  return true;
}

bool Xform::singular() const {  // relative, so that a uniformly tiny scale is not "singular"
  const double scale = glm::length(linear[0]) * glm::length(linear[1]) * glm::length(linear[2]);
  return !(std::abs(det) > 1e-12 * scale);
}

bool sheared(const glm::dmat3& a) {
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      if (std::abs(glm::dot(a[i], a[j])) > 1e-4 * glm::length(a[i]) * glm::length(a[j]))
        return true;
  return false;
}

bool rotation_matrix(const std::vector<double>& xyzw, glm::dmat3& out) {
  glm::dvec4 q(xyzw[0], xyzw[1], xyzw[2], xyzw[3]);
  const double len = glm::length(q);
  if (!(len > 0.0) || !std::isfinite(len)) return false;
  q /= len;
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  out = glm::dmat3(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),  // column 0
                   2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),  // column 1
                   2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y));
  return true;
}

bool degenerate(const std::vector<vec3>& p, uint32_t i0, uint32_t i1, uint32_t i2) {
  if (i0 == i1 || i1 == i2 || i0 == i2) return true;
  const vec3 e1 = p[i1] - p[i0], e2 = p[i2] - p[i0], e3 = p[i2] - p[i1];
  const vec3 c = glm::cross(e1, e2);
  if (!(glm::dot(c, c) >= std::numeric_limits<float>::min())) return true;
  const dvec3 d1(e1), d2(e2), d3(e3);
  const double longest2 = std::max({glm::dot(d1, d1), glm::dot(d2, d2), glm::dot(d3, d3)});
  return glm::length(glm::cross(d1, d2)) <= 1e-12 * longest2;
}

}  // namespace pb::gltf
