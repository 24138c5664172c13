// The OpenImageIO module (src/io/oiio_codec.h): image_io's reads, texture decoding and PNG
// writing through OpenImageIO, built as build/photonbound_oiio.so and loaded on first use.
// Every entry catches what its body throws and reports it as a CodecFailure: exceptions do not
// cross the module's edge.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <new>

#include "io/oiio/image_limits.h"
#include "io/oiio_codec.h"
#include "util/memory.h"
#include "util/message_text.h"

namespace pb {

namespace {

// OpenImageIO 2.4's IOMemReader reads wherever it is told: an EXR whose chunk offset table holds
// a negative offset made OpenEXR read before the buffer (ASan: heap-buffer-overflow in
// IOMemReader::pread, found by tools/fuzz.sh image). This one reads only inside it.
class BoundedMemReader final : public OIIO::Filesystem::IOMemReader {
 public:
  using IOMemReader::IOMemReader;
  bool seek(int64_t offset) override {
    if (offset < 0) return false;
    m_pos = offset;
    return true;
  }
  size_t read(void* buf, size_t size) override {
    const size_t n = pread(buf, size, m_pos);
    m_pos += int64_t(n);
    return n;
  }
  size_t pread(void* buf, size_t size, int64_t offset) override {
    if (offset < 0 || offset >= int64_t(m_buf.size())) return 0;
    const size_t n = std::min(size, size_t(int64_t(m_buf.size()) - offset));
    std::memcpy(buf, m_buf.data() + offset, n);
    return n;
  }
};

// A reader that takes its bytes from an IOProxy; "null" makes images up from the name alone.
bool from_memory(const OIIO::ImageInput& reader) {
  return reader.supports("ioproxy") && std::string(reader.format_name()) != "null";
}

// libpng's default error and warning handlers, which OpenImageIO's PNG reader keeps, write to
// stderr themselves ("libpng error: IDAT: Read error", "libpng warning: iCCP: known incorrect
// sRGB profile"): a line that names no file ahead of the one-line error that does, or noise on
// a good texture. OpenImageIO passes the same text to geterror(), which the error below
// carries, so stderr is pointed at /dev/null while a texture decodes (the loader decodes on
// one thread, before any progress output).
class QuietStderr {
 public:
  QuietStderr() {
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, 2);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, 2);
    ::close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_ = -1;
};

// read_image returned `ok`; a reader may also have recorded an error and returned true.
void check_read(const std::string& path, OIIO::ImageInput& in, bool ok) {
  if (!ok || in.has_error())
    throw ImageError(path + ": cannot read pixels: " +
                     (in.has_error() ? one_line(in.geterror()) : "the reader failed"));
}

ExrImage exr_pixels(const std::string& path, const ReadLimit& limit) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw ImageError(path + ": cannot read image: " + one_line(OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  check_whole_read(path, *in, limit);
  check_read_chunk(path, spec, OIIO::TypeDesc::FLOAT, limit.max_bytes);
  ExrImage image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.channelnames;
  image.pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  check_read(path, *in,
             in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()));
  for (const OIIO::ParamValue& p : spec.extra_attribs) {
    const std::string name = p.name().string();
    if (name.rfind("photonbound:", 0) == 0)
      image.metadata.emplace_back(name.substr(12), spec.get_string_attribute(name));
  }
  in->close();
  return image;
}

RgbImage rgb_pixels(const std::string& path, const ReadLimit& limit) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw ImageError(path + ": cannot read image: " + one_line(OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  check_whole_read(path, *in, limit);
  check_read_chunk(path, spec, OIIO::TypeDesc::FLOAT, limit.max_bytes);
  const size_t pixels = size_t(spec.width) * size_t(spec.height);
  if (pixels * size_t(spec.nchannels) > (size_t(1) << 29))
    throw ImageError(path + ": " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                     " pixels of " + std::to_string(spec.nchannels) +
                     " channels is not an environment map (at most 2^29 values)");
  // R, G and B by name when the file has them (an EXR's channels need not come in that order),
  // else the first three channels, or the one channel as grey.
  int source[3] = {spec.channelindex("R"), spec.channelindex("G"), spec.channelindex("B")};
  if (source[0] < 0 || source[1] < 0 || source[2] < 0)
    for (int c = 0; c < 3; ++c) source[c] = std::min(c, spec.nchannels - 1);
  const int channels = spec.nchannels;
  std::vector<float> data(pixels * size_t(channels));
  check_read(path, *in, in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data()));
  in->close();
  RgbImage out;
  out.width = spec.width;
  out.height = spec.height;
  out.rgb.resize(3 * pixels);
  for (size_t p = 0; p < pixels; ++p)
    for (size_t c = 0; c < 3; ++c)
      out.rgb[3 * p + c] = data[p * size_t(channels) + size_t(source[c])];
  return out;
}

Image decoded(const unsigned char* data, size_t size, const std::string& name,
              const std::string& file, const std::string& gltf, bool gltf_only,
              uint64_t max_bytes) {
  const QuietStderr quiet;
  BoundedMemReader memory(data, size);
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // keep colour as stored, not premultiplied
  // With a configuration the readers take the proxy from it (ioproxy_retrieve_from_config).
  OIIO::Filesystem::IOProxy* proxy = &memory;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  // Only readers that take the bytes from the proxy: ImageInput::open would, for a format whose
  // reader cannot (SGI, ICO, ...), or when the extension's reader fails and it tries the others,
  // open `name` as a file relative to the working directory instead.
  std::unique_ptr<OIIO::ImageInput> in;
  std::string first_error;
  auto attempt = [&](const std::string& format) {
    auto reader = OIIO::ImageInput::create(format, false, &config);
    if (!reader || !from_memory(*reader)) return false;
    memory.seek(0);
    reader->set_ioproxy(&memory);
    OIIO::ImageSpec opened;
    if (reader->open(file, opened, config)) {
      in = std::move(reader);
      return true;
    }
    if (first_error.empty()) first_error = reader->geterror();
    return false;
  };
  std::string extension = std::filesystem::path(file).extension().string();
  if (!extension.empty()) extension.erase(0, 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  std::string named_format;  // the reader the extension names, when it names one
  if (!extension.empty())
    if (auto reader = OIIO::ImageInput::create(extension, false)) {
      named_format = reader->format_name();
      if (!from_memory(*reader))
        throw ImageError(name + ": cannot decode the image: OpenImageIO's " + named_format +
                         " reader reads files by name, not bytes in memory, and photonbound "
                         "decodes images only from the bytes the scene holds (use PNG, JPEG, "
                         "WebP, TIFF, EXR, HDR, BMP or TGA)");
    }
  // glTF's formats are read by the reader their signature names alone: an image that fails
  // there is not offered to the other readers.
  if (gltf_only) {
    attempt(gltf);
  } else if (named_format.empty() || !attempt(named_format)) {
    const std::string list = OIIO::get_string_attribute("input_format_list");
    for (size_t at = 0; at <= list.size() && !in;) {
      const size_t comma = std::min(list.find(',', at), list.size());
      const std::string format = list.substr(at, comma - at);
      at = comma + 1;
      if (!format.empty() && format != named_format) attempt(format);
    }
  }
  if (!in)
    throw ImageError(name + ": cannot decode the image: " +
                     (first_error.empty()
                          ? std::string("not an image in a format photonbound reads")
                          : one_line(first_error)));
  const OIIO::ImageSpec& spec = in->spec();
  Image im;
  im.name = name;
  im.width = spec.width;
  im.height = spec.height;
  im.channels = std::min(spec.nchannels, 4);
  const std::string claim = std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                            " with " + std::to_string(spec.nchannels) + " channels";
  const uint64_t texels = uint64_t(std::max(spec.width, 0)) * uint64_t(std::max(spec.height, 0));
  if (spec.width <= 0 || spec.height <= 0 || im.channels <= 0 || texels > kMaxTexels)
    throw ImageError(name + ": the image is " + claim +
                     "; photonbound reads 1 to 4 channels and up to 2^28 texels");
  check_plausible(*in, data, size, name, claim);
  const bool u8 = spec.format == OIIO::TypeDesc::UINT8;
  check_read_chunk(name, spec, u8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT, max_bytes);
  const size_t values = size_t(texels) * size_t(im.channels);
  const uint64_t bytes = uint64_t(values) * (u8 ? 1 : sizeof(float));
  if (bytes > max_bytes)
    throw ImageTooLarge(name + ": the image is " + claim + ", " + bytes_text(bytes) + " decoded",
                        bytes);
  bool ok;
  if (u8) {
    im.u8.resize(values);
    ok = in->read_image(0, 0, 0, im.channels, OIIO::TypeDesc::UINT8, im.u8.data());
  } else {
    im.f32.resize(values);
    ok = in->read_image(0, 0, 0, im.channels, OIIO::TypeDesc::FLOAT, im.f32.data());
  }
  // A decoder may return true and only record the problem: OpenImageIO's JPEG reader does for
  // libjpeg's "Premature end of JPEG file", after filling the missing rows with grey.
  if (!ok || in->has_error()) {
    // OpenImageIO's readers quote the name they were opened with, here the made-up `file`.
    std::string why = in->has_error() ? one_line(in->geterror()) : "the decoder failed";
    for (const std::string& quoted : {" (\"" + file + "\")", " \"" + file + "\""})
      for (size_t at; (at = why.find(quoted)) != std::string::npos;) why.erase(at, quoted.size());
    throw ImageError(name + ": cannot decode the image: " + why);
  }
  in->close();
  return im;
}

void png_file(const std::string& path, const std::string& tmp, int width, int height,
              const unsigned char* rgb) {
  const OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  auto out = OIIO::ImageOutput::create(tmp);
  if (!out)
    throw ImageError(path + ": cannot create an image writer: " + one_line(OIIO::geterror()));
  bool ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::UINT8, rgb);
  ok = out->close() && ok;
  if (!ok) throw ImageError(path + ": cannot write: " + one_line(out->geterror()));
}

// Runs `body`, reporting what it throws in `failure`.
template <class Body>
void reported(CodecFailure& failure, Body&& body) {
  failure = {};
  try {
    body();
  } catch (const ImageFormatRefused& e) {
    failure = {CodecFailure::Kind::FormatRefused, e.what(), 0, e.format};
  } catch (const ImageTooLarge& e) {
    failure = {CodecFailure::Kind::TooLarge, e.what(), e.bytes, {}};
  } catch (const std::bad_alloc&) {
    failure = {CodecFailure::Kind::TooLarge, "out of memory while reading the image", 0, {}};
  } catch (const std::exception& e) {
    failure = {CodecFailure::Kind::Image, e.what(), 0, {}};
  }
}

const OiioCodec kCodec = {
    kOiioCodecAbi,
    [](const std::string& path, const ReadLimit& limit, ExrImage& out, CodecFailure& f) {
      reported(f, [&] { out = exr_pixels(path, limit); });
    },
    [](const std::string& path, const ReadLimit& limit, RgbImage& out, CodecFailure& f) {
      reported(f, [&] { out = rgb_pixels(path, limit); });
    },
    [](const unsigned char* data, size_t size, const std::string& name, const std::string& file,
       const std::string& gltf, bool gltf_only, uint64_t max_bytes, Image& out, CodecFailure& f) {
      reported(f, [&] { out = decoded(data, size, name, file, gltf, gltf_only, max_bytes); });
    },
    [](const std::string& path, const std::string& tmp, int width, int height,
       const unsigned char* rgb,
       CodecFailure& f) { reported(f, [&] { png_file(path, tmp, width, height, rgb); }); },
};

}  // namespace

}  // namespace pb

extern "C" __attribute__((visibility("default"))) const pb::OiioCodec* photonbound_oiio_codec() {
  return &pb::kCodec;
}
