// The glTF loader's accessors and primitives (see gltf_loader_impl.h).
#include "gltf_loader_impl.h"

#include <algorithm>
#include <climits>

namespace pb::gltf {

View Loader::accessor(int index, const std::string& ctx, std::initializer_list<int> components,
                      int type) const {
  if (index < 0 || size_t(index) >= m_.accessors.size())
    fail(ctx + " refers to " + absent("accessor", index, m_.accessors.size()));
  const tinygltf::Accessor& a = m_.accessors[size_t(index)];
  const std::string al = ctx + " accessor " + std::to_string(index);
  if (a.sparse.isSparse) fail(al + " is sparse; sparse accessors are not supported");
  if (a.type != type) fail(al + " has type " + type_name(a.type) + "; expected " + type_name(type));
  if (std::find(components.begin(), components.end(), a.componentType) == components.end()) {
    std::string want;
    for (int c : components) want += (want.empty() ? "" : " or ") + component_name(c);
    fail(al + " has componentType " + component_name(a.componentType) + "; expected " + want);
  }
  if (a.bufferView < 0) fail(al + " has no bufferView; accessors without data are not supported");
  if (size_t(a.bufferView) >= m_.bufferViews.size())
    fail(al + " refers to " + absent("bufferView", a.bufferView, m_.bufferViews.size()));
  const tinygltf::BufferView& v = m_.bufferViews[size_t(a.bufferView)];
  const std::string vl = "bufferView " + std::to_string(a.bufferView) + " (of " + al + ")";
  if (v.buffer < 0 || size_t(v.buffer) >= m_.buffers.size())
    fail(vl + " refers to " + absent("buffer", v.buffer, m_.buffers.size()));
  const size_t size = m_.buffers[size_t(v.buffer)].data.size();
  if (v.byteOffset > size || v.byteLength > size - v.byteOffset)
    fail(vl + " (offset " + std::to_string(v.byteOffset) + ", length " +
         std::to_string(v.byteLength) + ") extends past the end of buffer " +
         std::to_string(v.buffer) + " (" + std::to_string(size) + " bytes)");
  const size_t element = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)) *
                                tinygltf::GetNumComponentsInType(uint32_t(a.type)));
  const size_t stride = v.byteStride != 0 ? v.byteStride : element;
  if (stride < element)
    fail(vl + " has byteStride " + std::to_string(stride) + ", smaller than the " +
         std::to_string(element) + "-byte elements of " + al);
  const size_t room = v.byteLength - std::min(v.byteLength, a.byteOffset);
  if (a.count > 0 && (element > room || (a.count - 1) > (room - element) / stride))
    fail(al + " reads past the end of bufferView " + std::to_string(a.bufferView) + " (" +
         std::to_string(a.count) + " elements of " + std::to_string(element) + " bytes, stride " +
         std::to_string(stride) + ", from offset " + std::to_string(a.byteOffset) + " in " +
         std::to_string(v.byteLength) + " bytes)");
  return View{m_.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset, stride,
              a.count, a.componentType};
}

void Loader::add_primitive(size_t mesh_index, size_t p, const Xform& xf) {
  const tinygltf::Mesh& gm = m_.meshes[mesh_index];
  const tinygltf::Primitive& prim = gm.primitives[p];
  const std::string ml = label("mesh", gm.name, mesh_index);
  const std::string where = ml + " primitive " + std::to_string(p);
  if (prim.mode != TINYGLTF_MODE_TRIANGLES)
    fail(where + " uses mode " + mode_name(prim.mode) + "; only TRIANGLES is supported");
  if (!prim.targets.empty()) warn(ml + ": morph targets are ignored");
  const auto pit = prim.attributes.find("POSITION");
  if (pit == prim.attributes.end()) fail(where + " has no POSITION attribute");
  constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
  const View pos = accessor(pit->second, where + " POSITION", {kFloat}, TINYGLTF_TYPE_VEC3);
  if (pos.count > UINT32_MAX) fail(where + " has more than 2^32 vertices");
  Mesh out;
  out.name = gm.name.empty() ? "mesh " + std::to_string(mesh_index) : gm.name;
  out.positions.resize(pos.count);
  for (size_t i = 0; i < pos.count; ++i) {
    const dvec3 local = pos.vec3f(i), w = xf.point(local);
    if (!is_finite(vec3(local)))
      fail(ml + " has a non-finite vertex coordinate (POSITION, vertex " + std::to_string(i) + ")");
    if (!(std::max({std::abs(w.x), std::abs(w.y), std::abs(w.z)}) <= kMaxCoordinate))
      fail(ml + " has a vertex coordinate beyond the limit of 1e10 in world space (vertex " +
           std::to_string(i) + ")");
    out.positions[i] = vec3(w);
  }
  if (const auto nit = prim.attributes.find("NORMAL"); nit != prim.attributes.end()) {
    const View nor = accessor(nit->second, where + " NORMAL", {kFloat}, TINYGLTF_TYPE_VEC3);
    if (nor.count != pos.count)
      fail(where + " has " + std::to_string(nor.count) + " normals for " +
           std::to_string(pos.count) + " positions");
    const dmat3 normal_matrix = glm::transpose(glm::inverse(xf.linear));
    out.normals.resize(nor.count);
    for (size_t i = 0; i < nor.count; ++i) {
      const dvec3 local = nor.vec3f(i), w = normal_matrix * local;
      if (!is_finite(vec3(local)))
        fail(ml + " has a non-finite vertex coordinate (NORMAL, vertex " + std::to_string(i) + ")");
      const dvec3 unit = w / glm::length(w);
      out.normals[i] = vec3(unit);
      if (!(std::abs(glm::length(unit) - 1.0) < 1e-6)) {
        warn(ml + ": zero or non-finite normals after transform; its normals are dropped");
        out.normals.clear();
        break;
      }
    }
  }
  std::vector<uint32_t> idx;
  if (prim.indices >= 0) {
    const View iv =
        accessor(prim.indices, where + " indices",
                 {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                 TINYGLTF_TYPE_SCALAR);
    idx.resize(iv.count);
    for (size_t i = 0; i < iv.count; ++i) {
      idx[i] = iv.component == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? iv.get<uint8_t>(i, 0)
               : iv.component == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? iv.get<uint16_t>(i, 0)
                                                                        : iv.get<uint32_t>(i, 0);
      if (idx[i] >= pos.count)
        fail(where + " indices accessor " + std::to_string(prim.indices) + ": index " +
             std::to_string(i) + " has value " + std::to_string(idx[i]) + ", out of range for " +
             std::to_string(pos.count) + " vertices");
    }
    if (idx.size() % 3 != 0)
      fail(where + " has " + std::to_string(idx.size()) + " indices, not a multiple of 3");
  } else {
    if (pos.count % 3 != 0)
      fail(where + " has " + std::to_string(pos.count) + " vertices, not a multiple of 3, and " +
           "no indices");
    idx.resize(pos.count);
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
  }
  out.material = material(prim.material, where);
  const bool flip = xf.det < 0.0;  // a mirroring transform: keep the counter-clockwise front
  for (size_t t = 0; t < idx.size(); t += 3) {
    const uint32_t a = idx[t], b = idx[t + (flip ? 2 : 1)], c = idx[t + (flip ? 1 : 2)];
    if (degenerate(out.positions, a, b, c)) {
      ++scene_.degenerate_triangles;
      continue;
    }
    out.indices.insert(out.indices.end(), {a, b, c});
  }
  if (!out.indices.empty()) scene_.meshes.push_back(std::move(out));
}

// extensions[name][key] as a number, or fallback when absent; a present non-number is an error.
}  // namespace pb::gltf
