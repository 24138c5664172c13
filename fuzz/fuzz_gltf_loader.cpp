// libFuzzer target for the glTF loader: any byte string, read as glTF JSON or (when it starts
// with the GLB magic) as a binary .glb, must either load into a Scene that the renderer can
// prepare or be refused with a SceneError. Anything else (a crash, a sanitizer report, another
// exception type, a hang) is a finding. tools/fuzz.sh builds and runs it.
#include "gltf/gltf_loader.h"
#include "render/camera_choice.h"
#include "render/scene_defaults.h"
#include "world/world.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  // External buffers resolve next to this made-up name; fuzz/corpus/ holds none on purpose so
  // that the fuzzer does not spend its time on file-system errors.
  const char* name = glb ? "fuzz-input/input.glb" : "fuzz-input/input.gltf";
  const std::vector<unsigned char> bytes(data, data + size);
  try {
    pb::Scene scene = pb::load_gltf_bytes(name, bytes);
    // A scene the loader accepts must also be one the renderer can prepare: add the default sky
    // and view where it has none, build the acceleration structure and the light distributions.
    const pb::RenderOptions options;
    pb::complete_scene(scene, options);
    const pb::World world(std::move(scene));
    (void)pb::choose_camera(world.scene(), options);
  } catch (const pb::SceneError&) {
    // Refused with a message: the expected outcome for almost every mutated input.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: unexpected exception type: %s\n", e.what());
    std::abort();
  }
  return 0;
}
