// Loads the glTF 2.0 subset photonbound renders (README "Scenes") into plain Scene data.
// The only file that sees tinygltf types is src/gltf_loader.cpp.
#pragma once

#include "photonbound/scene.h"

#include <stdexcept>
#include <string>

namespace pb {

// Bad input in a scene file. what() is one line: "<file>: <what is wrong>".
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads a .gltf (embedded or external buffers) or .glb file. Throws SceneError for anything
// the renderer cannot use: missing or malformed file, out-of-range accessors or indices,
// non-finite or absurd coordinates, unsupported primitive modes or light types, no camera,
// no light with positive power. Degenerate triangles are skipped and counted.
Scene load_gltf(const std::string& path);

}  // namespace pb
