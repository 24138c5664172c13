#include "photonbound/image_io.h"

#include <OpenImageIO/imageio.h>

#include <fcntl.h>
#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace pb {

namespace {

std::string temporary_name(const std::string& path) {
  const std::filesystem::path p(path);
  // Keep the extension: OpenImageIO picks the writer from it.
  const std::string ext = p.extension().string().empty() ? ".exr" : p.extension().string();
  std::string name = ".";  // appended piecewise: GCC 12 misreports operator+ chains (-Wrestrict)
  name.append(p.stem().string()).append(".tmp").append(std::to_string(::getpid())).append(ext);
  return (p.parent_path() / name).string();
}

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// Writes through a temporary file and renames it into place.
void write_atomic(const std::string& path, const OIIO::ImageSpec& spec, const void* data,
                  OIIO::TypeDesc type) {
  const std::string tmp = temporary_name(path);
  auto out = OIIO::ImageOutput::create(tmp);
  if (!out)
    throw ImageError(path + ": cannot create an image writer: " + one_line(OIIO::geterror()));
  bool ok = out->open(tmp, spec) && out->write_image(type, data);
  ok = out->close() && ok;
  if (!ok) {
    const std::string err = one_line(out->geterror());
    std::remove(tmp.c_str());
    throw ImageError(path + ": cannot write: " + err);
  }
  // Flush the image to disk before the rename makes it the file of record (checkpoints must
  // survive a crash), then make the rename itself durable.
  if (const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC); fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw ImageError(path + ": cannot rename the finished image into place: " + ec.message());
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (const int dfd =
          ::open(parent.empty() ? "." : parent.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
      dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace

int ExrImage::channel_index(const std::string& name) const {
  for (size_t c = 0; c < channels.size(); ++c)
    if (channels[c] == name) return int(c);
  return -1;
}

void check_writable(const std::string& path) {
  if (std::filesystem::is_directory(path)) throw ImageError(path + ": is a directory");
  const std::string tmp = temporary_name(path);
  std::ofstream f(tmp, std::ios::binary);
  if (!f) throw ImageError(path + ": cannot write here (" + std::strerror(errno) + ")");
  f.close();
  std::remove(tmp.c_str());
}

void write_exr(const std::string& path, const ExrImage& image, ExrCompression compression) {
  OIIO::ImageSpec spec(image.width, image.height, int(image.channels.size()),
                       OIIO::TypeDesc::FLOAT);
  spec.channelnames = image.channels;
  spec.alpha_channel = -1;
  spec.attribute("compression", compression == ExrCompression::Zip ? "zip" : "none");
  for (const auto& [key, value] : image.metadata) spec.attribute("photonbound:" + key, value);
  write_atomic(path, spec, image.pixels.data(), OIIO::TypeDesc::FLOAT);
}

void write_png(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb) {
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  write_atomic(path, spec, rgb.data(), OIIO::TypeDesc::UINT8);
}

ExrImage read_exr(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw ImageError(path + ": cannot read image: " + one_line(OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  ExrImage image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.channelnames;
  image.pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    throw ImageError(path + ": cannot read pixels: " + one_line(in->geterror()));
  for (const OIIO::ParamValue& p : spec.extra_attribs) {
    const std::string name = p.name().string();
    if (name.rfind("photonbound:", 0) == 0)
      image.metadata.emplace_back(name.substr(12), spec.get_string_attribute(name));
  }
  in->close();
  return image;
}

}  // namespace pb
