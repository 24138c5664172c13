// The JSON rewrite before tinygltf parses a file; see gltf_prepass.h.
#include "gltf/gltf_prepass.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>

namespace pb::gltf {

namespace {

using nlohmann::json;

constexpr size_t kMaxNesting = 512;  // nlohmann's dump() recurses once per level

bool needs_prepass(std::string_view text) {
  for (const char* key : {"EXT_meshopt_compression", "KHR_draco_mesh_compression", "\"sparse\"",
                          "KHR_animation_pointer"})
    if (text.find(key) != std::string_view::npos) return true;
  return false;
}

// Deepest [ ] / { } nesting outside strings.
size_t nesting(std::string_view text) {
  size_t depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
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

}  // namespace

bool prepass(std::string_view text, bool glb, Prepass& out, std::string& rewritten) {
  if (!needs_prepass(text) || nesting(text) > kMaxNesting) return false;
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
