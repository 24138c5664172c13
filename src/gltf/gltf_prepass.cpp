// The JSON rewrite before tinygltf parses a file; see gltf_prepass.h.
#include "gltf/gltf_prepass.h"

#include "gltf/gltf_files.h"
#include "util/memory.h"
#include "util/message_text.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace pb::gltf {

namespace {

using nlohmann::json;

bool needs_prepass(std::string_view text) {
  for (const char* key : {"EXT_meshopt_compression", "KHR_draco_mesh_compression", "\"sparse\"",
                          "KHR_animation_pointer"})
    if (text.find(key) != std::string_view::npos) return true;
  return false;
}

// A buffer without uri that cannot be the GLB's BIN chunk becomes a one-byte data URI
// (tinygltf 2.7 refuses an empty one).
bool rewrite_buffers(json& doc, bool glb, Prepass& out) {
  const auto buffers = doc.find("buffers");
  if (buffers == doc.end() || !buffers->is_array()) return false;
  bool changed = false;
  for (size_t i = 0; i < buffers->size(); ++i) {
    json& b = (*buffers)[i];
    if (!b.is_object() || b.contains("uri")) continue;
    const auto length = b.find("byteLength");
    if (length == b.end() || !length->is_number_unsigned()) continue;  // tinygltf reports it
    bool fallback = false;
    if (const auto ext = b.find("extensions"); ext != b.end() && ext->is_object())
      if (const auto m = ext->find("EXT_meshopt_compression"); m != ext->end() && m->is_object())
        fallback = m->value("fallback", json(false)) == json(true);
    if (glb && i == 0 && !fallback) continue;  // the BIN chunk
    out.placeholders[i] = length->get<uint64_t>();
    b["byteLength"] = 1;
    b["uri"] = "data:application/octet-stream;base64,AA==";
    changed = true;
  }
  return changed;
}

// Takes "indices" out of every primitive whose indices accessor exists and has no bufferView.
bool detach_indices(json& doc, Prepass& out) {
  const auto meshes = doc.find("meshes"), accessors = doc.find("accessors");
  if (meshes == doc.end() || !meshes->is_array() || accessors == doc.end() ||
      !accessors->is_array())
    return false;
  bool changed = false;
  for (size_t m = 0; m < meshes->size(); ++m) {
    json& mesh = (*meshes)[m];
    if (!mesh.is_object()) continue;
    const auto prims = mesh.find("primitives");
    if (prims == mesh.end() || !prims->is_array()) continue;
    for (size_t p = 0; p < prims->size(); ++p) {
      json& prim = (*prims)[p];
      if (!prim.is_object()) continue;
      const auto idx = prim.find("indices");
      if (idx == prim.end() || !idx->is_number_unsigned()) continue;
      const uint64_t a = idx->get<uint64_t>();
      if (a >= accessors->size()) continue;  // tinygltf reports it
      const json& acc = (*accessors)[size_t(a)];
      if (!acc.is_object() || acc.contains("bufferView")) continue;
      out.indices[{m, p}] = int(a);
      prim.erase("indices");
      changed = true;
    }
  }
  return changed;
}

// Drops every animation channel whose target has no "node": KHR_animation_pointer's channels
// name their target by a JSON pointer instead, and tinygltf 2.7 fails the whole file with
// "'node' property is missing". Animations are ignored anyway (with a warning); a channel
// left without its node would only be ignored too.
bool drop_pointer_channels(json& doc) {
  const auto animations = doc.find("animations");
  if (animations == doc.end() || !animations->is_array()) return false;
  bool changed = false;
  for (json& a : *animations) {
    if (!a.is_object()) continue;
    const auto channels = a.find("channels");
    if (channels == a.end() || !channels->is_array()) continue;
    json kept = json::array();
    for (json& c : *channels) {
      const auto target = c.is_object() ? c.find("target") : c.end();
      const bool nodeless =
          c.is_object() && target != c.end() && target->is_object() && !target->contains("node");
      if (nodeless)
        changed = true;
      else
        kept.push_back(std::move(c));
    }
    *channels = std::move(kept);
  }
  return changed;
}

// Where glTF 2.0 (and KHR_lights_punctual) requires a number: '#' is any array element, '*'
// any member name. The members an extension object holds are read through the loader's
// ext_number, which refuses a string itself.
constexpr std::array kNumberPaths = {
    "scene",
    "scenes.#.nodes.#",
    "nodes.#.camera",
    "nodes.#.mesh",
    "nodes.#.skin",
    "nodes.#.children.#",
    "nodes.#.extensions.KHR_lights_punctual.light",
    "meshes.#.primitives.#.indices",
    "meshes.#.primitives.#.material",
    "meshes.#.primitives.#.mode",
    "meshes.#.primitives.#.attributes.*",
    "meshes.#.primitives.#.targets.#.*",
    "accessors.#.bufferView",
    "accessors.#.byteOffset",
    "accessors.#.componentType",
    "accessors.#.count",
    "accessors.#.sparse.count",
    "accessors.#.sparse.indices.bufferView",
    "accessors.#.sparse.indices.byteOffset",
    "accessors.#.sparse.indices.componentType",
    "accessors.#.sparse.values.bufferView",
    "accessors.#.sparse.values.byteOffset",
    "bufferViews.#.buffer",
    "bufferViews.#.byteOffset",
    "bufferViews.#.byteLength",
    "bufferViews.#.byteStride",
    "bufferViews.#.target",
    "buffers.#.byteLength",
    "images.#.bufferView",
    "textures.#.sampler",
    "textures.#.source",
    "samplers.#.magFilter",
    "samplers.#.minFilter",
    "samplers.#.wrapS",
    "samplers.#.wrapT",
    "skins.#.inverseBindMatrices",
    "skins.#.skeleton",
    "skins.#.joints.#",
    "materials.#.alphaCutoff",
    "materials.#.pbrMetallicRoughness.metallicFactor",
    "materials.#.pbrMetallicRoughness.roughnessFactor",
    "materials.#.pbrMetallicRoughness.baseColorTexture.index",
    "materials.#.pbrMetallicRoughness.baseColorTexture.texCoord",
    "materials.#.pbrMetallicRoughness.metallicRoughnessTexture.index",
    "materials.#.pbrMetallicRoughness.metallicRoughnessTexture.texCoord",
    "materials.#.normalTexture.index",
    "materials.#.normalTexture.texCoord",
    "materials.#.normalTexture.scale",
    "materials.#.occlusionTexture.index",
    "materials.#.occlusionTexture.texCoord",
    "materials.#.occlusionTexture.strength",
    "materials.#.emissiveTexture.index",
    "materials.#.emissiveTexture.texCoord",
    "cameras.#.perspective.yfov",
    "cameras.#.perspective.znear",
    "cameras.#.perspective.zfar",
    "cameras.#.perspective.aspectRatio",
    "cameras.#.orthographic.xmag",
    "cameras.#.orthographic.ymag",
    "cameras.#.orthographic.znear",
    "cameras.#.orthographic.zfar",
    "extensions.KHR_lights_punctual.lights.#.intensity",
    "extensions.KHR_lights_punctual.lights.#.range",
    "extensions.KHR_lights_punctual.lights.#.spot.innerConeAngle",
    "extensions.KHR_lights_punctual.lights.#.spot.outerConeAngle",
};
// Where glTF requires an array of numbers: the member and each element.
constexpr std::array kNumberArrayPaths = {
    "nodes.#.matrix",
    "nodes.#.translation",
    "nodes.#.rotation",
    "nodes.#.scale",
    "nodes.#.weights",
    "meshes.#.weights",
    "accessors.#.min",
    "accessors.#.max",
    "materials.#.emissiveFactor",
    "materials.#.pbrMetallicRoughness.baseColorFactor",
    "extensions.KHR_lights_punctual.lights.#.color",
};

using Pattern = std::vector<std::string_view>;

std::vector<Pattern> number_patterns() {
  auto split = [](std::string_view p) {
    Pattern out;
    for (size_t at = 0;;) {
      const size_t dot = p.find('.', at);
      out.push_back(p.substr(at, dot - at));
      if (dot == std::string_view::npos) return out;
      at = dot + 1;
    }
  };
  std::vector<Pattern> all;
  for (const char* p : kNumberPaths) all.push_back(split(p));
  for (const char* p : kNumberArrayPaths) {
    all.push_back(split(p));
    all.push_back(split(p));
    all.back().push_back("#");
  }
  return all;
}

// A container being scanned: an array and its element index, or an object and the member name
// last read (`expect_key` until its ':' is passed).
struct Frame {
  bool array = false;
  bool expect_key = true;
  size_t index = 0;
  std::string_view key;
};

// The members and elements to the value at the top of `stack`, or nullopt under "extras".
bool number_required(const std::vector<Frame>& stack, const std::vector<Pattern>& patterns) {
  for (const Frame& f : stack)
    if (!f.array && f.key == "extras") return false;
  for (const Pattern& p : patterns) {
    if (p.size() != stack.size()) continue;
    bool match = true;
    for (size_t k = 0; k < p.size() && match; ++k) {
      const Frame& f = stack[k];
      match = f.array ? p[k] == "#" : (p[k] == "*" || p[k] == f.key);
    }
    if (match) return true;
  }
  return false;
}

std::string path_text(const std::vector<Frame>& stack) {
  std::string out;
  for (const Frame& f : stack)
    out += f.array ? "[" + std::to_string(f.index) + "]"
                   : (out.empty() ? "" : ".") + std::string(f.key);
  return out;
}

}  // namespace

std::string json_problem(std::string_view text) {
  static const std::vector<Pattern> patterns = number_patterns();
  std::vector<Frame> stack;
  const size_t n = text.size();
  auto wrong = [&](const std::string& what, std::string_view value) {
    std::string v(value.substr(0, 40));
    if (value.size() > 40) v += "...";
    return path_text(stack) + " is " + what + " (" + one_line(v) + ") where glTF requires a number";
  };
  for (size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (c == '"') {
      const size_t start = ++i;
      while (i < n && text[i] != '"') i += text[i] == '\\' ? 2 : 1;
      const std::string_view s = text.substr(start, std::min(i, n) - start);
      if (s.size() > kMaxJsonString)
        return path_text(stack) + " is " +
               (s.rfind("data:", 0) == 0 ? "a data: URI" : std::string("a string")) + " of " +
               bytes_text(s.size()) + ", over the " + bytes_text(kMaxJsonString) +
               " photonbound reads (put its bytes in a .bin file beside the scene, or in a .glb)";
      if (!stack.empty() && !stack.back().array && stack.back().expect_key) {
        stack.back().key = s;
        stack.back().expect_key = false;
      } else if (!stack.empty() && number_required(stack, patterns)) {
        return wrong("a string", "\"" + std::string(s.substr(0, 40)) + "\"");
      }
    } else if (c == '{' || c == '[') {
      if (stack.size() >= kMaxJsonNesting)
        return "JSON nested deeper than " + std::to_string(kMaxJsonNesting) + " levels";
      stack.push_back(Frame{c == '[', c == '{', 0, {}});
    } else if (c == '}' || c == ']') {
      if (!stack.empty()) stack.pop_back();
    } else if (c == ',') {
      if (!stack.empty()) {
        if (stack.back().array)
          ++stack.back().index;
        else
          stack.back().expect_key = true;
      }
    } else if (c == 't' || c == 'f') {
      const std::string_view word = text.substr(i, c == 't' ? 4 : 5);
      if (!stack.empty() && (word == "true" || word == "false") && number_required(stack, patterns))
        return wrong("a boolean", word);
      i += word.size() - 1;
    }
  }
  return {};
}

std::string uri_owner(std::string_view text, const std::string& decoded) {
  const json doc = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_object())
    for (const char* kind : {"buffers", "images"}) {
      const auto list = doc.find(kind);
      if (list == doc.end() || !list->is_array()) continue;
      for (size_t i = 0; i < list->size(); ++i) {
        const json& item = (*list)[i];
        if (!item.is_object()) continue;
        const auto uri = item.find("uri");
        if (uri == item.end() || !uri->is_string()) continue;
        const std::string raw = uri->get<std::string>();
        if (tinygltf_decoded(raw) == decoded)
          return std::string(kind == std::string("buffers") ? "buffer " : "image ") +
                 std::to_string(i) + " uri '" + one_line(raw) + "'";
      }
    }
  return "uri '" + one_line(decoded) + "'";
}

bool prepass(std::string_view text, bool glb, Prepass& out, std::string& rewritten) {
  if (!needs_prepass(text)) return false;
  json doc = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return false;
  const bool buffers = rewrite_buffers(doc, glb, out);
  const bool indices = detach_indices(doc, out);
  const bool channels = drop_pointer_channels(doc);
  if (!buffers && !indices && !channels) return false;
  rewritten = doc.dump();
  return true;
}

}  // namespace pb::gltf
