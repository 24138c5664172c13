// libFuzzer target for the image decoders a scene's textures go through (issue 36): any byte
// string handed to decode_image as glTF's images are by default (ImageFormats::Gltf: PNG, JPEG
// and WebP, each by its own reader) must decode into texels of the size its header states or
// be refused with an ImageError (ImageTooLarge and ImageFormatRefused included), within a
// budget of 256 MiB of texels. Anything else (a crash, a sanitizer report, another exception, a
// hang, an allocation beyond the budget) is a finding. tools/fuzz.sh image builds and runs it.
#include "io/image_io.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The name only names a format in the refusal's message (TGA, which has no signature).
  const std::string name = size && data[0] % 2 ? "t.tga" : "t.png";
  constexpr uint64_t kBudget = uint64_t(256) << 20;
  try {
    const pb::Image image = pb::decode_image(data, size, name, kBudget, pb::ImageFormats::Gltf);
    const size_t values = size_t(image.width) * size_t(image.height) * size_t(image.channels);
    if (image.u8.size() + image.f32.size() != values || image.channels < 1 || image.channels > 4) {
      std::fprintf(stderr, "fuzz: %dx%dx%d image holds %zu values\n", image.width, image.height,
                   image.channels, image.u8.size() + image.f32.size());
      std::abort();
    }
    if (pb::image_bytes(image) > kBudget) {
      std::fprintf(stderr, "fuzz: %llu bytes of texels passed the %llu-byte budget\n",
                   (unsigned long long)pb::image_bytes(image), (unsigned long long)kBudget);
      std::abort();
    }
  } catch (const pb::ImageError&) {
    // Refused with a message naming the image: the expected outcome for most inputs.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: unexpected exception type: %s\n", e.what());
    std::abort();
  }
  return 0;
}
