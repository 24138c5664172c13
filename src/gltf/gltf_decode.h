// Decoders for compressed glTF geometry: KHR_draco_mesh_compression (Draco) and
// EXT_meshopt_compression (meshoptimizer). Only src/gltf/gltf_decode.cpp includes the two
// libraries; the loader (src/gltf/gltf_geometry.cpp, src/gltf/gltf_accessor.cpp) sees these plain
// types. Failures throw DecodeError, whose message the loader prefixes with the file and the glTF
// object.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace pb::gltf {

class DecodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One attribute to take from a Draco mesh: its unique id (the extension's "attributes" map),
// and the layout of the glTF accessor it fills (componentType code, components per element).
struct DracoRequest {
  int unique_id = 0;
  int component = 0;
  int components = 0;
};

struct DracoMesh {
  size_t points = 0;              // vertices (Draco "points")
  std::vector<uint32_t> indices;  // three point indices per face
  // Per request, in order: points x components values of the requested componentType, packed
  // (the bytes an uncompressed accessor with no byteStride would hold).
  std::vector<std::vector<unsigned char>> attributes;
};

// Decodes a Draco mesh (or point cloud, which has no faces). Throws DecodeError when the bytes
// are not a Draco geometry, an id is absent, or an attribute's component count or values do not
// fit the request.
DracoMesh decode_draco(const unsigned char* data, size_t size,
                       const std::vector<DracoRequest>& want);

enum class MeshoptMode { Attributes, Triangles, Indices };
enum class MeshoptFilter { None, Octahedral, Quaternion, Exponential };

// Decodes `count` elements of `stride` bytes from `size` compressed bytes, then applies the
// filter. The extension's rules on stride, count and filter are checked first (meshoptimizer
// asserts on them), and so is the smallest compressed size the codecs can reach, so that a
// hostile count cannot make the output buffer arbitrarily large. Throws DecodeError.
std::vector<unsigned char> decode_meshopt(const unsigned char* data, size_t size, uint64_t count,
                                          uint64_t stride, MeshoptMode mode, MeshoptFilter filter);

}  // namespace pb::gltf
