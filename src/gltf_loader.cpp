// glTF 2.0 -> pb::Scene. The only translation unit that includes tiny_gltf.h; the helpers that
// need no tinygltf types live in gltf_support.cpp.
//
// Phases: read the file (checking the GLB container), let tinygltf parse it (images are never
// decoded), walk the default scene's node tree composing transforms, and turn every
// node x primitive into a world-space Mesh, every KHR_lights_punctual light instance into a
// PunctualLight and every perspective camera into a Camera. Each accessor is validated before
// it is read. Errors throw SceneError("<file>: <one line>"); a Scene is only returned whole.
//
// Material rules (the README repeats them):
//  1. KHR_materials_transmission.transmissionFactor > 0 -> Dielectric (smooth glass) with
//     ior = KHR_materials_ior.ior (default 1.5; must be finite and >= 1) and
//     base_color = baseColorFactor.rgb as the transmission tint.
//  2. else pbrMetallicRoughness.metallicFactor >= 0.5 -> Mirror tinted by baseColorFactor.rgb.
//     glTF defaults apply: metallicFactor defaults to 1, so a material without
//     pbrMetallicRoughness is a mirror. roughnessFactor > 0.05 gets a warning (smooth mirror).
//  3. else Lambertian with base_color = baseColorFactor.rgb.
//  emission = emissiveFactor x KHR_materials_emissive_strength.emissiveStrength (default 1).
//  baseColorFactor.rgb must be within [0, 1] (a reflectance above 1 creates energy) and
//  emission finite and >= 0, or the file is rejected. Textures are never read (one warning per
//  file) and alpha is ignored. Primitives without a material share one Lambertian material
//  named "default" with base_color 0.8 (one warning).
#include "photonbound/gltf_loader.h"

#include "gltf_support.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>

namespace pb {
namespace {

using namespace gltf;  // NOLINT: the loader's own helpers
using glm::dmat3;
using glm::dmat4;

constexpr double kMaxCoordinate = 1e10;  // |world coordinate| limit
constexpr int kMaxDepth = 1000;          // node hierarchy depth limit

bool fits_float(double v) { return std::abs(v) <= double(std::numeric_limits<float>::max()); }

bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                const unsigned char*, int, void*) {
  return true;  // accept without decoding: textures are not used
}

// .glb by extension, otherwise glTF JSON. Every error tinygltf reports is fatal, even when it
// returns true (2.7 drops e.g. a baseColorFactor of the wrong length with only a message).
tinygltf::Model parse(const std::string& path, const std::vector<unsigned char>& bytes,
                      std::vector<std::string>& warnings) {
  const bool glb = std::filesystem::path(path).extension() == ".glb";
  const uint32_t size = glb ? check_glb(path, bytes) : uint32_t(bytes.size());
  const std::string dir = std::filesystem::path(path).parent_path().string();
  tinygltf::TinyGLTF reader;
  reader.SetImageLoader(&skip_image, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    ok = glb ? reader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), size, dir)
             : reader.LoadASCIIFromString(&model, &err, &warn,
                                          reinterpret_cast<const char*>(bytes.data()), size, dir);
  } catch (const std::exception& e) {
    err = e.what();
    ok = false;
  }
  const std::vector<std::string> errors = nonempty_lines(err), notes = nonempty_lines(warn);
  if (!ok || !errors.empty()) {
    std::string first = !errors.empty() ? errors[0] : !notes.empty() ? notes[0] : "unknown error";
    if (first.size() > 160) first = first.substr(0, 160) + "...";  // it may quote a data URI
    throw SceneError(path + ": malformed glTF: " + first);
  }
  for (const std::string& l : notes) warnings.push_back("glTF: " + l);
  return model;
}

class Loader {
 public:
  Loader(const std::string& file, const tinygltf::Model& model) : file_(file), m_(model) {}
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
  View accessor(int index, const std::string& ctx, std::initializer_list<int> components,
                int type) const;
  void add_primitive(size_t mesh, size_t prim, const Xform& xf);
  uint32_t material(int index, const std::string& where);
  Material convert_material(size_t index);
  double ext_number(const tinygltf::ExtensionMap& ext, const std::string& owner, const char* name,
                    const char* key, double fallback) const;
  void add_light(const tinygltf::Node& n, const std::string& nl, const Xform& xf);
  void add_camera(int index, const std::string& nl, const Xform& xf);
  vec3 origin(const Xform& xf, const std::string& nl) const;
  void finish();

  const std::string& file_;
  const tinygltf::Model& m_;
  Scene scene_;
  std::set<std::string> warned_;
  std::vector<char> visited_;
  std::vector<int64_t> material_slot_;  // glTF material -> Scene::materials index, -1 unused
  int64_t default_material_ = -1;
};

// The default scene (or scene 0, or every node that is nobody's child when there are none).
Scene Loader::run(const std::vector<std::string>& parse_warnings) {
  for (const std::string& w : parse_warnings) warn(w);
  check_extensions();
  visited_.assign(m_.nodes.size(), 0);
  material_slot_.assign(m_.materials.size(), -1);
  const int s = m_.defaultScene;
  if (s != -1 && (s < 0 || size_t(s) >= m_.scenes.size()))
    fail("\"scene\" refers to " + absent("scene", s, m_.scenes.size()));
  if (!m_.scenes.empty()) {
    const size_t si = s >= 0 ? size_t(s) : 0;
    for (int r : m_.scenes[si].nodes) walk(r, label("scene", m_.scenes[si].name, si));
  } else {
    std::vector<char> child(m_.nodes.size(), 0);
    for (const tinygltf::Node& n : m_.nodes)
      for (int c : n.children)
        if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = 1;
    for (size_t i = 0; i < child.size(); ++i)
      if (!child[i]) walk(int(i), "the file");
  }
  finish();
  return std::move(scene_);
}

void Loader::check_extensions() {
  static const std::set<std::string> known = {
      "KHR_lights_punctual",   "KHR_materials_transmission",
      "KHR_materials_ior",     "KHR_materials_emissive_strength",
      "KHR_texture_transform", "KHR_texture_basisu",
      "EXT_texture_webp"};  // textures: unread
  for (const std::string& e : m_.extensionsRequired)
    if (!known.count(e)) fail("requires extension '" + e + "', which is not supported");
  for (const std::string& e : m_.extensionsUsed)
    if (!known.count(e)) warn("extension '" + e + "' is ignored");
}

dmat4 Loader::local_matrix(const tinygltf::Node& n, const std::string& nl) const {
  auto check = [&](const std::vector<double>& v, size_t want, const char* what) {
    if (!v.empty() && v.size() != want)
      fail(nl + " has a " + what + " of " + std::to_string(v.size()) + " numbers; expected " +
           std::to_string(want));
  };
  check(n.matrix, 16, "matrix");
  check(n.translation, 3, "translation");
  check(n.rotation, 4, "rotation");
  check(n.scale, 3, "scale");
  dmat4 m(1.0);
  if (!n.matrix.empty()) {  // column-major
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[size_t(c * 4 + r)];
    return m;
  }
  if (!n.translation.empty())
    m[3] = glm::dvec4(n.translation[0], n.translation[1], n.translation[2], 1.0);
  dmat3 r(1.0);
  if (!n.rotation.empty() && !rotation_matrix(n.rotation, r))
    fail(nl + " has a zero or non-finite rotation quaternion");
  for (int c = 0; c < 3; ++c) m[c] = glm::dvec4(r[c] * (n.scale.empty() ? 1.0 : n.scale[c]), 0.0);
  return m;  // T * R * S
}

// Depth-first, parents before children, with an explicit stack (no recursion depth limit
// but kMaxDepth). Each node may be reached once: that rejects cycles and shared children.
void Loader::walk(int root, const std::string& root_from) {
  struct Pending {
    int index;
    int depth;
    dmat4 parent;
    std::string from;
  };
  std::vector<Pending> stack{{root, 0, dmat4(1.0), root_from}};
  while (!stack.empty()) {
    const Pending item = std::move(stack.back());
    stack.pop_back();
    if (item.index < 0 || size_t(item.index) >= m_.nodes.size())
      fail(item.from + " refers to " + absent("node", item.index, m_.nodes.size()));
    const tinygltf::Node& n = m_.nodes[size_t(item.index)];
    const std::string nl = label("node", n.name, size_t(item.index));
    if (item.depth > kMaxDepth)
      fail("the node hierarchy is deeper than " + std::to_string(kMaxDepth) + " levels");
    if (visited_[size_t(item.index)])
      fail(nl + " is reached twice: the node hierarchy has a cycle or a shared child");
    visited_[size_t(item.index)] = 1;
    const Xform xf(item.parent * local_matrix(n, nl));
    if (!xf.finite()) fail(nl + " has a non-finite transform");
    visit(n, nl, xf);
    for (auto c = n.children.rbegin(); c != n.children.rend(); ++c)
      stack.push_back({*c, item.depth + 1, xf.m, nl});
  }
}

// A node's own content: mesh instances, camera, light.
void Loader::visit(const tinygltf::Node& n, const std::string& nl, const Xform& xf) {
  if (n.skin != -1) warn(nl + ": skins are ignored; the mesh is drawn unposed");
  if (n.mesh != -1) {
    if (n.mesh < 0 || size_t(n.mesh) >= m_.meshes.size())
      fail(nl + " refers to " + absent("mesh", n.mesh, m_.meshes.size()));
    const tinygltf::Mesh& mesh = m_.meshes[size_t(n.mesh)];
    if (xf.singular())
      fail(nl + " has a singular transform (determinant " + num(xf.det) + "); cannot place " +
           label("mesh", mesh.name, size_t(n.mesh)));
    for (size_t p = 0; p < mesh.primitives.size(); ++p) add_primitive(size_t(n.mesh), p, xf);
  }
  if (n.camera != -1) add_camera(n.camera, nl, xf);
  if (n.extensions.count("KHR_lights_punctual")) add_light(n, nl, xf);
}

// Index, bufferView and buffer in range, type and componentType as expected, not sparse, and
// byteOffset + stride * (count - 1) + element size within the bufferView within the buffer.
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
double Loader::ext_number(const tinygltf::ExtensionMap& ext, const std::string& owner,
                          const char* name, const char* key, double fallback) const {
  const auto it = ext.find(name);
  if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key)) return fallback;
  const tinygltf::Value& v = it->second.Get(key);
  if (!v.IsNumber()) fail(owner + ": " + name + "." + key + " is not a number");
  return v.GetNumberAsDouble();
}

uint32_t Loader::material(int index, const std::string& where) {
  if (index == -1) {
    if (default_material_ < 0) {
      warn("primitives without a material use a default grey Lambertian material (0.8)");
      default_material_ = int64_t(scene_.materials.size());
      Material def;
      def.name = "default";
      scene_.materials.push_back(def);  // Lambertian, base_color 0.8
    }
    return uint32_t(default_material_);
  }
  if (index < 0 || size_t(index) >= m_.materials.size())
    fail(where + " refers to " + absent("material", index, m_.materials.size()));
  int64_t& slot = material_slot_[size_t(index)];
  if (slot < 0) {
    Material converted = convert_material(size_t(index));
    slot = int64_t(scene_.materials.size());
    scene_.materials.push_back(std::move(converted));
  }
  return uint32_t(slot);
}

Material Loader::convert_material(size_t index) {  // the rules are in the comment at the top
  const tinygltf::Material& gm = m_.materials[index];
  const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
  const std::string ml = label("material", gm.name, index);
  Material out;
  out.name = gm.name.empty() ? "material " + std::to_string(index) : gm.name;
  bool textured = pbr.baseColorTexture.index >= 0 || pbr.metallicRoughnessTexture.index >= 0 ||
                  gm.normalTexture.index >= 0 || gm.occlusionTexture.index >= 0 ||
                  gm.emissiveTexture.index >= 0;
  for (const auto& [name, value] : gm.extensions)  // e.g. transmissionTexture
    for (const std::string& key : value.Keys())
      textured |= key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0;
  if (textured) warn("textures are not read; factors are used");
  const std::vector<double>& bc = pbr.baseColorFactor;
  if (bc.size() < 3) fail(ml + ": baseColorFactor has fewer than 3 numbers");
  if (!std::all_of(bc.begin(), bc.begin() + 3, [](double v) { return v >= 0.0 && v <= 1.0; }))
    fail(ml + ": baseColorFactor (" + num(bc[0]) + ", " + num(bc[1]) + ", " + num(bc[2]) +
         ") is outside [0, 1] (a reflectance above 1 would create energy)");
  out.base_color = vec3(float(bc[0]), float(bc[1]), float(bc[2]));
  const tinygltf::ExtensionMap& ext = gm.extensions;
  const double transmission =
      ext_number(ext, ml, "KHR_materials_transmission", "transmissionFactor", 0.0);
  if (transmission > 0.0) {
    out.model = Reflection::Dielectric;
    const double ior = ext_number(ext, ml, "KHR_materials_ior", "ior", 1.5);
    if (!(ior >= 1.0 && fits_float(ior)))
      fail(ml + ": ior " + num(ior) + " must be finite and >= 1");
    out.ior = float(ior);
    if (transmission < 1.0)
      warn(ml + ": transmissionFactor " + num(transmission) + " treated as clear glass");
  } else if (pbr.metallicFactor >= 0.5) {
    out.model = Reflection::Mirror;
    if (pbr.roughnessFactor > 0.05)
      warn(ml + ": roughness " + num(pbr.roughnessFactor) + " treated as a smooth mirror");
  } else {
    out.model = Reflection::Lambertian;
  }
  const double strength =
      ext_number(ext, ml, "KHR_materials_emissive_strength", "emissiveStrength", 1.0);
  if (gm.emissiveFactor.size() != 3) fail(ml + ": emissiveFactor must have 3 numbers");
  for (int c = 0; c < 3; ++c) {
    const double e = gm.emissiveFactor[size_t(c)] * strength;
    if (!(e >= 0.0 && strength >= 0.0 && fits_float(e)))
      fail(ml + ": emission (emissiveFactor x emissiveStrength) must be finite and >= 0");
    out.emission[c] = float(e);
  }
  return out;
}

void Loader::add_light(const tinygltf::Node& n, const std::string& nl, const Xform& xf) {
  const tinygltf::Value& ext = n.extensions.at("KHR_lights_punctual");
  if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber())
    fail(nl + ": KHR_lights_punctual has no light index");
  const double li = ext.Get("light").GetNumberAsDouble();
  if (!(li >= 0.0 && li < double(m_.lights.size()) && li == std::floor(li)))
    fail(nl + " refers to " + absent("light", li, m_.lights.size()));
  const tinygltf::Light& gl = m_.lights[size_t(li)];
  const std::string ll = label("light", gl.name, size_t(li));
  PunctualLight out;
  out.name = gl.name.empty() ? "light " + num(li) : gl.name;
  if (gl.type == "directional")
    fail(ll + " is directional; only point and spot lights are supported");
  if (gl.type != "point" && gl.type != "spot") fail(ll + " has unknown type '" + gl.type + "'");
  const std::vector<double> color = gl.color.empty() ? std::vector<double>(3, 1.0) : gl.color;
  if (color.size() != 3) fail(ll + ": color must have 3 numbers");
  for (int c = 0; c < 3; ++c) {  // radiant intensity per channel = color x intensity
    const double v = color[size_t(c)] * gl.intensity;
    if (!(v >= 0.0 && gl.intensity >= 0.0 && color[size_t(c)] >= 0.0 && fits_float(v)))
      fail(ll + ": intensity and color must be finite and >= 0");
    out.intensity[c] = float(v);
  }
  if (gl.range > 0.0) warn(ll + ": range is ignored (inverse-square falloff)");
  out.position = origin(xf, nl);
  if (gl.type == "spot") {
    out.kind = PunctualKind::Spot;
    const double inner = gl.spot.innerConeAngle, outer = gl.spot.outerConeAngle;
    if (!(inner >= 0.0 && inner < outer && outer <= kPiD / 2))
      fail(ll + ": spot cone angles inner " + num(inner) + ", outer " + num(outer) +
           " must satisfy 0 <= inner < outer <= pi/2");
    out.cos_inner = float(std::cos(inner));
    out.cos_outer = float(std::cos(outer));
    const dvec3 d = xf.direction(dvec3(0.0, 0.0, -1.0));
    if (!(glm::length(d) > 0.0)) fail(ll + ": the spot direction is zero (" + nl + " is singular)");
    out.direction = vec3(glm::normalize(d));
  }
  scene_.lights.push_back(std::move(out));
}

void Loader::add_camera(int index, const std::string& nl, const Xform& xf) {
  if (index < 0 || size_t(index) >= m_.cameras.size())
    fail(nl + " refers to " + absent("camera", index, m_.cameras.size()));
  const tinygltf::Camera& gc = m_.cameras[size_t(index)];
  const std::string cl = label("camera", gc.name, size_t(index));
  if (gc.type != "perspective") {
    warn(cl + " is " + gc.type + " and is skipped; only perspective cameras are supported");
    return;
  }
  Camera out;
  out.name = gc.name.empty() ? "camera " + std::to_string(index) : gc.name;
  const double yfov = gc.perspective.yfov;
  if (!(yfov > 0.0 && yfov < kPiD)) fail(cl + ": yfov " + num(yfov) + " must be in (0, pi)");
  out.yfov = float(yfov);
  if (gc.perspective.aspectRatio > 0.0 && fits_float(gc.perspective.aspectRatio))
    out.aspect = float(gc.perspective.aspectRatio);
  const dvec3 f = xf.direction(dvec3(0.0, 0.0, -1.0)), u = xf.direction(dvec3(0.0, 1.0, 0.0));
  const dvec3 fn = f / glm::length(f), uo = u - glm::dot(u, fn) * fn;  // Gram-Schmidt
  if (!(glm::length(f) > 0.0 && glm::length(uo) > 1e-9 * glm::length(u) && is_finite(vec3(uo))))
    fail(cl + ": " + nl + " has a degenerate transform (no forward or up direction)");
  out.position = origin(xf, nl);
  out.forward = vec3(fn);
  out.up = vec3(glm::normalize(uo));
  out.right = glm::normalize(glm::cross(out.forward, out.up));
  scene_.cameras.push_back(std::move(out));
}

vec3 Loader::origin(const Xform& xf, const std::string& nl) const {
  const dvec3 p = xf.point(dvec3(0.0));
  if (!(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) <= kMaxCoordinate))
    fail(nl + " is placed beyond the limit of 1e10 in world space");
  return vec3(p);
}

void Loader::finish() {
  if (scene_.degenerate_triangles > 0)
    warn(std::to_string(scene_.degenerate_triangles) + " degenerate triangles skipped");
  if (scene_.meshes.empty()) fail("no triangles");
  if (scene_.cameras.empty()) fail("no perspective camera");
  bool lit = false;
  for (const PunctualLight& l : scene_.lights) lit |= max_component(l.intensity) > 0.0f;
  for (const Mesh& m : scene_.meshes) lit |= scene_.materials[m.material].emits();
  if (!lit) fail("no light: the scene has no punctual light and no emissive triangles");
  // Photon flux is carried in float: the total emitted power (4 pi I per point light, an upper
  // bound for a spot; pi A Le per emissive triangle, summed over the channels) must fit, or the
  // light distribution overflows later with no file to name.
  double power = 0.0;
  for (const PunctualLight& l : scene_.lights)
    power += 4.0 * kPiD * (double(l.intensity.x) + l.intensity.y + l.intensity.z);
  for (const Mesh& m : scene_.meshes) {
    const vec3 le = scene_.materials[m.material].emission;
    if (!scene_.materials[m.material].emits()) continue;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      const dvec3 p0(m.positions[m.indices[t]]);
      const double area = 0.5 * glm::length(glm::cross(dvec3(m.positions[m.indices[t + 1]]) - p0,
                                                       dvec3(m.positions[m.indices[t + 2]]) - p0));
      power += kPiD * area * (double(le.x) + le.y + le.z);
    }
  }
  if (!(power <= double(std::numeric_limits<float>::max())))
    fail("the lights emit " + num(power) +
         " W in total, beyond the float range (3.4e+38) photon power is carried in");
  for (const Mesh& m : scene_.meshes)
    for (uint32_t i : m.indices) scene_.bounds.extend(m.positions[i]);
  scene_.source = file_;
}

}  // namespace

Scene load_gltf(const std::string& path) { return load_gltf_bytes(path, read_file(path)); }

Scene load_gltf_bytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::vector<std::string> warnings;
  const tinygltf::Model model = parse(path, bytes, warnings);
  return Loader(path, model).run(warnings);
}

}  // namespace pb
