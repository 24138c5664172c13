// The glTF loader's accessors (see gltf_loader_impl.h): every index, offset and length checked
// before a byte is read; bufferViews compressed with EXT_meshopt_compression decoded once into a
// copy that accessors then read like any bufferView; accessors without bufferView (zeros) and
// sparse accessors (glTF 2.0 "Sparse Accessors") materialised once, tightly packed.
#include "gltf/gltf_decode.h"
#include "gltf/gltf_loader_impl.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace pb::gltf {

namespace {

// An accessor with no bufferView is zeros (plus its sparse values): its size comes from the
// JSON alone, so it is capped.
constexpr uint64_t kMaxSynthesized = uint64_t(1) << 28;  // bytes

size_t element_size(const tinygltf::Accessor& a) {
  return size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)) *
                tinygltf::GetNumComponentsInType(uint32_t(a.type)));
}

}  // namespace

// Index in range, type and componentType as expected. `al` becomes the accessor's label.
const tinygltf::Accessor& Loader::header(int index, const std::string& ctx,
                                         std::initializer_list<int> components, int type,
                                         std::string& al) const {
  if (index < 0 || size_t(index) >= m_.accessors.size())
    fail(ctx + " refers to " + absent("accessor", index, m_.accessors.size()));
  const tinygltf::Accessor& a = m_.accessors[size_t(index)];
  al = ctx + " accessor " + std::to_string(index);
  if (type == kVec3OrVec4) {
    if (a.type != TINYGLTF_TYPE_VEC3 && a.type != TINYGLTF_TYPE_VEC4)
      fail(al + " has type " + type_name(a.type) + "; expected VEC3 or VEC4");
  } else if (a.type != type) {
    fail(al + " has type " + type_name(a.type) + "; expected " + type_name(type));
  }
  if (std::find(components.begin(), components.end(), a.componentType) == components.end()) {
    std::string want;
    for (int c : components) want += (want.empty() ? "" : " or ") + component_name(c);
    fail(al + " has componentType " + component_name(a.componentType) + "; expected " + want);
  }
  return a;
}

View Loader::accessor(int index, const std::string& ctx, std::initializer_list<int> components,
                      int type) {
  std::string al;
  const tinygltf::Accessor& a = header(index, ctx, components, type, al);
  const size_t element = element_size(a);
  if (a.sparse.isSparse || a.bufferView < 0) return synthesized(index, a, al, element);
  return stored(a, al, element);
}

// byteOffset + stride * (count - 1) + element size within the bufferView.
View Loader::stored(const tinygltf::Accessor& a, const std::string& al, size_t element) {
  const Bytes b = view_bytes(a.bufferView, al);
  const tinygltf::BufferView& v = m_.bufferViews[size_t(a.bufferView)];
  const std::string vl = "bufferView " + std::to_string(a.bufferView) + " (of " + al + ")";
  const size_t stride = v.byteStride != 0 ? v.byteStride : element;
  if (stride < element)
    fail(vl + " has byteStride " + std::to_string(stride) + ", smaller than the " +
         std::to_string(element) + "-byte elements of " + al);
  const size_t room = b.size - std::min(b.size, a.byteOffset);
  if (a.count > 0 && (element > room || (a.count - 1) > (room - element) / stride))
    fail(al + " reads past the end of bufferView " + std::to_string(a.bufferView) + " (" +
         std::to_string(a.count) + " elements of " + std::to_string(element) + " bytes, stride " +
         std::to_string(stride) + ", from offset " + std::to_string(a.byteOffset) + " in " +
         std::to_string(b.size) + " bytes)");
  return View{
      b.data + a.byteOffset, stride,       a.count,
      a.componentType,       a.normalized, tinygltf::GetNumComponentsInType(uint32_t(a.type))};
}

// The bufferView's elements (or zeros without one) copied tightly packed, then the sparse
// substitution; made once per accessor.
View Loader::synthesized(int index, const tinygltf::Accessor& a, const std::string& al,
                         size_t element) {
  auto it = synthesized_.find(index);
  if (it == synthesized_.end()) {
    std::vector<unsigned char> data;
    if (a.bufferView >= 0) {
      const View base = stored(a, al, element);
      data.resize(a.count * element);
      for (size_t i = 0; i < a.count; ++i)
        std::memcpy(data.data() + i * element, base.base + i * base.stride, element);
    } else {
      if (a.count > kMaxSynthesized / element)
        fail(al + " has no bufferView and " + std::to_string(a.count) + " elements of " +
             std::to_string(element) + " bytes, more than the 256 MiB of zeros allowed");
      data.assign(a.count * element, 0);
    }
    if (a.sparse.isSparse) substitute(a, al, element, data);
    it = synthesized_.emplace(index, std::move(data)).first;
  }
  return View{it->second.data(), element,      a.count,
              a.componentType,   a.normalized, tinygltf::GetNumComponentsInType(uint32_t(a.type))};
}

// glTF 2.0 "Sparse Accessors": count in 1 .. accessor count, indices strictly increasing and
// below the accessor count, values tightly packed elements of the accessor's type.
void Loader::substitute(const tinygltf::Accessor& a, const std::string& al, size_t element,
                        std::vector<unsigned char>& data) {
  const auto& s = a.sparse;
  const std::string sl = al + " sparse";
  if (s.count < 1 || uint64_t(s.count) > a.count)
    fail(sl + " count " + std::to_string(s.count) + " is not within 1 .. " +
         std::to_string(a.count) + " (the accessor's count)");
  const int ic = s.indices.componentType;
  const size_t isize = ic == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
                       : ic == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                       : ic == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT   ? 4
                                                                      : 0;
  if (isize == 0)
    fail(sl + " indices have componentType " + component_name(ic) +
         "; expected UNSIGNED_BYTE or UNSIGNED_SHORT or UNSIGNED_INT");
  const size_t n = size_t(s.count);
  const Bytes ib = span(s.indices.bufferView, s.indices.byteOffset, n * isize, sl + " indices");
  const Bytes vb = span(s.values.bufferView, s.values.byteOffset, n * element, sl + " values");
  uint32_t previous = 0;
  for (size_t k = 0; k < n; ++k) {
    uint32_t i = 0;
    if (isize == 1) i = ib.data[k];
    if (isize == 2) i = uint32_t(ib.data[2 * k]) | uint32_t(ib.data[2 * k + 1]) << 8;
    if (isize == 4) std::memcpy(&i, ib.data + 4 * k, 4);  // glTF is little-endian, as we are
    if (i >= a.count)
      fail(sl + " index " + std::to_string(k) + " is " + std::to_string(i) + ", out of range for " +
           std::to_string(a.count) + " elements");
    if (k > 0 && i <= previous)
      fail(sl + " indices are not strictly increasing (index " + std::to_string(k) + " is " +
           std::to_string(i) + " after " + std::to_string(previous) + ")");
    previous = i;
    std::memcpy(data.data() + size_t(i) * element, vb.data + k * element, element);
  }
}

// `length` bytes from `offset` in bufferView `view`.
Bytes Loader::span(int view, int offset, size_t length, const std::string& who) {
  const Bytes b = view_bytes(view, who);
  if (offset < 0 || size_t(offset) > b.size || length > b.size - size_t(offset))
    fail(who + " read past the end of bufferView " + std::to_string(view) + " (" +
         std::to_string(length) + " bytes from offset " + std::to_string(offset) + " in " +
         std::to_string(b.size) + " bytes)");
  return {b.data + offset, length};
}

// The bytes of a bufferView: a range of its buffer, or the decoded EXT_meshopt_compression data.
Bytes Loader::view_bytes(int index, const std::string& who) {
  if (index < 0 || size_t(index) >= m_.bufferViews.size())
    fail(who + " refers to " + absent("bufferView", index, m_.bufferViews.size()));
  const tinygltf::BufferView& v = m_.bufferViews[size_t(index)];
  const std::string vl = "bufferView " + std::to_string(index) + " (of " + who + ")";
  if (v.extensions.count("EXT_meshopt_compression")) return meshopt_view(index, vl);
  if (v.buffer < 0 || size_t(v.buffer) >= m_.buffers.size())
    fail(vl + " refers to " + absent("buffer", v.buffer, m_.buffers.size()));
  if (pre_.placeholders.count(size_t(v.buffer)))
    fail(vl + " reads buffer " + std::to_string(v.buffer) +
         ", which has no data (a fallback buffer), and is not compressed with "
         "EXT_meshopt_compression");
  const size_t size = m_.buffers[size_t(v.buffer)].data.size();
  if (v.byteOffset > size || v.byteLength > size - v.byteOffset)
    fail(vl + " (offset " + std::to_string(v.byteOffset) + ", length " +
         std::to_string(v.byteLength) + ") extends past the end of buffer " +
         std::to_string(v.buffer) + " (" + std::to_string(size) + " bytes)");
  return {m_.buffers[size_t(v.buffer)].data.data() + v.byteOffset, v.byteLength};
}

// EXT_meshopt_compression: the extension's buffer range holds `count` elements of `byteStride`
// bytes compressed in `mode`, then `filter`ed; decoded they fill the parent bufferView, whose
// byteLength must be count x byteStride (and whose byteStride, if any, must match).
Bytes Loader::meshopt_view(int index, const std::string& vl) {
  if (const auto it = decoded_views_.find(index); it != decoded_views_.end())
    return {it->second.data(), it->second.size()};
  const tinygltf::BufferView& v = m_.bufferViews[size_t(index)];
  const tinygltf::Value& e = v.extensions.at("EXT_meshopt_compression");
  const std::string el = vl + " EXT_meshopt_compression";
  if (!e.IsObject()) fail(el + " is not an object");
  auto integer = [&](const char* key, bool required) -> uint64_t {
    if (!e.Has(key)) {
      if (required) fail(el + " has no " + key);
      return 0;
    }
    const tinygltf::Value& x = e.Get(key);
    const double d = x.IsNumber() ? x.GetNumberAsDouble() : -1.0;
    if (!(d >= 0.0 && d <= 9007199254740992.0 && d == std::floor(d)))
      fail(el + ": " + key + " is not a non-negative integer");
    return uint64_t(d);
  };
  auto name = [&](const char* key, const char* fallback) -> std::string {
    if (!e.Has(key)) {
      if (!fallback) fail(el + " has no " + key);
      return fallback;
    }
    if (!e.Get(key).IsString()) fail(el + ": " + key + " is not a string");
    return e.Get(key).Get<std::string>();
  };
  const uint64_t buffer = integer("buffer", true), offset = integer("byteOffset", false),
                 length = integer("byteLength", true), stride = integer("byteStride", true),
                 count = integer("count", true);
  const std::string mode_s = name("mode", nullptr), filter_s = name("filter", "NONE");
  const MeshoptMode mode = mode_s == "ATTRIBUTES"  ? MeshoptMode::Attributes
                           : mode_s == "TRIANGLES" ? MeshoptMode::Triangles
                                                   : MeshoptMode::Indices;
  if (mode_s != "ATTRIBUTES" && mode_s != "TRIANGLES" && mode_s != "INDICES")
    fail(el + " has mode '" + mode_s + "'; expected ATTRIBUTES, TRIANGLES or INDICES");
  static const std::map<std::string, MeshoptFilter> filters = {
      {"NONE", MeshoptFilter::None},
      {"OCTAHEDRAL", MeshoptFilter::Octahedral},
      {"QUATERNION", MeshoptFilter::Quaternion},
      {"EXPONENTIAL", MeshoptFilter::Exponential}};
  const auto filter = filters.find(filter_s);
  if (filter == filters.end())
    fail(el + " has filter '" + filter_s +
         "'; expected NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
  if (v.byteStride != 0 && v.byteStride != stride)
    fail(vl + " has byteStride " + std::to_string(v.byteStride) +
         " but its EXT_meshopt_compression byteStride is " + std::to_string(stride));
  if (stride != 0 && (count > v.byteLength / stride || count * stride != v.byteLength))
    fail(el + ": count x byteStride (" + std::to_string(count) + " x " + std::to_string(stride) +
         ") is not the bufferView's byteLength (" + std::to_string(v.byteLength) + ")");
  if (buffer >= m_.buffers.size())
    fail(el + " refers to " + absent("buffer", double(buffer), m_.buffers.size()));
  if (pre_.placeholders.count(size_t(buffer)))
    fail(el + " reads buffer " + std::to_string(buffer) +
         ", which has no data (a fallback buffer)");
  const std::vector<unsigned char>& data = m_.buffers[size_t(buffer)].data;
  if (offset > data.size() || length > data.size() - offset)
    fail(el + " (offset " + std::to_string(offset) + ", length " + std::to_string(length) +
         ") extends past the end of buffer " + std::to_string(buffer) + " (" +
         std::to_string(data.size()) + " bytes)");
  std::vector<unsigned char> decoded;
  try {
    decoded =
        decode_meshopt(data.data() + offset, size_t(length), count, stride, mode, filter->second);
  } catch (const DecodeError& x) {
    fail(el + ": " + x.what());
  }
  const auto& slot = decoded_views_.emplace(index, std::move(decoded)).first->second;
  return {slot.data(), slot.size()};
}

}  // namespace pb::gltf
