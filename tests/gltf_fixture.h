// Small glTF files for the decode and loader tests (test_gltf_*.cpp) and the corpus generator
// (make_gltf_corpus.cpp): a wavy grid with normals and two texture coordinate
// sets, its Draco and meshoptimizer encodings, and a document writer (.gltf with an embedded
// buffer, or .glb). Documents are built with nlohmann::json.
#pragma once

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb::test {

using json = nlohmann::json;

// An n x n vertex height field z = 0.2 sin(3x) cos(2y) over [-1, 1]^2 with analytic unit
// normals, uv0 = ((x + 1) / 2, (y + 1) / 2) and uv1 = (2 - x, 3y): no degenerate triangles.
struct Grid {
  std::vector<float> positions, normals, uv0, uv1;  // packed xyz / uv
  std::vector<uint32_t> indices;
  size_t vertices() const { return positions.size() / 3; }
};

inline Grid make_grid(int n) {
  Grid g;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const double x = -1.0 + 2.0 * c / (n - 1), y = -1.0 + 2.0 * r / (n - 1);
      const double z = 0.2 * std::sin(3 * x) * std::cos(2 * y);
      const double dx = 0.6 * std::cos(3 * x) * std::cos(2 * y);
      const double dy = -0.4 * std::sin(3 * x) * std::sin(2 * y);
      const double len = std::sqrt(dx * dx + dy * dy + 1);
      g.positions.insert(g.positions.end(), {float(x), float(y), float(z)});
      g.normals.insert(g.normals.end(), {float(-dx / len), float(-dy / len), float(1 / len)});
      g.uv0.insert(g.uv0.end(), {float((x + 1) / 2), float((y + 1) / 2)});
      g.uv1.insert(g.uv1.end(), {float(2 - x), float(3 * y)});
    }
  for (int r = 0; r + 1 < n; ++r)
    for (int c = 0; c + 1 < n; ++c) {
      const uint32_t a = uint32_t(r * n + c), b = a + 1, d = a + uint32_t(n), e = d + 1;
      g.indices.insert(g.indices.end(), {a, b, e, a, e, d});  // counter-clockwise seen from +z
    }
  return g;
}

// Draco attribute unique ids the tests map in the extension: deliberately not 0, 1, 2, 3, and
// the two TEX_COORD attributes told apart only by their ids.
struct DracoIds {
  int position = 5, normal = 2, uv0 = 9, uv1 = 4;
};

// Bits of quantisation: positions, normals (octahedral), texture coordinates.
struct DracoBits {
  int position = 14, normal = 10, texcoord = 12;
};

inline std::vector<unsigned char> draco_encode(const Grid& g, const DracoIds& ids,
                                               const DracoBits& bits) {
  draco::Mesh m;
  const uint32_t n = uint32_t(g.vertices());
  m.set_num_points(n);
  auto add = [&](draco::GeometryAttribute::Type type, const std::vector<float>& v, int comps,
                 int id) {
    draco::GeometryAttribute ga;
    ga.Init(type, nullptr, uint8_t(comps), draco::DT_FLOAT32, false, sizeof(float) * comps, 0);
    const int att = m.AddAttribute(ga, true, n);
    for (uint32_t i = 0; i < n; ++i)
      m.attribute(att)->SetAttributeValue(draco::AttributeValueIndex(i), &v[size_t(i) * comps]);
    m.attribute(att)->set_unique_id(uint32_t(id));
  };
  add(draco::GeometryAttribute::POSITION, g.positions, 3, ids.position);
  add(draco::GeometryAttribute::NORMAL, g.normals, 3, ids.normal);
  add(draco::GeometryAttribute::TEX_COORD, g.uv0, 2, ids.uv0);
  add(draco::GeometryAttribute::TEX_COORD, g.uv1, 2, ids.uv1);
  for (size_t t = 0; t < g.indices.size(); t += 3)
    m.AddFace({draco::PointIndex(g.indices[t]), draco::PointIndex(g.indices[t + 1]),
               draco::PointIndex(g.indices[t + 2])});
  draco::Encoder enc;
  enc.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits.position);
  enc.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, bits.normal);
  enc.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, bits.texcoord);
  draco::EncoderBuffer out;
  const draco::Status s = enc.EncodeMeshToBuffer(m, &out);
  if (!s.ok()) throw std::runtime_error("draco: " + s.error_msg_string());
  return std::vector<unsigned char>(out.data(), out.data() + out.size());
}

inline std::vector<unsigned char> meshopt_vertices(const void* data, size_t count, size_t stride) {
  std::vector<unsigned char> out(meshopt_encodeVertexBufferBound(count, stride));
  out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), data, count, stride));
  return out;
}

inline std::vector<unsigned char> meshopt_triangles(const std::vector<uint32_t>& idx,
                                                    size_t vertices) {
  std::vector<unsigned char> out(meshopt_encodeIndexBufferBound(idx.size(), vertices));
  out.resize(meshopt_encodeIndexBuffer(out.data(), out.size(), idx.data(), idx.size()));
  return out;
}

inline std::vector<unsigned char> meshopt_sequence(const std::vector<uint32_t>& idx,
                                                   size_t vertices) {
  std::vector<unsigned char> out(meshopt_encodeIndexSequenceBound(idx.size(), vertices));
  out.resize(meshopt_encodeIndexSequence(out.data(), out.size(), idx.data(), idx.size()));
  return out;
}

inline std::string base64(const std::vector<unsigned char>& d) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < d.size(); i += 3) {
    const uint32_t v = uint32_t(d[i]) << 16 | (i + 1 < d.size() ? uint32_t(d[i + 1]) << 8 : 0u) |
                       (i + 2 < d.size() ? uint32_t(d[i + 2]) : 0u);
    out += t[v >> 18 & 63];
    out += t[v >> 12 & 63];
    out += i + 1 < d.size() ? t[v >> 6 & 63] : '=';
    out += i + 2 < d.size() ? t[v & 63] : '=';
  }
  return out;
}

// The node transform every test mesh gets: translation, rotation about (1, 2, 2) / 3 by 0.5 rad
// and a non-uniform scale.
inline json mesh_trs() {
  const double h = 0.25, s = std::sin(h) / 3.0;
  return json{{"translation", {1.0, -2.0, 0.5}},
              {"rotation", {s, 2 * s, 2 * s, std::cos(h)}},
              {"scale", {2.0, 0.5, 1.5}}};
}

// A glTF document whose buffer 0 holds `bin`, with a camera, a point light and one material.
struct Doc {
  json j;
  std::vector<unsigned char> bin;
  json more_buffers = json::array();  // buffers 1, 2, ...
  std::string buffer_uri;             // buffer 0's uri in a .gltf (default: a data URI)

  Doc() {
    j["asset"] = json{{"version", "2.0"}};
    j["scene"] = 0;
    j["scenes"] = json::array({json{{"nodes", json::array({0, 1})}}});
    const json light = json{{"KHR_lights_punctual", json{{"light", 0}}}};
    j["nodes"] = json::array({json{{"camera", 0}, {"translation", {0, 0, 8}}},
                              json{{"translation", {0, 3, 3}}, {"extensions", light}}});
    j["cameras"] = json::array(
        {json{{"type", "perspective"}, {"perspective", json{{"yfov", 0.8}, {"znear", 0.01}}}}});
    j["materials"] = json::array(
        {json{{"name", "grey"}, {"pbrMetallicRoughness", json{{"metallicFactor", 0}}}}});
    const json point = json{{"type", "point"}, {"intensity", 10}, {"color", {1, 1, 1}}};
    j["extensions"] = json{{"KHR_lights_punctual", json{{"lights", json::array({point})}}}};
    j["extensionsUsed"] = json::array({"KHR_lights_punctual"});
    for (const char* s : {"accessors", "bufferViews", "meshes"}) j[s] = json::array();
  }
  // Appends bytes to buffer 0 (4-byte aligned); returns their offset.
  size_t append(const void* data, size_t size) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t off = bin.size();
    bin.resize(off + size);
    if (size) std::memcpy(bin.data() + off, data, size);
    return off;
  }
  int add(const char* section, json item) {
    j[section].push_back(std::move(item));
    return int(j[section].size()) - 1;
  }
  // A bufferView over new bytes in buffer 0; `extra` members are merged in.
  int view(const void* data, size_t size, const json& extra = json::object()) {
    json v = json{{"buffer", 0}, {"byteOffset", append(data, size)}, {"byteLength", size}};
    v.update(extra);
    return add("bufferViews", v);
  }
  template <class T>
  int view(const std::vector<T>& v, const json& extra = json::object()) {
    return view(v.data(), v.size() * sizeof(T), extra);
  }
  int accessor(int view, int component, size_t count, const char* type,
               const json& extra = json::object()) {
    json a = json{{"componentType", component}, {"count", count}, {"type", type}};
    if (view >= 0) a["bufferView"] = view;
    a.update(extra);
    return add("accessors", a);
  }
  // A mesh with one primitive (material 0 unless it names one) under a new root node.
  int mesh_node(json primitive, const json& node = mesh_trs()) {
    if (!primitive.contains("material")) primitive["material"] = 0;
    const int m = add("meshes", json{{"name", "grid"}, {"primitives", json::array({primitive})}});
    json n = node;
    n["mesh"] = m;
    n["name"] = "grid node";
    j["scenes"][0]["nodes"].push_back(add("nodes", n));
    return m;
  }
  // EXT_meshopt_compression: `compressed` goes to buffer 0, the parent bufferView lies in the
  // fallback buffer 1 (created without uri on first use, marked "fallback" when `tagged`).
  int meshopt_view(const std::vector<unsigned char>& compressed, size_t count, size_t stride,
                   const char* mode, const char* filter = "NONE", bool attributes = true,
                   bool tagged = true) {
    if (more_buffers.empty()) {
      more_buffers.push_back(json{{"byteLength", 0}});
      if (tagged)
        more_buffers[0]["extensions"] = json{{"EXT_meshopt_compression", json{{"fallback", true}}}};
    }
    json& fallback = more_buffers[0];
    const size_t at = (fallback["byteLength"].get<size_t>() + 3) / 4 * 4;
    fallback["byteLength"] = at + count * stride;
    json ext = json{{"buffer", 0},
                    {"byteOffset", append(compressed.data(), compressed.size())},
                    {"byteLength", compressed.size()},
                    {"byteStride", stride},
                    {"count", count},
                    {"mode", mode},
                    {"filter", filter}};
    json v = json{{"buffer", 1}, {"byteOffset", at}, {"byteLength", count * stride}};
    if (attributes) v["byteStride"] = stride;
    v["extensions"] = json{{"EXT_meshopt_compression", ext}};
    return add("bufferViews", v);
  }
  // A float VEC3 accessor and an UNSIGNED_SHORT index accessor over new bufferViews.
  int vec3s(const std::vector<float>& xyz) {
    return accessor(view(xyz), 5126, xyz.size() / 3, "VEC3");
  }
  int indices(const std::vector<uint16_t>& i) {
    return accessor(view(i), 5123, i.size(), "SCALAR");
  }
  void require(const std::vector<std::string>& extensions) {
    for (const std::string& e : extensions) {
      j["extensionsUsed"].push_back(e);
      j["extensionsRequired"].push_back(e);
    }
  }
  json buffers(bool glb) const {
    json b0 = json{{"byteLength", bin.size()}};
    if (!glb)
      b0["uri"] =
          buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(bin) : buffer_uri;
    json all = json::array({b0});
    for (const json& b : more_buffers) all.push_back(b);
    return all;
  }
  std::string gltf() const {
    json d = j;
    d["buffers"] = buffers(false);
    return d.dump();
  }
  std::vector<unsigned char> glb() const {
    json d = j;
    d["buffers"] = buffers(true);
    std::string text = d.dump();
    while (text.size() % 4) text += ' ';
    std::vector<unsigned char> b = bin;
    while (b.size() % 4) b.push_back(0);
    std::vector<unsigned char> out = {'g', 'l', 'T', 'F'};
    auto u32 = [&](size_t v) {
      for (int k = 0; k < 4; ++k) out.push_back(uint8_t(v >> (8 * k)));
    };
    u32(2);
    u32(12 + 8 + text.size() + 8 + b.size());
    u32(text.size());
    u32(0x4E4F534Au);  // JSON
    out.insert(out.end(), text.begin(), text.end());
    u32(b.size());
    u32(0x004E4942u);  // BIN
    out.insert(out.end(), b.begin(), b.end());
    return out;
  }
  // Writes .glb or .gltf by the path's extension; returns the path.
  std::string write(const std::string& path) const {
    std::ofstream f(path, std::ios::binary);
    if (path.size() > 4 && path.compare(path.size() - 4, 4, ".glb") == 0) {
      const std::vector<unsigned char> b = glb();
      f.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
    } else {
      f << gltf();
    }
    return path;
  }
};

constexpr int kFloat = 5126, kShort = 5122, kUShort = 5123, kUInt = 5125;

// A Draco primitive over bufferView `bv`, its accessors without bufferView.
inline json draco_primitive(Doc& d, const Grid& g, int bv, const DracoIds& ids, size_t points) {
  const json ext = json{{"bufferView", bv},
                        {"attributes", json{{"POSITION", ids.position},
                                            {"NORMAL", ids.normal},
                                            {"TEXCOORD_0", ids.uv0},
                                            {"TEXCOORD_1", ids.uv1}}}};
  const json minmax = json{{"min", {-1, -1, -0.2}}, {"max", {1, 1, 0.2}}};
  return json{{"attributes", json{{"POSITION", d.accessor(-1, kFloat, points, "VEC3", minmax)},
                                  {"NORMAL", d.accessor(-1, kFloat, points, "VEC3")},
                                  {"TEXCOORD_0", d.accessor(-1, kFloat, points, "VEC2")},
                                  {"TEXCOORD_1", d.accessor(-1, kFloat, points, "VEC2")}}},
              {"indices", d.accessor(-1, kUInt, g.indices.size(), "SCALAR")},
              {"extensions", json{{"KHR_draco_mesh_compression", ext}}}};
}

// The grid with every attribute and the indices in EXT_meshopt_compression bufferViews: POSITION
// FLOAT (no filter), NORMAL SHORT normalised with the OCTAHEDRAL filter (12 bits), TEXCOORD_0
// FLOAT with the EXPONENTIAL filter (15-bit mantissa), TEXCOORD_1 FLOAT, indices TRIANGLES.
struct MeshoptGrid {
  static constexpr int kOctBits = 12, kExpBits = 15;
  Doc d;
  json prim;
  MeshoptGrid(const Grid& g, bool tagged) {
    const size_t n = g.vertices();
    std::vector<float> n4;
    for (size_t k = 0; k < n; ++k)
      n4.insert(n4.end(), {g.normals[3 * k], g.normals[3 * k + 1], g.normals[3 * k + 2], 0.0f});
    std::vector<int16_t> oct(4 * n);
    meshopt_encodeFilterOct(oct.data(), n, 8, kOctBits, n4.data());
    std::vector<float> exp(2 * n);
    meshopt_encodeFilterExp(exp.data(), n, 8, kExpBits, g.uv0.data());
    d.require({"EXT_meshopt_compression", "KHR_mesh_quantization"});
    const auto attr = [&](const void* data, size_t stride, const char* filter) {
      return d.meshopt_view(meshopt_vertices(data, n, stride), n, stride, "ATTRIBUTES", filter,
                            true, tagged);
    };
    const int pos = attr(g.positions.data(), 12, "NONE"), nor = attr(oct.data(), 8, "OCTAHEDRAL"),
              uv0 = attr(exp.data(), 8, "EXPONENTIAL"), uv1 = attr(g.uv1.data(), 8, "NONE");
    const int idx = d.meshopt_view(meshopt_triangles(g.indices, n), g.indices.size(), 4,
                                   "TRIANGLES", "NONE", false, tagged);
    prim = json{{"attributes",
                 json{{"POSITION", d.accessor(pos, kFloat, n, "VEC3")},
                      {"NORMAL", d.accessor(nor, kShort, n, "VEC3", json{{"normalized", true}})},
                      {"TEXCOORD_0", d.accessor(uv0, kFloat, n, "VEC2")},
                      {"TEXCOORD_1", d.accessor(uv1, kFloat, n, "VEC2")}}},
                {"indices", d.accessor(idx, kUInt, g.indices.size(), "SCALAR")}};
  }
  json& ext(int view) {
    return d.j["bufferViews"][size_t(view)]["extensions"]["EXT_meshopt_compression"];
  }
};

}  // namespace pb::test
