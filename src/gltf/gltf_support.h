// tinygltf-free helpers of the glTF loader (src/gltf_*.cpp, the only files that see
// tinygltf types): one-line messages, reading the file, checking the GLB container, world
// transforms and the degenerate-triangle test.
#pragma once

#include "util/math.h"
#include "util/message_text.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pb::gltf {

std::string num(double v);  // shortest readable form: 1.5, 1e+12
// "mesh 'name'" when named, "mesh 3" otherwise.
std::string label(const char* kind, const std::string& name, size_t index);
// "<kind> <index>, which does not exist (the file has <count> <kind>s)"
std::string absent(const std::string& kind, double index, size_t count);
// glTF enum names for messages: primitive mode, accessor type, accessor componentType.
std::string mode_name(int mode);
std::string type_name(int type);
std::string component_name(int component);

// A validated accessor: component c of element i is at base + i * stride + c * sizeof(T).
struct View {
  const unsigned char* base = nullptr;
  size_t stride = 0, count = 0;
  int component = 0;  // glTF componentType
  bool normalized = false;
  int components = 0;  // per element: 1 (SCALAR) to 16 (MAT4)
  template <class T>
  T get(size_t i, int c) const {
    T v;
    std::memcpy(&v, base + i * stride + size_t(c) * sizeof(T), sizeof(T));
    return v;
  }
  // Component c of element i as a number: FLOAT as stored, integers as stored or, when
  // normalized, dequantised (glTF 2.0 "Animations": signed max(c / 127, -1) and
  // max(c / 32767, -1), unsigned c / 255 and c / 65535; KHR_mesh_quantization uses the same).
  double scalar(size_t i, int c) const {
    switch (component) {
      case 5120:
        return normalized ? std::max(get<int8_t>(i, c) / 127.0, -1.0) : get<int8_t>(i, c);
      case 5121:
        return normalized ? get<uint8_t>(i, c) / 255.0 : get<uint8_t>(i, c);
      case 5122:
        return normalized ? std::max(get<int16_t>(i, c) / 32767.0, -1.0) : get<int16_t>(i, c);
      case 5123:
        return normalized ? get<uint16_t>(i, c) / 65535.0 : get<uint16_t>(i, c);
      case 5125:
        return get<uint32_t>(i, c);
      default:
        return get<float>(i, c);  // 5126: the loader checks componentType first
    }
  }
  dvec3 vec3(size_t i) const { return dvec3(scalar(i, 0), scalar(i, 1), scalar(i, 2)); }
};

// The whole file; throws SceneError "<path>: cannot open (<strerror>)" when it cannot, and
// "<path>: file is larger than ..." past `max_size` (--max-memory) or 4 GiB.
std::vector<unsigned char> read_file(const std::string& path, uint64_t max_size = UINT32_MAX);

// Checks the GLB header and chunk bounds (tinygltf 2.7 lets the BIN chunk run up to 8 bytes
// past the declared length) and returns the declared length. Throws SceneError.
uint32_t check_glb(const std::string& path, const std::vector<unsigned char>& data);

// A GLB that check_glb accepted with its JSON and BIN chunks padded to 4 bytes, as glTF requires
// and tinygltf 2.7 insists ("BIN Chunk end does not aligned"; real exporters, FME 2018 among
// them, leave the last chunk unpadded); none when both already are. The buffer's byteLength is
// unchanged: a chunk may be up to 3 bytes longer than its buffer.
std::optional<std::vector<unsigned char>> align_glb(const std::vector<unsigned char>& glb,
                                                    uint32_t length);

// The JSON chunk of a GLB that check_glb accepted, and the same GLB (its first `length` bytes)
// with that chunk replaced by `json`.
std::string_view glb_json(const std::vector<unsigned char>& glb);
std::vector<unsigned char> replace_glb_json(const std::vector<unsigned char>& glb, uint32_t length,
                                            const std::string& json);

// A node's world transform and what meshes, normals and directions need from it.
struct Xform {
  glm::dmat4 m{1.0};
  glm::dmat3 linear{1.0};
  double det = 1.0;
  explicit Xform(const glm::dmat4& world);
  dvec3 point(const dvec3& p) const { return dvec3(m * glm::dvec4(p, 1.0)); }
  dvec3 direction(const dvec3& d) const { return linear * d; }
  bool finite() const;
  bool singular() const;  // |det| tiny relative to the column lengths
};

// Whether a linear map is not rotation x scale (glTF 2.0 "Transformations": TRS): two of its
// columns are not orthogonal, beyond float rounding (1e-4 of their lengths' product).
bool sheared(const glm::dmat3& linear);

// The column-major matrix of a glTF quaternion [x, y, z, w] (normalised here); false when the
// quaternion is zero or not finite.
bool rotation_matrix(const std::vector<double>& xyzw, glm::dmat3& out);

// A triangle is degenerate when an index repeats, when |cross| <= 1e-12 * (longest edge)^2,
// or when its area is so small that its square underflows in float (the renderer's precision).
bool degenerate(const std::vector<vec3>& p, uint32_t i0, uint32_t i1, uint32_t i2);

}  // namespace pb::gltf
