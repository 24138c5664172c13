// The glTF loader's primitives (see gltf_loader_impl.h): POSITION, NORMAL, TEXCOORD_0/1, TANGENT
// and indices, read from accessors (gltf_accessor.cpp) or from the decoded
// KHR_draco_mesh_compression data, integer attributes dequantised (KHR_mesh_quantization), then
// placed in world space.
#include "gltf/gltf_decode.h"
#include "gltf/gltf_loader_impl.h"

#include <algorithm>
#include <climits>
#include <cmath>

namespace pb::gltf {

namespace {

constexpr std::initializer_list<int> kIndexComponents = {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT};

// The vertex attributes the renderer reads: their accessor type, and float or (normalised or
// not) 8- and 16-bit integers (KHR_mesh_quantization; it allows fewer combinations for NORMAL,
// but every one of these has one meaning).
int attribute_type(const std::string& name) {
  if (name == "TANGENT" || name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0)
    return TINYGLTF_TYPE_VEC4;
  if (name.rfind("COLOR_", 0) == 0) return kVec3OrVec4;
  return name.rfind("TEXCOORD_", 0) == 0 ? TINYGLTF_TYPE_VEC2 : TINYGLTF_TYPE_VEC3;
}
constexpr std::initializer_list<int> kAttributeComponents = {
    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
    TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};
const char* const kAttributes[] = {"POSITION",  "NORMAL",   "TEXCOORD_0", "TEXCOORD_1",
                                   "TANGENT",   "JOINTS_0", "WEIGHTS_0",  "JOINTS_1",
                                   "WEIGHTS_1", "JOINTS_2", "WEIGHTS_2",  "COLOR_0"};

// The texture coordinate sets a material's textures read.
bool uses_set(const Material& m, int set) {
  for (const TextureRef* t :
       {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
        &m.emissive_texture, &m.transmission_texture, &m.specular_texture,
        &m.specular_color_texture, &m.clearcoat_texture, &m.clearcoat_roughness_texture,
        &m.clearcoat_normal_texture, &m.sheen_color_texture, &m.sheen_roughness_texture,
        &m.specular_glossiness_texture, &m.diffuse_transmission_texture,
        &m.diffuse_transmission_color_texture})
    if (t->present() && t->texcoord == set) return true;
  return false;
}

// An integer member of an extension object, or -1 when absent or not an integer.
int ext_int(const tinygltf::Value& obj, const char* key) {
  if (!obj.IsObject() || !obj.Has(key) || !obj.Get(key).IsInt()) return -1;
  return obj.Get(key).GetNumberAsInt();
}

}  // namespace

// KHR_draco_mesh_compression: the extension's bufferView holds a Draco mesh; "attributes" maps
// glTF attribute names to Draco unique ids. The accessors of the attributes it maps (and of the
// indices) keep their type, componentType and count, which must match the decoded data; their
// bufferView (if any, an uncompressed fallback) is not read. Decoded once per primitive.
const DracoPrimitive* Loader::draco(size_t mesh, size_t p, const std::string& where) {
  const tinygltf::Primitive& prim = m_.meshes[mesh].primitives[p];
  const auto ext = prim.extensions.find("KHR_draco_mesh_compression");
  if (ext == prim.extensions.end()) return nullptr;
  if (const auto it = draco_.find({mesh, p}); it != draco_.end()) return &it->second;
  const std::string el = where + " KHR_draco_mesh_compression";
  const tinygltf::Value& e = ext->second;
  const int view = ext_int(e, "bufferView");
  if (view < 0) fail(el + " has no valid bufferView");
  if (!e.Has("attributes") || !e.Get("attributes").IsObject())
    fail(el + " has no attributes object");
  const tinygltf::Value& ids = e.Get("attributes");
  std::vector<DracoRequest> want;
  std::vector<std::string> names;
  for (const char* name : kAttributes) {
    if (!ids.Has(name)) continue;
    const int id = ext_int(ids, name);
    if (id < 0) fail(el + ": the id of " + name + " is not a non-negative integer");
    const auto a = prim.attributes.find(name);
    if (a == prim.attributes.end())
      fail(el + " maps " + name + ", which the primitive's attributes do not list");
    std::string al;
    const tinygltf::Accessor& acc =
        header(a->second, where + " " + name, kAttributeComponents, attribute_type(name), al);
    want.push_back({id, acc.componentType, tinygltf::GetNumComponentsInType(uint32_t(acc.type))});
    names.push_back(name);
  }
  const Bytes b = view_bytes(view, el);
  DracoMesh decoded;
  try {
    decoded = decode_draco(b.data, b.size, want);
  } catch (const DecodeError& x) {
    fail(el + ": " + x.what());
  }
  DracoPrimitive out;
  out.points = decoded.points;
  out.indices = std::move(decoded.indices);
  for (size_t k = 0; k < names.size(); ++k)
    out.attributes[names[k]] = std::move(decoded.attributes[k]);
  return &draco_.emplace(std::make_pair(mesh, p), std::move(out)).first->second;
}

// The primitive's attribute `name`, from the Draco data when the extension maps it.
std::optional<View> Loader::attribute(const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                                      const std::string& name, const std::string& where) {
  const auto it = prim.attributes.find(name);
  if (it == prim.attributes.end()) return std::nullopt;
  const std::string ctx = where + " " + name;
  const int type = attribute_type(name);
  const auto d = dp ? dp->attributes.find(name) : decltype(dp->attributes.end())();
  if (!dp || d == dp->attributes.end())
    return accessor(it->second, ctx, kAttributeComponents, type);
  std::string al;
  const tinygltf::Accessor& a = header(it->second, ctx, kAttributeComponents, type, al);
  // The Draco faces index the decoded points, so those are what the primitive is. Exporters
  // (COLLADA2GLTF's CesiumMilkTruck: 1856 against 1886) write the uncompressed count, which
  // differs where the encoder split points at seams; three.js and Cesium read the decoded data.
  if (a.count != dp->points && draco_counts_differ_++ == 0)
    first_draco_count_ = al + " has count " + std::to_string(a.count) + ", the Draco data " +
                         std::to_string(dp->points) + " points";
  const size_t element = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)) *
                                tinygltf::GetNumComponentsInType(uint32_t(a.type)));
  return View{d->second.data(), element,      dp->points,
              a.componentType,  a.normalized, tinygltf::GetNumComponentsInType(uint32_t(a.type))};
}

// Three per triangle (strips and fans unrolled), each below `vertices`: the Draco faces, the
// indices accessor, or 0, 1, 2, ... when there is none. tinygltf never sees an indices accessor
// without bufferView (gltf_prepass.h), so that one comes from the prepass.
std::vector<uint32_t> Loader::indices(size_t mesh, size_t p, const DracoPrimitive* dp,
                                      size_t vertices, const std::string& where) {
  const tinygltf::Primitive& prim = m_.meshes[mesh].primitives[p];
  int index = prim.indices;
  if (const auto it = pre_.indices.find({mesh, p}); it != pre_.indices.end()) index = it->second;
  const std::string il = where + " indices";
  std::vector<uint32_t> idx;
  if (dp) {
    if (index >= 0) {
      std::string al;
      const tinygltf::Accessor& a = header(index, il, kIndexComponents, TINYGLTF_TYPE_SCALAR, al);
      if (a.count != dp->indices.size() && draco_counts_differ_++ == 0)
        first_draco_count_ = al + " has count " + std::to_string(a.count) + ", the Draco data " +
                             std::to_string(dp->indices.size()) + " indices";
    }
    idx = dp->indices;
  } else if (index >= 0) {
    const View iv = accessor(index, il, kIndexComponents, TINYGLTF_TYPE_SCALAR);
    idx.resize(iv.count);
    for (size_t i = 0; i < iv.count; ++i)
      idx[i] = iv.component == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? iv.get<uint8_t>(i, 0)
               : iv.component == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? iv.get<uint16_t>(i, 0)
                                                                        : iv.get<uint32_t>(i, 0);
  } else {
    if (prim.mode == TINYGLTF_MODE_TRIANGLES && vertices % 3 != 0)
      fail(where + " has " + std::to_string(vertices) + " vertices, not a multiple of 3, and " +
           "no indices");
    idx.resize(vertices);
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
  }
  const std::string from = dp ? il + " (Draco faces)" : il + " accessor " + std::to_string(index);
  for (size_t i = 0; i < idx.size(); ++i)
    if (idx[i] >= vertices)
      fail(from + ": index " + std::to_string(i) + " has value " + std::to_string(idx[i]) +
           ", out of range for " + std::to_string(vertices) + " vertices");
  if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
    if (idx.size() % 3 != 0)
      fail(where + " has " + std::to_string(idx.size()) + " indices, not a multiple of 3");
    return idx;
  }
  // Strips and fans as glTF 2.0 section 3.7.2.1 defines their triangles: a strip's p_i is
  // (v_i, v_{i + 1 + i % 2}, v_{i + 2 - i % 2}), keeping every triangle's winding; a fan's is
  // (v_{i + 1}, v_{i + 2}, v_0).
  std::vector<uint32_t> tris;
  const bool strip = prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP;
  for (size_t i = 0; i + 2 < idx.size(); ++i)
    if (strip)
      tris.insert(tris.end(), {idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
    else
      tris.insert(tris.end(), {idx[i + 1], idx[i + 2], idx[0]});
  return tris;
}

// Whether the mode is drawn (glTF 2.0 section 3.7.2.1): triangles; points, lines warn; others fail.
bool Loader::drawn_mode(const tinygltf::Primitive& prim, const std::string& where) {
  // Points and lines have no area: nothing of theirs reflects light. A file that mixes them with
  // surfaces (a wireframe overlay, a point cloud beside a model) renders its surfaces.
  if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) {
    warn(where + " uses mode " + mode_name(prim.mode) +
         ": points and lines have no area and are not drawn");
    ++skipped_points_lines_;
    return false;
  }
  if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
    fail(where + " uses mode " + mode_name(prim.mode) + ", which glTF 2.0 does not define");
  return true;
}

// out.positions: POSITION plus the morph offsets, placed in world space, validated.
void Loader::read_positions(Mesh& out, const View& pos, const std::vector<dvec3>& moved,
                            const Placement& place, const std::string& ml) {
  out.positions.resize(pos.count);
  for (size_t i = 0; i < pos.count; ++i) {
    const dvec3 local = pos.vec3(i);
    if (!is_finite(vec3(local)))
      fail(ml + " has a non-finite vertex coordinate (POSITION, vertex " + std::to_string(i) + ")");
    const dvec3 w = place.point(i, moved.empty() ? local : local + moved[i]);
    if (!(std::max({std::abs(w.x), std::abs(w.y), std::abs(w.z)}) <= kMaxCoordinate))
      fail(ml + " has a vertex coordinate beyond the limit of 1e10 in world space (vertex " +
           std::to_string(i) + ")");
    out.positions[i] = vec3(w - scene_.origin);
  }
}

// out.normals: NORMAL (glTF 2.0 "Meshes") plus its morph offsets, placed; none if one vanishes.
void Loader::read_normals(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                          const Instance& inst, const Placement& place, size_t vertices,
                          const std::string& ml, const std::string& where) {
  const std::optional<View> nor = attribute(prim, dp, "NORMAL", where);
  if (!nor) return;
  if (nor->count != vertices)
    fail(where + " has " + std::to_string(nor->count) + " normals for " + std::to_string(vertices) +
         " positions");
  const std::vector<dvec3> bent = morph_offsets(prim, dp, inst, "NORMAL", vertices, where);
  out.normals.resize(nor->count);
  for (size_t i = 0; i < nor->count; ++i) {
    const dvec3 local = nor->vec3(i);
    if (!is_finite(vec3(local)))
      fail(ml + " has a non-finite vertex coordinate (NORMAL, vertex " + std::to_string(i) + ")");
    const dvec3 w = place.normal(i, bent.empty() ? local : local + bent[i]);
    const dvec3 unit = w / glm::length(w);
    out.normals[i] = vec3(unit);
    if (!(std::abs(glm::length(unit) - 1.0) < 1e-6)) {
      warn(ml + ": zero or non-finite normals after transform; its normals are dropped");
      out.normals.clear();
      break;
    }
  }
}

// out.texcoords: TEXCOORD_0 and TEXCOORD_1 (glTF 2.0 "Meshes"), validated.
void Loader::read_texcoords(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                            size_t vertices, const std::string& ml, const std::string& where) {
  for (int set = 0; set < 2; ++set) {
    const std::string name = "TEXCOORD_" + std::to_string(set);
    const std::optional<View> uv = attribute(prim, dp, name, where);
    if (!uv) continue;
    if (uv->count != vertices)
      fail(where + " has " + std::to_string(uv->count) + " " + name + " values for " +
           std::to_string(vertices) + " positions");
    std::vector<vec2>& dst = out.texcoords[set];
    dst.resize(uv->count);
    for (size_t i = 0; i < uv->count; ++i) {
      dst[i] = vec2(float(uv->scalar(i, 0)), float(uv->scalar(i, 1)));
      if (!std::isfinite(dst[i].x) || !std::isfinite(dst[i].y))
        fail(ml + " has a non-finite texture coordinate (" + name + ", vertex " +
             std::to_string(i) + ")");
    }
  }
}

// out.colors: COLOR_0 as RGBA in [0, 1] (glTF 2.0 "Meshes"), with its warnings.
void Loader::read_colors(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                         size_t vertices, const std::string& ml, const std::string& where) {
  const std::optional<View> col = attribute(prim, dp, "COLOR_0", where);
  if (!col) return;
  // glTF 2.0 "Meshes": COLOR_0 multiplies the base colour, as float or normalised unsigned
  // bytes or shorts in [0, 1]; an RGB attribute has alpha 1.
  if (col->count != vertices)
    fail(where + " has " + std::to_string(col->count) + " COLOR_0 values for " +
         std::to_string(vertices) + " positions");
  const bool integer = col->component != TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (col->component == TINYGLTF_COMPONENT_TYPE_BYTE ||
      col->component == TINYGLTF_COMPONENT_TYPE_SHORT)
    fail(where + " COLOR_0 has componentType " + component_name(col->component) +
         "; expected FLOAT, UNSIGNED_BYTE or UNSIGNED_SHORT");
  View v = *col;
  if (integer && !v.normalized) {
    warn(where + ": COLOR_0 is not marked normalized; read as normalised, as glTF requires");
    v.normalized = true;
  }
  out.colors.resize(v.count);
  bool clamped = false;
  for (size_t i = 0; i < v.count; ++i) {
    glm::vec4 c(1.0f);
    for (int k = 0; k < v.components; ++k) {
      const double x = v.scalar(i, k);
      if (!std::isfinite(x))
        fail(ml + " has a non-finite COLOR_0 value (vertex " + std::to_string(i) + ")");
      clamped = clamped || x < 0.0 || x > 1.0;
      c[k] = float(std::clamp(x, 0.0, 1.0));
    }
    out.colors[i] = c;
  }
  if (clamped) warn(where + ": COLOR_0 values outside [0, 1] are clamped to it");
}

// out.indices: the triangles of idx, front kept counter-clockwise, degenerate ones counted.
void Loader::add_triangles(Mesh& out, const std::vector<uint32_t>& idx, bool flip) {
  // flip: a mirroring transform; swapping two corners keeps the counter-clockwise front.
  for (size_t t = 0; t < idx.size(); t += 3) {
    const uint32_t a = idx[t], b = idx[t + (flip ? 2 : 1)], c = idx[t + (flip ? 1 : 2)];
    if (degenerate(out.positions, a, b, c)) {
      ++scene_.degenerate_triangles;
      continue;
    }
    out.indices.insert(out.indices.end(), {a, b, c});
  }
}

// The warning for each texture coordinate set the mesh's material reads and the mesh lacks.
void Loader::warn_missing_texcoords(const Mesh& out, const std::string& ml) {
  const Material& mat = scene_.materials[out.material];
  for (int set = 0; set < 2; ++set)
    if (uses_set(mat, set) && out.texcoords[set].empty())
      warn(ml + ": its material's textures read TEXCOORD_" + std::to_string(set) +
           ", which it does not have (one texel is read)");
}

// A primitive's scene mesh by phases: mode, decoding and placement, attributes, triangles,
// tangents.
void Loader::add_primitive(size_t mesh_index, size_t p, const Instance& inst) {
  const tinygltf::Mesh& gm = m_.meshes[mesh_index];
  const tinygltf::Primitive& prim = gm.primitives[p];
  const std::string ml = label("mesh", gm.name, mesh_index);
  const std::string where = ml + " primitive " + std::to_string(p);
  if (!drawn_mode(prim, where)) return;
  if (!prim.attributes.count("POSITION")) fail(where + " has no POSITION attribute");
  const DracoPrimitive* dp = draco(mesh_index, p, where);
  const View pos = *attribute(prim, dp, "POSITION", where);
  if (pos.count > UINT32_MAX) fail(where + " has more than 2^32 vertices");
  // The shape a viewer draws: the base plus the morph targets at the instance's weights, placed
  // by the node or, skinned, by its joints.
  const std::vector<dvec3> moved = morph_offsets(prim, dp, inst, "POSITION", pos.count, where);
  const Placement place = placement(prim, dp, inst, pos.count, where);
  Mesh out;
  out.name = gm.name.empty() ? "mesh " + std::to_string(mesh_index) : gm.name;
  read_positions(out, pos, moved, place, ml);
  read_normals(out, prim, dp, inst, place, pos.count, ml, where);
  read_texcoords(out, prim, dp, pos.count, ml, where);
  read_colors(out, prim, dp, pos.count, ml, where);
  const std::vector<uint32_t> idx = indices(mesh_index, p, dp, pos.count, where);
  out.material = material(prim.material, where);
  add_triangles(out, idx, place.flip);
  if (out.indices.empty()) return;
  warn_missing_texcoords(out, ml);
  add_tangents(out, prim, dp, place, morph_offsets(prim, dp, inst, "TANGENT", pos.count, where),
               where);
  scene_.meshes.push_back(std::move(out));
}

}  // namespace pb::gltf
