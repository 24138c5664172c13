// A rewrite of the glTF JSON before tinygltf 2.7 parses it, for two things glTF allows and
// that parser refuses (the whole load fails):
//  - EXT_meshopt_compression fallback buffers, which have no uri: in a .gltf tinygltf reports
//    "'uri' is missing" and then fails to open the file "", in a .glb it copies the BIN chunk
//    into every buffer without uri and fails when the declared byteLength is longer. Every such
//    buffer (but the GLB's own BIN buffer, index 0 unless it is marked "fallback": true) becomes
//    a one-byte data URI here; the loader knows it has no data.
//  - a primitive whose indices accessor has no bufferView (every KHR_draco_mesh_compression
//    primitive): tinygltf fails with "accessor[N] invalid bufferView". Its "indices" member is
//    taken out here and handed to the loader beside the model.
//  - KHR_animation_pointer channels, whose target has no "node": tinygltf fails with "'node'
//    property is missing". They are dropped (animations are ignored anyway).
// Only files that name EXT_meshopt_compression, KHR_draco_mesh_compression,
// KHR_animation_pointer or a "sparse" accessor are parsed twice; nlohmann::json (the parser
// tinygltf uses) is seen only here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>

namespace pb::gltf {

struct Prepass {
  std::map<size_t, uint64_t> placeholders;           // buffer index -> declared byteLength
  std::map<std::pair<size_t, size_t>, int> indices;  // (mesh, primitive) -> indices accessor
};

// When anything in `json` (the JSON text, or the GLB's JSON chunk when `glb`) needs changing,
// writes the changed text to `rewritten`, fills `out` and returns true. Text that is not JSON is
// left to tinygltf to report. The loader runs json_problem() first, so no text deeper than
// kMaxJsonNesting reaches the parser here.
bool prepass(std::string_view json, bool glb, Prepass& out, std::string& rewritten);

// Nesting deeper than this is refused before any recursive parser sees the text.
inline constexpr size_t kMaxJsonNesting = 512;
// A longer string is refused before any parser sees the text: nlohmann's parser and tinygltf's
// base64 decoding copy a data: URI about six times over (a 1 GiB URI peaked at 7.5 GB); bytes
// that large belong in a .bin file or a GLB's binary chunk, which are read once.
inline constexpr size_t kMaxJsonString = size_t(256) << 20;

// What is wrong with the JSON text that tinygltf 2.7 would not say, found in one pass over the
// bytes before any parser runs: "JSON nested deeper than 512 levels" (nlohmann's parser and
// dump() recurse once per level: 100,000 nested arrays overflow the stack), a string longer
// than kMaxJsonString (a data: URI), or a string or
// boolean where glTF requires a number or an array of numbers (tinygltf takes the default
// without a word: "intensity": "NaN" is intensity 1), named by its JSON path. Empty when
// nothing is. Members under "extras" are the author's own and are not checked.
std::string json_problem(std::string_view json);

// Who refers to `decoded` (a URI as tinygltf_decoded() gives it), for messages:
// "buffer 0 uri '../x.bin'" or "image 2 uri '%2e%2e/x.png'"; "uri '<decoded>'" when no buffer or
// image of `json` does.
std::string uri_owner(std::string_view json, const std::string& decoded);

}  // namespace pb::gltf
