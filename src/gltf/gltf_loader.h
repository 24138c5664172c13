// Loads the glTF 2.0 subset photonbound renders (docs/gltf.md) into plain Scene data.
// Only the loader's own files (src/gltf_*.cpp) see tinygltf types.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb {

// Which files outside the scene file a load may read (docs/gltf.md "Which files a scene may
// read"): a buffer or image URI must resolve, after percent-decoding and following symlinks,
// to a regular file inside the scene file's own folder or inside one of `asset_dirs` (--asset-dir).
// Anything else is refused before it is opened, with a message that says nothing about it.
// What a load may hold (docs/usage.md "Memory"): the scene file, the files it names and the
// decoded texels of all its images together, each file checked from its size before it is read
// and each image from its header before it is decoded (the same bytes are decoded once).
struct LoadPolicy {
  std::vector<std::string> asset_dirs;  // further folders files may be read from
  uint64_t max_memory = UINT64_MAX;     // --max-memory
  // --texture-formats any: images in any format OpenImageIO reads, not only glTF's PNG, JPEG
  // and WebP (image_io.h ImageFormats; an image in another format gives a warning and the
  // textures using it their factors).
  bool any_texture_format = false;
};

// Reads a .gltf (embedded or external buffers) or .glb file. Throws SceneError for anything
// the renderer cannot use: missing or malformed file, out-of-range accessors or indices,
// non-finite or absurd coordinates, unsupported primitive modes or light types, lights whose
// power overflows float. No camera and no light are allowed (scene_defaults.h and camera_choice.h
// add the default view and sky); what is ignored (skins, morph targets, animations, unknown
// extensions) is in Scene::warnings. Degenerate triangles are skipped and counted.
Scene load_gltf(const std::string& path, const LoadPolicy& policy = {});

// The same for a file already in memory (the fuzz target's entry point). `path` names the input
// in messages, its extension picks .glb or JSON, and its folder is where external buffers are
// looked up (under `policy`).
Scene load_gltf_bytes(const std::string& path, const std::vector<unsigned char>& bytes,
                      const LoadPolicy& policy = {});

}  // namespace pb
