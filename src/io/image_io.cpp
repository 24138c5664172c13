#include "io/image_io.h"
#include "io/image_write.h"

#include <dlfcn.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "io/container_check.h"
#include "io/oiio_codec.h"
#include "util/message_text.h"

// Defined where the module's sources are linked in (the fuzz targets); null otherwise.
extern "C" const pb::OiioCodec* photonbound_oiio_codec() __attribute__((weak));

namespace pb {

namespace {

// The most texels a whole read within `limit` can have: one float channel each.
uint64_t max_texels(const ReadLimit& limit) { return limit.max_bytes / sizeof(float); }

// The OpenImageIO module (oiio_codec.h), loaded on first use: beside the running binary
// (build/photonbound_oiio.so next to build/photonbound), else where this build put it (the
// tests and tools run from other folders of the build).
const OiioCodec& codec() {
  static const OiioCodec* loaded = nullptr;
  static std::string why;
  static std::once_flag once;
  std::call_once(once, [] {
    if (photonbound_oiio_codec) {
      loaded = photonbound_oiio_codec();
      return;
    }
    std::vector<std::string> paths;
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) paths.push_back((self.parent_path() / "photonbound_oiio.so").string());
#ifdef PHOTONBOUND_OIIO_MODULE
    paths.push_back(PHOTONBOUND_OIIO_MODULE);
#endif
    for (const std::string& path : paths) {
      void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        if (why.empty()) why = one_line(dlerror());
        continue;
      }
      using Entry = const OiioCodec* (*)();
      const auto entry = reinterpret_cast<Entry>(dlsym(handle, "photonbound_oiio_codec"));
      const OiioCodec* table = entry ? entry() : nullptr;
      if (table && table->abi == kOiioCodecAbi) {
        loaded = table;
        return;
      }
      why = path + " is from another build of photonbound";
      dlclose(handle);
    }
  });
  if (!loaded)
    throw ImageError(
        "cannot load photonbound's image module photonbound_oiio.so (build it "
        "with the binary): " +
        why);
  return *loaded;
}

// Throws what a call into the module reported.
void rethrow(const CodecFailure& f) {
  switch (f.kind) {
    case CodecFailure::Kind::None:
      return;
    case CodecFailure::Kind::TooLarge:
      throw ImageTooLarge(f.message, f.bytes);
    case CodecFailure::Kind::FormatRefused:
      throw ImageFormatRefused(f.message, f.format);
    case CodecFailure::Kind::Image:
      break;
  }
  throw ImageError(f.message);
}

}  // namespace

void write_png(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb) {
  const OiioCodec& c = codec();
  write_image(path, [&](const std::string& tmp) {
    CodecFailure failure;
    c.write_png(path, tmp, width, height, rgb.data(), failure);
    rethrow(failure);
  });
}

namespace {

// A whole file read by the module's `read` after the container walk of the file.
template <class Out>
Out read_whole(const std::string& path, const ReadLimit& limit,
               void (*OiioCodec::*read)(const std::string&, const ReadLimit&, Out&,
                                        CodecFailure&)) {
  check_container_file(path, max_texels(limit), limit.max_bytes);
  Out out;
  CodecFailure failure;
  (codec().*read)(path, limit, out, failure);
  rethrow(failure);
  return out;
}

}  // namespace

ExrImage read_exr(const std::string& path, const ReadLimit& limit) {
  return read_whole(path, limit, &OiioCodec::read_exr);
}

RgbImage read_rgb_image(const std::string& path, const ReadLimit& limit) {
  return read_whole(path, limit, &OiioCodec::read_rgb_image);
}

namespace {

// glTF's own image formats by their signatures: OpenImageIO's reader name, or "".
std::string gltf_format(const unsigned char* d, size_t n) {
  if (n >= 8 && std::memcmp(d, "\x89PNG\r\n\x1a\n", 8) == 0) return "png";
  if (n >= 3 && d[0] == 0xff && d[1] == 0xd8 && d[2] == 0xff) return "jpeg";
  if (n >= 12 && std::memcmp(d, "RIFF", 4) == 0 && std::memcmp(d + 8, "WEBP", 4) == 0)
    return "webp";
  return "";
}

// A file name whose extension names the format the bytes are in: glTF's formats by their
// signatures, otherwise whatever `name` says.
std::string format_name(const unsigned char* d, size_t n, const std::string& name) {
  const std::string f = gltf_format(d, n);
  return f.empty() ? name : "image." + f;
}

// Another format an image might be in, for the message that refuses it: by its signature, or
// TGA (which has none) by its extension or version 2 footer; "" when nothing is recognised.
std::string other_format(const unsigned char* d, size_t n, const std::string& name) {
  auto starts = [&](const char* magic, size_t len) {
    return n >= len && std::memcmp(d, magic, len) == 0;
  };
  if (starts("II*\0", 4) || starts("MM\0*", 4) || starts("II+\0", 4) || starts("MM\0+", 4))
    return "TIFF";
  if (starts("\x76\x2f\x31\x01", 4)) return "OpenEXR";
  if (starts("#?RADIANCE", 10) || starts("#?RGBE", 6)) return "Radiance HDR";
  if (starts("BM", 2)) return "BMP";
  if (starts("GIF8", 4)) return "GIF";
  if (starts("8BPS", 4)) return "Photoshop";
  if (starts("DDS ", 4)) return "DDS";
  if (starts("\xabKTX 11\xbb", 8)) return "KTX";
  if (starts("\x01\xda", 2)) return "SGI";
  if (starts("\0\0\1\0", 4)) return "ICO";
  if (starts("\0\0\0\x0cjP  ", 8) || starts("\xff\x4f\xff\x51", 4)) return "JPEG 2000";
  if (n >= 12 && std::memcmp(d + 4, "ftyp", 4) == 0) return "HEIF/AVIF";
  if (n >= 2 && d[0] == 'P' && d[1] >= '1' && d[1] <= '7') return "PNM";
  if (n >= 18 && std::memcmp(d + n - 18, "TRUEVISION-XFILE.", 17) == 0) return "TGA";
  std::string ext = std::filesystem::path(name).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".tga" || ext == ".targa") return "TGA";
  return "";
}

}  // namespace

bool is_ktx2(const unsigned char* data, size_t size) {
  return size >= 12 && std::memcmp(data, "\xabKTX 20\xbb\r\n\x1a\n", 12) == 0;
}

Image decode_image(const unsigned char* data, size_t size, const std::string& name,
                   uint64_t max_bytes, ImageFormats formats) {
  const std::string gltf = gltf_format(data, size);
  if (formats == ImageFormats::Gltf && gltf.empty()) {
    const std::string other = is_ktx2(data, size) ? "KTX2" : other_format(data, size, name);
    throw ImageFormatRefused(
        name + (other.empty() ? ": cannot decode the image: it is not a PNG, JPEG or WebP image"
                              : ": the image is " + other +
                                    ", not one of glTF's image formats (PNG, JPEG, WebP)"),
        other);
  }
  // KTX2 (KHR_texture_basisu's container) has no OpenImageIO reader; without this, OpenImageIO
  // falls back to opening `name` as a path relative to the working directory and reports a
  // missing file.
  if (is_ktx2(data, size))
    throw ImageError(name +
                     ": cannot decode the image: it is KTX2 (Basis Universal), which "
                     "photonbound does not read");
  // Before any reader sees the bytes: the module offers them to every format's reader.
  check_container(data, size, name, kMaxTexels, max_bytes);
  Image image;
  CodecFailure failure;
  codec().decode_image(data, size, name, format_name(data, size, name), gltf,
                       formats == ImageFormats::Gltf, max_bytes, image, failure);
  rethrow(failure);
  return image;
}

uint64_t image_bytes(const Image& image) {
  return uint64_t(image.u8.size()) + uint64_t(image.f32.size()) * sizeof(float);
}

}  // namespace pb
