// tinygltf compiled into the fuzz target from Debian's header, so that the sanitizers and the
// fuzzer's coverage see inside the parser too (the renderer links Debian's shared library).
// Images are never decoded by photonbound (src/gltf/gltf_loader.cpp installs a loader that skips
// them), so stb_image is left out (CMakeLists.txt defines TINYGLTF_NO_STB_IMAGE*).
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
