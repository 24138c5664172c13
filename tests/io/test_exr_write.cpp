// write_exr packs, predicts and deflates the chunks itself (libdeflate) and hands them to
// OpenEXR's core library as they are: read back by OpenEXR's own C++ reader, which undoes ZIP
// with zlib, every float must come back bit for bit, in every channel, for every chunk shape
// (a last chunk shorter than ZIP's 16 lines, one-line and one-pixel images), with the
// attributes and the compression the file claims.
#include "io/image_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

namespace pb {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("pb_exr_write_" + std::to_string(getpid()) + "_" + name))
      .string();
}

uint32_t bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

// Channels in an order EXR does not keep (it sorts by name), values of every kind the renderer
// writes: smooth ramps (which deflate shrinks), noise over all exponents and signs (which it
// does not), zeros, subnormals and infinities.
ExrImage test_image(int w, int h, uint32_t seed) {
  ExrImage im;
  im.width = w;
  im.height = h;
  im.channels = {"R", "G", "B", "Photons", "ErrorBound.R", "Variance.B", "A_first"};
  const size_t nc = im.channels.size();
  im.pixels.resize(size_t(w) * size_t(h) * nc);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<uint32_t> any;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (size_t c = 0; c < nc; ++c) {
        float v = 0.0f;
        switch (c) {
          case 0:
            v = 0.01f * float(x + y);
            break;
          case 1: {  // any finite float, both signs
            uint32_t u = any(rng);
            if (((u >> 23) & 0xffu) == 0xffu) u &= ~(1u << 23);
            std::memcpy(&v, &u, 4);
            break;
          }
          case 2:
            v = (x + y) % 5 == 0 ? std::numeric_limits<float>::infinity()
                                 : std::numeric_limits<float>::denorm_min() * float(x + 1);
            break;
          case 3:
            v = float((x * 7 + y * 3) % 11);
            break;
          default:
            v = std::ldexp(float(any(rng) % 1000) / 1000.0f, int(any(rng) % 40) - 20);
        }
        im.pixels[(size_t(y) * size_t(w) + size_t(x)) * nc + c] = v;
      }
  im.metadata = {{"seed", std::to_string(seed)}, {"note", "a b, c"}};
  return im;
}

void expect_read_back(const std::string& path, const ExrImage& im, Imf::Compression compression) {
  Imf::InputFile in(path.c_str());
  const Imf::Header& header = in.header();
  EXPECT_EQ(header.compression(), compression);
  const Imath::Box2i dw = header.dataWindow();
  ASSERT_EQ(dw.max.x - dw.min.x + 1, im.width);
  ASSERT_EQ(dw.max.y - dw.min.y + 1, im.height);
  int channels = 0;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    ++channels;
    EXPECT_EQ(it.channel().type, Imf::FLOAT) << it.name();
  }
  ASSERT_EQ(size_t(channels), im.channels.size());
  const size_t nc = im.channels.size();
  std::vector<float> back(im.pixels.size(), -1.0f);
  Imf::FrameBuffer frame;
  for (size_t c = 0; c < nc; ++c)
    frame.insert(im.channels[c],
                 Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(back.data() + c),
                            nc * sizeof(float), nc * sizeof(float) * size_t(im.width)));
  in.setFrameBuffer(frame);
  in.readPixels(dw.min.y, dw.max.y);
  size_t differ = 0;
  for (size_t k = 0; k < back.size(); ++k) differ += bits(back[k]) != bits(im.pixels[k]);
  EXPECT_EQ(differ, 0u) << path;
  for (const auto& [key, value] : im.metadata) {
    const auto* a = header.findTypedAttribute<Imf::StringAttribute>("photonbound:" + key);
    ASSERT_NE(a, nullptr) << key;
    EXPECT_EQ(a->value(), value);
  }
}

TEST(ExrWrite, ZipAndNoneReadBackBitForBitThroughOpenExr) {
  const int sizes[][2] = {{37, 53}, {300, 17}, {5, 1}, {1, 1}, {64, 16}, {64, 32}};
  uint32_t seed = 1;
  for (const auto& s : sizes) {
    const ExrImage im = test_image(s[0], s[1], seed++);
    const std::string zip = temp_path("zip.exr"), none = temp_path("none.exr");
    write_exr(zip, im, ExrCompression::Zip);
    write_exr(none, im, ExrCompression::None);
    SCOPED_TRACE(std::to_string(s[0]) + "x" + std::to_string(s[1]));
    expect_read_back(zip, im, Imf::ZIP_COMPRESSION);
    expect_read_back(none, im, Imf::NO_COMPRESSION);
    // The ramps and counts shrink: a ZIP file that stored every chunk raw would not.
    if (s[0] * s[1] >= 1000)
      EXPECT_LT(std::filesystem::file_size(zip), std::filesystem::file_size(none));
    std::filesystem::remove(zip);
    std::filesystem::remove(none);
  }
}

// pb::read_exr (the OpenImageIO module) reads the same file to the same floats.
TEST(ExrWrite, ReadExrAgrees) {
  const ExrImage im = test_image(40, 23, 9);
  const std::string path = temp_path("rt.exr");
  write_exr(path, im);
  const ExrImage back = read_exr(path);
  ASSERT_EQ(back.width, im.width);
  ASSERT_EQ(back.height, im.height);
  size_t differ = 0;
  for (size_t c = 0; c < im.channels.size(); ++c) {
    const int b = back.channel_index(im.channels[c]);
    ASSERT_GE(b, 0) << im.channels[c];
    for (size_t p = 0; p < size_t(im.width) * size_t(im.height); ++p)
      differ += bits(back.pixels[p * back.channels.size() + size_t(b)]) !=
                bits(im.pixels[p * im.channels.size() + c]);
  }
  EXPECT_EQ(differ, 0u);
  std::filesystem::remove(path);
}

std::vector<char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A render writes its film through a view of its planes (an RGB plane of stride 3 beside planes
// of stride 1, none in the file's order): the file must be, byte for byte, the one its packed
// image gives, and packed() must interleave the view's values where they belong.
TEST(ExrWrite, AViewOfPlanesWritesTheFileItsPackedImageWrites) {
  const ExrImage source = test_image(45, 37, 4);  // 37 lines: a last ZIP chunk of 5
  const size_t pixels = size_t(source.width) * size_t(source.height);
  const size_t nc = source.channels.size();
  // The source's channels regrouped as planes: the first three as one RGB plane, each other
  // one alone.
  std::vector<float> rgb(3 * pixels);
  std::vector<std::vector<float>> single(nc - 3, std::vector<float>(pixels));
  for (size_t p = 0; p < pixels; ++p) {
    for (size_t c = 0; c < 3; ++c) rgb[3 * p + c] = source.pixels[p * nc + c];
    for (size_t c = 3; c < nc; ++c) single[c - 3][p] = source.pixels[p * nc + c];
  }
  ExrView view;
  view.width = source.width;
  view.height = source.height;
  view.channels = source.channels;
  view.metadata = source.metadata;
  for (size_t c = 0; c < 3; ++c) view.planes.push_back({rgb.data() + c, 3});
  for (size_t c = 3; c < nc; ++c) view.planes.push_back({single[c - 3].data(), 1});

  const ExrImage back = packed(view);
  EXPECT_EQ(back.channels, source.channels);
  EXPECT_EQ(back.metadata, source.metadata);
  ASSERT_EQ(back.pixels.size(), source.pixels.size());
  size_t differ = 0;
  for (size_t k = 0; k < back.pixels.size(); ++k)
    differ += bits(back.pixels[k]) != bits(source.pixels[k]);
  EXPECT_EQ(differ, 0u);

  for (const ExrCompression compression : {ExrCompression::Zip, ExrCompression::None}) {
    const std::string from_view = temp_path("view.exr"), from_image = temp_path("image.exr");
    write_exr(from_view, view, compression);
    write_exr(from_image, source, compression);
    EXPECT_EQ(file_bytes(from_view), file_bytes(from_image));
    std::filesystem::remove(from_view);
    std::filesystem::remove(from_image);
  }
}

// An image whose pixels do not fill it, or a view missing a plane, is refused naming the file,
// and nothing is left behind.
TEST(ExrWrite, AnImageWithoutItsPixelsIsRefusedAndLeavesNoFile) {
  ExrImage short_of_pixels = test_image(8, 8, 2);
  short_of_pixels.pixels.pop_back();
  ExrView missing_plane = test_image(8, 8, 3);
  missing_plane.planes[2].data = nullptr;
  for (const ExrView& bad : {ExrView(short_of_pixels), missing_plane}) {
    const std::string path = temp_path("bad.exr");
    try {
      write_exr(path, bad);
      ADD_FAILURE() << "written";
    } catch (const ImageError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(path));
  }
}

}  // namespace
}  // namespace pb
