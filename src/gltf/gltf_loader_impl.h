// The glTF loader's internals, shared by its translation units (src/gltf/gltf_loader.cpp: parsing,
// the node walk and the final checks; src/gltf/gltf_accessor.cpp: accessors, sparse substitution
// and EXT_meshopt_compression bufferViews; src/gltf/gltf_geometry.cpp: primitives, quantised
// attributes and KHR_draco_mesh_compression; src/gltf/gltf_material.cpp: materials, lights and
// cameras; src/gltf/gltf_texture.cpp: textures, images and tangents). Only these files see tinygltf
// types.
#pragma once

#include "gltf/gltf_loader.h"

#include "gltf/gltf_prepass.h"
#include "gltf/gltf_support.h"

#include <tiny_gltf.h>

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace pb::gltf {

using glm::dmat3;
using glm::dmat4;

inline constexpr double kMaxCoordinate = 1e10;  // |world coordinate| limit
inline constexpr double kRecentreRatio = 64.0;  // distance / size past which a model is centred
inline constexpr int kMaxDepth = 1000;          // node hierarchy depth limit
inline constexpr int kVec3OrVec4 = -1;          // an accessor type COLOR_n may have
// EXT_mesh_gpu_instancing copies each instance's triangles: at most this many in all (about
// 6 GB of triangles, vertices and their acceleration structure).
inline constexpr uint64_t kMaxInstancedTriangles = uint64_t(1) << 26;

inline bool fits_float(double v) {
  return std::abs(v) <= double(std::numeric_limits<float>::max());
}

// Bytes of a bufferView (or a part of one), validated.
struct Bytes {
  const unsigned char* data = nullptr;
  size_t size = 0;
};

// Where a primitive's vertices go in world space (before the scene's origin is taken off): one
// transform for all, the node's, or one per vertex, a skin's blend of its joint matrices
// (glTF 2.0 "Skins"; gltf_deform.cpp).
struct Placement {
  const Xform* rigid = nullptr;
  dmat3 rigid_normal{1.0};     // the node's inverse transpose
  std::vector<dmat4> skinned;  // per vertex, when skinned
  bool flip = false;           // the counter-clockwise front is mirrored
  explicit Placement(const Xform& xf)
      : rigid(&xf), rigid_normal(glm::transpose(glm::inverse(xf.linear))), flip(xf.det < 0.0) {}
  dvec3 point(size_t i, const dvec3& p) const {
    return skinned.empty() ? rigid->point(p) : dvec3(skinned[i] * glm::dvec4(p, 1.0));
  }
  dvec3 direction(size_t i, const dvec3& d) const {
    return skinned.empty() ? rigid->direction(d) : dmat3(skinned[i]) * d;
  }
  // The normal's direction (not unit): the inverse transpose, for a skinned vertex its cofactor
  // matrix times the determinant's sign (0 where the blend is singular).
  dvec3 normal(size_t i, const dvec3& n) const;
};

// What a node asks of its mesh: its world transform, the morph target weights (the node's, else
// the mesh's) and its skin (-1: none).
struct Instance {
  const Xform* xf = nullptr;
  const std::vector<double>* weights = nullptr;
  int skin = -1;
  std::string label;  // the node, for messages
};

// A KHR_draco_mesh_compression primitive, decoded: the attributes the renderer reads, in the
// layout of their glTF accessors, and the faces.
struct DracoPrimitive {
  size_t points = 0;
  std::vector<uint32_t> indices;
  std::map<std::string, std::vector<unsigned char>> attributes;  // by glTF attribute name
};

class Loader {
 public:
  // `held`: the bytes of the file and of the buffers and images it names, which count against
  // `max_memory` with the decoded texels.
  Loader(const std::string& file, const tinygltf::Model& model, const Prepass& pre,
         uint64_t max_memory = UINT64_MAX, uint64_t held = 0, bool any_texture_format = false)
      : file_(file),
        m_(model),
        pre_(pre),
        max_memory_(max_memory),
        held_bytes_(held),
        any_texture_format_(any_texture_format) {}
  Scene run(const std::vector<std::string>& parse_warnings);

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw SceneError(file_ + ": " + one_line(what));
  }
  void warn(const std::string& w) {
    if (warned_.insert(w).second) scene_.warnings.push_back(w);
  }
  void check_extensions();
  void walk(int root, const std::string& from);
  void visit(const tinygltf::Node& n, const std::string& nl, const Xform& xf);
  dmat4 local_matrix(const tinygltf::Node& n, const std::string& nl) const;
  // gltf_accessor.cpp
  const tinygltf::Accessor& header(int index, const std::string& ctx,
                                   std::initializer_list<int> components, int type,
                                   std::string& al) const;
  View accessor(int index, const std::string& ctx, std::initializer_list<int> components, int type);
  View stored(const tinygltf::Accessor& a, const std::string& al, size_t element);
  View synthesized(int index, const tinygltf::Accessor& a, const std::string& al, size_t element);
  void substitute(const tinygltf::Accessor& a, const std::string& al, size_t element,
                  std::vector<unsigned char>& data);
  Bytes view_bytes(int index, const std::string& who);
  Bytes span(int view, int offset, size_t length, const std::string& who);
  Bytes meshopt_view(int index, const std::string& vl);
  // gltf_geometry.cpp
  const DracoPrimitive* draco(size_t mesh, size_t prim, const std::string& where);
  std::optional<View> attribute(const tinygltf::Primitive& prim, const DracoPrimitive* draco,
                                const std::string& name, const std::string& where);
  std::vector<uint32_t> indices(size_t mesh, size_t prim, const DracoPrimitive* draco,
                                size_t vertices, const std::string& where);
  void add_primitive(size_t mesh, size_t prim, const Instance& inst);
  // add_primitive()'s phases: the mode, the attributes, the triangles and a missing set's warning.
  bool drawn_mode(const tinygltf::Primitive& prim, const std::string& where);
  void read_positions(Mesh& out, const View& pos, const std::vector<dvec3>& moved,
                      const Placement& place, const std::string& ml);
  void read_normals(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                    const Instance& inst, const Placement& place, size_t vertices,
                    const std::string& ml, const std::string& where);
  void read_texcoords(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                      size_t vertices, const std::string& ml, const std::string& where);
  void read_colors(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                   size_t vertices, const std::string& ml, const std::string& where);
  void add_triangles(Mesh& out, const std::vector<uint32_t>& idx, bool flip);
  void warn_missing_texcoords(const Mesh& out, const std::string& ml);
  // gltf_deform.cpp: morph targets at the instance's weights, skins at the joints' poses.
  std::vector<dvec3> morph_offsets(const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                                   const Instance& inst, const char* attribute, size_t count,
                                   const std::string& where);
  Placement placement(const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                      const Instance& inst, size_t count, const std::string& where);
  const dmat4& node_world(int index, const std::string& from);
  // EXT_mesh_gpu_instancing: each instance's T * R * S, in the node's frame (none without it).
  std::vector<dmat4> instances(const tinygltf::Node& n, const std::string& nl);
  uint32_t material(int index, const std::string& where);
  Material convert_material(size_t index);
  void specular_glossiness(const tinygltf::ExtensionMap& ext, const std::string& ml, Material& out);
  double ext_number(const tinygltf::ExtensionMap& ext, const std::string& owner, const char* name,
                    const char* key, double fallback) const;
  // Three numbers in [0, hi], or nullopt when absent.
  std::optional<vec3> ext_color(const tinygltf::ExtensionMap& ext, const std::string& owner,
                                const char* name, const char* key, double hi) const;
  // gltf_texture.cpp
  TextureRef texture(int index, int tex_coord, const tinygltf::ExtensionMap& info_ext,
                     const std::string& where);
  TextureRef ext_texture(const tinygltf::ExtensionMap& ext, const std::string& owner,
                         const char* name, const char* key);
  int32_t image(int index, const std::string& where);
  void add_tangents(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                    const Placement& place, const std::vector<dvec3>& offsets,
                    const std::string& where);
  void add_light(const tinygltf::Node& n, const std::string& nl, const Xform& xf);
  void add_camera(int index, const std::string& nl, const Xform& xf);
  vec3 origin(const Xform& xf, const std::string& nl) const;
  void finish();
  void measure(const tinygltf::Node& n, const std::string& nl, const Xform& xf);
  void measure_mesh(const tinygltf::Node& n, const Xform& xf);
  void choose_origin();

  const std::string& file_;
  const tinygltf::Model& m_;
  const Prepass& pre_;
  std::map<int, std::vector<unsigned char>> decoded_views_;  // EXT_meshopt_compression
  std::map<int, std::vector<unsigned char>> synthesized_;    // sparse or without bufferView
  std::map<std::pair<size_t, size_t>, DracoPrimitive> draco_;
  Scene scene_;
  std::set<std::string> warned_;
  std::vector<char> visited_;
  std::vector<int64_t> material_slot_;  // glTF material -> Scene::materials index, -1 unused
  std::vector<int64_t> image_slot_;     // glTF image -> Scene::images index, -1 not decoded
  // A KTX2 image, or one in a format --texture-formats leaves out, warned about once.
  static constexpr int64_t kUndecodable = -2;
  // What the files and all decoded texels may take (LoadPolicy::max_memory), and what they take
  // so far. Images with the same bytes are decoded once: image_by_bytes_ maps their checksum to
  // the Scene::images index (the bytes compared before sharing).
  uint64_t max_memory_;
  uint64_t held_bytes_;
  std::multimap<uint64_t, int64_t> image_by_bytes_;
  std::vector<Bytes> image_source_;  // Scene::images index -> the encoded bytes
  bool any_texture_format_;          // LoadPolicy::any_texture_format
  int64_t default_material_ = -1;
  // Recentring (Loader::choose_origin): the world bounds of the POSITION accessors' min/max.
  dvec3 measured_lo_{INFINITY}, measured_hi_{-INFINITY};
  bool measuring_ = false;
  // Skins: every node's world matrix, computed on demand for the joints (node_world), and
  // its state (0 not yet, 1 under way: a cycle, 2 done).
  std::vector<dmat4> node_world_;
  std::vector<char> node_world_state_;
  std::vector<int> parent_;
  size_t unbound_vertices_ = 0;  // skinned vertices whose weights are all 0: one warning
  std::string first_unbound_;
  uint64_t instanced_triangles_ = 0;  // EXT_mesh_gpu_instancing copies so far
  size_t skipped_points_lines_ = 0;   // primitives of mode POINTS or LINES*, not drawn
  size_t draco_counts_differ_ = 0;    // Draco accessors whose count is not the decoded data's
  std::string first_draco_count_;     // the first of them, for the one warning
};

}  // namespace pb::gltf
