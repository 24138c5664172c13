// Draco and meshoptimizer decoding for the glTF loader; see gltf_decode.h. The only file that
// includes either library.
#include "gltf/gltf_decode.h"

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>

#include <cstring>
#include <memory>
#include <string>

namespace pb::gltf {

namespace {

// The attribute's values for every point, converted to T (draco's ConvertValue refuses values
// that do not fit T), packed.
template <class T>
std::vector<unsigned char> convert(const draco::PointAttribute& att, size_t points, int components,
                                   int id) {
  std::vector<unsigned char> out(points * size_t(components) * sizeof(T));
  T value[4] = {};
  for (size_t p = 0; p < points; ++p) {
    const draco::AttributeValueIndex v = att.mapped_index(draco::PointIndex(uint32_t(p)));
    if (!att.ConvertValue<T>(v, int8_t(components), value))
      throw DecodeError("Draco attribute " + std::to_string(id) + " has a value at point " +
                        std::to_string(p) + " that does not fit the accessor's componentType");
    std::memcpy(out.data() + p * size_t(components) * sizeof(T), value,
                size_t(components) * sizeof(T));
  }
  return out;
}

std::vector<unsigned char> attribute(const draco::Mesh& mesh, const DracoRequest& r) {
  const std::string al = "Draco attribute " + std::to_string(r.unique_id);
  if (r.unique_id < 0) throw DecodeError(al + ": a negative id");
  const draco::PointAttribute* att = mesh.GetAttributeByUniqueId(uint32_t(r.unique_id));
  if (!att) throw DecodeError(al + " is not in the compressed data");
  if (r.components < 1 || r.components > 4 || att->num_components() != r.components)
    throw DecodeError(al + " has " + std::to_string(att->num_components()) +
                      " components; the accessor has " + std::to_string(r.components));
  const size_t n = mesh.num_points();
  switch (r.component) {  // glTF componentType codes
    case 5120:
      return convert<int8_t>(*att, n, r.components, r.unique_id);
    case 5121:
      return convert<uint8_t>(*att, n, r.components, r.unique_id);
    case 5122:
      return convert<int16_t>(*att, n, r.components, r.unique_id);
    case 5123:
      return convert<uint16_t>(*att, n, r.components, r.unique_id);
    case 5125:
      return convert<uint32_t>(*att, n, r.components, r.unique_id);
    case 5126:
      return convert<float>(*att, n, r.components, r.unique_id);
    default:
      throw DecodeError(al + ": unsupported componentType " + std::to_string(r.component));
  }
}

}  // namespace

DracoMesh decode_draco(const unsigned char* data, size_t size,
                       const std::vector<DracoRequest>& want) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data), size);
  draco::Decoder decoder;
  draco::StatusOr<std::unique_ptr<draco::Mesh>> decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    throw DecodeError("the Draco data cannot be decoded (" + decoded.status().error_msg_string() +
                      ")");
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) throw DecodeError("the Draco data cannot be decoded (no mesh)");
  DracoMesh out;
  out.points = mesh->num_points();
  out.indices.reserve(size_t(mesh->num_faces()) * 3);
  for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
    for (int k = 0; k < 3; ++k) out.indices.push_back(mesh->face(f)[k].value());
  for (const DracoRequest& r : want) out.attributes.push_back(attribute(*mesh, r));
  return out;
}

std::vector<unsigned char> decode_meshopt(const unsigned char* data, size_t size, uint64_t count,
                                          uint64_t stride, MeshoptMode mode, MeshoptFilter filter) {
  const std::string s = std::to_string(stride);
  if (mode == MeshoptMode::Attributes) {
    if (stride == 0 || stride % 4 != 0 || stride > 256)
      throw DecodeError("mode ATTRIBUTES needs a byteStride divisible by 4 and at most 256, not " +
                        s);
  } else {
    if (stride != 2 && stride != 4)
      throw DecodeError("modes TRIANGLES and INDICES need a byteStride of 2 or 4, not " + s);
    if (filter != MeshoptFilter::None)
      throw DecodeError("modes TRIANGLES and INDICES take no filter");
    if (mode == MeshoptMode::Triangles && count % 3 != 0)
      throw DecodeError("mode TRIANGLES needs a count divisible by 3, not " +
                        std::to_string(count));
  }
  if ((filter == MeshoptFilter::Octahedral && stride != 4 && stride != 8) ||
      (filter == MeshoptFilter::Quaternion && stride != 8))
    throw DecodeError("this filter cannot decode a byteStride of " + s);
  // The densest codes (EXT_meshopt_compression appendix A): ATTRIBUTES spends at least 2 header
  // bits per 16 bytes (1/64), TRIANGLES one code byte per triangle, INDICES one byte per index.
  const uint64_t ratio = mode == MeshoptMode::Attributes  ? 64
                         : mode == MeshoptMode::Triangles ? 3 * stride
                                                          : stride;
  if (count > uint64_t(size) * ratio / stride)
    throw DecodeError(std::to_string(size) + " compressed bytes cannot hold " +
                      std::to_string(count) + " elements of " + s + " bytes");
  std::vector<unsigned char> out(size_t(count * stride));
  const int rc = mode == MeshoptMode::Attributes
                     ? meshopt_decodeVertexBuffer(out.data(), count, stride, data, size)
                 : mode == MeshoptMode::Triangles
                     ? meshopt_decodeIndexBuffer(out.data(), count, stride, data, size)
                     : meshopt_decodeIndexSequence(out.data(), count, stride, data, size);
  if (rc != 0)
    throw DecodeError("the compressed data is malformed (meshoptimizer error " +
                      std::to_string(rc) + ")");
  if (filter == MeshoptFilter::Octahedral) meshopt_decodeFilterOct(out.data(), count, stride);
  if (filter == MeshoptFilter::Quaternion) meshopt_decodeFilterQuat(out.data(), count, stride);
  if (filter == MeshoptFilter::Exponential) meshopt_decodeFilterExp(out.data(), count, stride);
  return out;
}

}  // namespace pb::gltf
