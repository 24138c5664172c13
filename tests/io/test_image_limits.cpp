// Hostile and broken image files (issue 36): each is made here, at test time, a few bytes long,
// and must be refused from what its header claims, before anything is allocated for its
// texels, or from the decoder's own report, with one line naming the file.
#include "io/image_io.h"

#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace pb {
namespace {

std::vector<unsigned char> file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

// An 8-bit RGB PNG of w x h texels, as write_png writes it.
std::vector<unsigned char> png(int w, int h) {
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() / ("pb_limits_" + std::to_string(getpid()) + ".png");
  std::vector<unsigned char> rgb(size_t(3 * w * h));
  for (size_t k = 0; k < rgb.size(); ++k) rgb[k] = uint8_t(k * 37);
  write_png(p.string(), w, h, rgb);
  std::vector<unsigned char> bytes = file_bytes(p.string());
  std::filesystem::remove(p);
  return bytes;
}

// PNG's chunk CRC (ISO 3309, as the PNG specification's annex D computes it).
uint32_t crc32(const unsigned char* d, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) {
    c ^= d[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

void put32(unsigned char* at, uint32_t v) {
  for (int k = 0; k < 4; ++k) at[k] = uint8_t(v >> (24 - 8 * k));
}

// `bytes` (a PNG) with its IHDR rewritten to claim w x h texels of `depth` bits and `colour`
// type (6: RGBA), its CRC made right: the image data stays that of the small image.
std::vector<unsigned char> claiming(std::vector<unsigned char> bytes, uint32_t w, uint32_t h,
                                    uint8_t depth, uint8_t colour) {
  unsigned char* ihdr = bytes.data() + 8;  // length, "IHDR", 13 bytes of data, CRC
  EXPECT_EQ(std::memcmp(ihdr + 4, "IHDR", 4), 0);
  put32(ihdr + 8, w);
  put32(ihdr + 12, h);
  ihdr[16] = depth;
  ihdr[17] = colour;
  put32(ihdr + 21, crc32(ihdr + 4, 17));
  return bytes;
}

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

std::string decode_error(const std::vector<unsigned char>& bytes, const std::string& name,
                         uint64_t max_bytes = UINT64_MAX) {
  try {
    decode_image(bytes.data(), bytes.size(), name, max_bytes);
  } catch (const ImageError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(name + ": ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    return m;
  }
  ADD_FAILURE() << name << " was decoded";
  return "";
}

TEST(ImageLimits, APngClaimingMoreTexelsThanItsBytesHoldIsRefusedFromItsHeader) {
  // 16384 x 16384 RGBA at 16 bits in under 100 bytes: 2 GiB of rows that deflate (at most
  // 1032:1) cannot make from them. Decoding it allocated 4 GiB of floats before libpng found
  // the data short; the refusal comes from the header, so this process stays far below that.
  const std::vector<unsigned char> bomb = claiming(png(2, 2), 16384, 16384, 16, 6);
  ASSERT_LT(bomb.size(), 100u);
  const std::string m = decode_error(bomb, "bomb.png");
  EXPECT_NE(m.find("claims 16384x16384 with 4 channels"), std::string::npos) << m;
  EXPECT_NE(m.find("more than its " + std::to_string(bomb.size()) + " bytes can hold"),
            std::string::npos)
      << m;
  EXPECT_LT(peak_rss_kib(), 1L << 20);  // 1 GiB: the bomb's texels alone are 4
}

TEST(ImageLimits, APngWhoseHeaderItsBytesCanHoldIsDecoded) {
  // The bound is deflate's, not a guess: a flat 1024 x 1024 image compresses about 1000:1 and
  // is still read.
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() / ("pb_flat_" + std::to_string(getpid()) + ".png");
  write_png(p.string(), 1024, 1024, std::vector<unsigned char>(3 * 1024 * 1024, 9));
  const std::vector<unsigned char> flat = file_bytes(p.string());
  std::filesystem::remove(p);
  EXPECT_LT(flat.size(), 3u * 1024 * 1024 / 200);  // compressed past 200:1
  const Image im = decode_image(flat.data(), flat.size(), "flat.png");
  EXPECT_EQ(im.width, 1024);
  EXPECT_EQ(im.u8[3 * 1024 * 1024 - 1], 9);
}

TEST(ImageLimits, AnImageOverTheBytesLeftIsRefusedBeforeDecoding) {
  // 64 x 64 RGB at 8 bits: 12288 bytes decoded. One byte less is refused, with the size.
  const std::vector<unsigned char> bytes = png(64, 64);
  EXPECT_EQ(image_bytes(decode_image(bytes.data(), bytes.size(), "a.png", 12288)), 12288u);
  try {
    decode_image(bytes.data(), bytes.size(), "a.png", 12287);
    ADD_FAILURE() << "decoded over the budget";
  } catch (const ImageTooLarge& e) {
    EXPECT_EQ(e.bytes, 12288u);
    EXPECT_NE(std::string(e.what()).find("64x64 with 3 channels, 12 KiB decoded"),
              std::string::npos)
        << e.what();
  }
}

TEST(ImageLimits, ATruncatedJpegIsRefusedNotFilledWithGrey) {
  // libjpeg fills the rows it could not read with grey and only warns; OpenImageIO's reader then
  // returns success with the warning recorded (has_error). Cut before its end-of-image marker,
  // tests/data/textures/solid_200_100_50.jpg must be refused, naming the file.
  std::vector<unsigned char> bytes =
      file_bytes(std::string(PHOTONBOUND_TEST_DATA) + "/textures/solid_200_100_50.jpg");
  ASSERT_GT(bytes.size(), 100u);
  EXPECT_NO_THROW(decode_image(bytes.data(), bytes.size(), "whole.jpg"));
  bytes.resize(bytes.size() - 8);
  const std::string m = decode_error(bytes, "cut.jpg");
  EXPECT_NE(m.find("cut.jpg: cannot decode the image: "), std::string::npos) << m;
  EXPECT_NE(m.find("Premature end of JPEG file"), std::string::npos) << m;
  EXPECT_EQ(m.find("image.jpg"), std::string::npos) << m;  // not the reader's made-up name
}

// A ZIP-compressed EXR of one pixel and `channels` channels whose header then claims w x h:
// its data and display windows rewritten, and its offset table (one entry per 16 rows for
// ZIP) grown to match, every entry pointing at the one chunk. A few KiB that claim gigabytes.
std::string exr_claiming(const std::string& path, int w, int h, int channels) {
  ExrImage one;
  one.width = one.height = 1;
  for (int c = 0; c < channels; ++c) one.channels.push_back("C" + std::to_string(c));
  one.pixels.assign(size_t(channels), 0.5f);
  write_exr(path, one, ExrCompression::Zip);
  std::vector<unsigned char> d = file_bytes(path);
  for (const std::string key : {"dataWindow", "displayWindow"}) {
    const std::string attr = key + '\0' + "box2i" + '\0';
    const auto at = std::search(d.begin(), d.end(), attr.begin(), attr.end());
    EXPECT_NE(at, d.end());
    const int32_t box[4] = {0, 0, w - 1, h - 1};
    std::memcpy(&*(at + std::ptrdiff_t(attr.size() + 4)), box, sizeof box);
  }
  size_t table = 0;  // the one offset, which points just past itself
  for (size_t i = 0; i + 8 < d.size() && !table; ++i) {
    int64_t v;
    std::memcpy(&v, &d[i], 8);
    if (v == int64_t(i + 8)) table = i;
  }
  EXPECT_GT(table, 0u);
  const size_t chunks = size_t(h + 15) / 16;
  std::vector<unsigned char> out(d.begin(), d.begin() + std::ptrdiff_t(table));
  const int64_t chunk = int64_t(table + 8 * chunks);
  for (size_t k = 0; k < chunks; ++k)
    out.insert(out.end(), reinterpret_cast<const unsigned char*>(&chunk),
               reinterpret_cast<const unsigned char*>(&chunk) + 8);
  out.insert(out.end(), d.begin() + std::ptrdiff_t(table + 8), d.end());
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(out.data()), std::streamsize(out.size()));
  return path;
}

std::string temp(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("pb_limits_" + std::to_string(getpid()) + "_" + name))
      .string();
}

template <class Read>
std::string read_error(const std::string& path, Read read) {
  try {
    read();
  } catch (const ImageError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    return m;
  }
  ADD_FAILURE() << path << " was read";
  return "";
}

TEST(ImageLimits, AnExrClaimingGigabytesIsRefusedFromItsHeader) {
  // 16384 x 16384 x 20 channels: 20 GiB as floats. compare, preview and --reference allocated
  // it and then found the file short (20.6 GB peak, 88 s). Past the limit it is refused from
  // the header; within it, its ZIP chunks cannot hold what it claims (deflate: 1032:1).
  const std::string path = exr_claiming(temp("claims.exr"), 16384, 16384, 20);
  ASSERT_LT(std::filesystem::file_size(path), 20000u);
  std::string m = read_error(path, [&] { read_exr(path, {uint64_t(1) << 30, "the test's"}); });
  EXPECT_NE(m.find("claims 16384x16384 pixels of 20 channels, 20 GiB as floats, over the 1.0 "
                   "GiB of the test's"),
            std::string::npos)
      << m;
  m = read_error(path, [&] { read_exr(path); });
  EXPECT_NE(m.find("bytes can hold"), std::string::npos) << m;
  m = read_error(path, [&] { read_rgb_image(path); });  // --environment's reader
  EXPECT_NE(m.find("bytes can hold"), std::string::npos) << m;
  std::filesystem::remove(path);
  EXPECT_LT(peak_rss_kib(), 1L << 20);  // 1 GiB
}

TEST(ImageLimits, AnExrWithinItsLimitIsReadAndOneByteLessIsNot) {
  const std::string path = exr_claiming(temp("small.exr"), 1, 1, 4);  // 16 bytes as floats
  EXPECT_EQ(read_exr(path, {16, "x"}).pixels.size(), 4u);
  EXPECT_EQ(read_rgb_image(path, {16, "x"}).rgb.size(), 3u);
  const std::string m = read_error(path, [&] { read_exr(path, {15, "x"}); });
  EXPECT_NE(m.find("16 bytes as floats, over the 15 bytes of x"), std::string::npos) << m;
  std::filesystem::remove(path);
}

TEST(ImageLimits, ADeepExrIsRefusedWithAMessage) {
  // Deep images (several samples per pixel) have no flat pixels to read; OpenImageIO's own
  // message was "called OpenEXRInput::read_native_scanlines without an open file".
  const std::string path = temp("deep.exr");
  OIIO::ImageSpec spec(4, 4, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Z"};
  spec.deep = true;
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out && out->open(path, spec));
  OIIO::DeepData deep(spec);
  for (int p = 0; p < 16; ++p) deep.set_samples(p, 1);
  ASSERT_TRUE(out->write_deep_image(deep));
  out->close();
  const std::string m = read_error(path, [&] { read_exr(path); });
  EXPECT_NE(m.find("is a deep image (several samples per pixel), which photonbound does not read"),
            std::string::npos)
      << m;
  std::filesystem::remove(path);
}

// ---- Container structure (io/container_check.h): what tools/fuzz.sh image found ----

// A 13x7 image of `channels` channels written by OpenImageIO with `spec`'s extra settings,
// as bytes; its pixel values are k / 1000 for value k in row-major order.
std::vector<unsigned char> written(const std::string& ext, OIIO::ImageSpec spec,
                                   int subimages = 1) {
  const std::string path = temp("written." + ext);
  std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  for (size_t k = 0; k < pixels.size(); ++k) pixels[k] = float(k % 1000) / 1000.0f;
  auto out = OIIO::ImageOutput::create(path);
  EXPECT_TRUE(out);
  std::vector<OIIO::ImageSpec> specs(size_t(subimages), spec);
  EXPECT_TRUE(out->open(path, subimages, specs.data())) << out->geterror();
  for (int s = 0; s < subimages; ++s) {
    if (s > 0) EXPECT_TRUE(out->open(path, spec, OIIO::ImageOutput::AppendSubimage));
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
  }
  out->close();
  std::vector<unsigned char> bytes = file_bytes(path);
  std::filesystem::remove(path);
  return bytes;
}

OIIO::ImageSpec spec13x7(int channels, OIIO::TypeDesc type) {
  OIIO::ImageSpec spec(13, 7, channels, type);
  return spec;
}

TEST(ContainerCheck, ExrAndTiffFilesOfEveryLayoutStillDecode) {
  // The checks refuse only what no valid file has: every layout OpenImageIO writes passes,
  // scan lines under each compression (1 to 256 lines a chunk), tiles, several parts, and
  // TIFF strips, tiles and BigTIFF; the first texel and the last (value 90 of 91 x channels)
  // come back.
  struct Case {
    std::string what, ext;
    OIIO::ImageSpec spec;
    int subimages = 1;
  };
  std::vector<Case> cases;
  for (const char* c : {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "dwaa", "dwab"}) {
    OIIO::ImageSpec s = spec13x7(3, OIIO::TypeDesc::FLOAT);
    s.attribute("compression", c);
    cases.push_back({std::string("EXR ") + c, "exr", s});
  }
  OIIO::ImageSpec tiled = spec13x7(4, OIIO::TypeDesc::HALF);
  tiled.tile_width = tiled.tile_height = 4;
  tiled.attribute("compression", "zip");
  cases.push_back({"tiled EXR", "exr", tiled});
  cases.push_back({"two-part EXR", "exr", spec13x7(3, OIIO::TypeDesc::HALF), 2});
  cases.push_back({"TIFF strips", "tif", spec13x7(3, OIIO::TypeDesc::UINT8)});
  OIIO::ImageSpec tiff_tiles = spec13x7(4, OIIO::TypeDesc::UINT16);
  tiff_tiles.tile_width = tiff_tiles.tile_height = 16;
  tiff_tiles.attribute("compression", "zip");
  cases.push_back({"TIFF tiles", "tif", tiff_tiles});
  OIIO::ImageSpec big = spec13x7(3, OIIO::TypeDesc::FLOAT);
  big.attribute("tiff:bigtiff", 1);
  cases.push_back({"BigTIFF", "tif", big});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const std::vector<unsigned char> bytes = written(c.ext, c.spec, c.subimages);
    // The writer made what the case names: a BigTIFF, a multi-part or a tiled EXR (version
    // bits 0x1000 and 0x200).
    if (c.what == "BigTIFF") ASSERT_EQ(bytes[2], 43);
    if (c.what == "two-part EXR") ASSERT_TRUE(bytes[5] & 0x10);
    if (c.what == "tiled EXR") ASSERT_TRUE(bytes[5] & 0x02);
    const Image im = decode_image(bytes.data(), bytes.size(), "t." + c.ext, UINT64_MAX);
    ASSERT_EQ(im.width, 13);
    ASSERT_EQ(im.height, 7);
    const size_t last = size_t(13 * 7 * c.spec.nchannels) - 1;
    const float first_value = im.u8.empty() ? im.f32.front() : im.u8.front() / 255.0f;
    const float last_value = im.u8.empty() ? im.f32.back() : im.u8.back() / 255.0f;
    // Within half's and 8 bits' rounding, and B44/DWA's lossy coding.
    const float tol =
        c.what.find("b44") != std::string::npos || c.what.find("dwa") != std::string::npos ? 0.05f
                                                                                           : 0.005f;
    EXPECT_NEAR(first_value, 0.0f, tol);
    EXPECT_NEAR(last_value, float(last % 1000) / 1000.0f, tol);
  }
}

// `bytes` with the 4-byte little-endian value at `at` replaced.
std::vector<unsigned char> patched32(std::vector<unsigned char> bytes, size_t at, uint32_t v) {
  for (int k = 0; k < 4; ++k) bytes[at + size_t(k)] = uint8_t(v >> (8 * k));
  return bytes;
}

size_t find_text(const std::vector<unsigned char>& d, const std::string& s) {
  const auto at = std::search(d.begin(), d.end(), s.begin(), s.end());
  EXPECT_NE(at, d.end()) << s;
  return size_t(at - d.begin());
}

TEST(ContainerCheck, AnExrAttributeLongerThanTheFileIsRefusedBeforeOpenExrAllocatesIt) {
  // OpenEXR allocated 1.7 to 2 GB for the fuzzer's string attributes of 200-byte files.
  const std::vector<unsigned char> good = written("exr", spec13x7(3, OIIO::TypeDesc::HALF));
  const std::string attr = std::string("channels") + '\0' + "chlist" + '\0';
  const size_t size_at = find_text(good, attr) + attr.size();
  const std::vector<unsigned char> bad = patched32(good, size_at, 1900000000u);
  const std::string m = decode_error(bad, "claims.exr");
  EXPECT_NE(m.find("EXR attribute 'channels' claims 1.8 GiB, more than the"), std::string::npos)
      << m;
  EXPECT_LT(peak_rss_kib(), 1L << 20);  // 1 GiB
  // The same from a file (compare, preview, --reference, --environment).
  const std::string path = temp("claims.exr");
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bad.data()), std::streamsize(bad.size()));
  EXPECT_NE(read_error(path, [&] { read_exr(path); }).find("'channels' claims 1.8 GiB"),
            std::string::npos);
  std::filesystem::remove(path);
}

TEST(ContainerCheck, AnExrAttributeMustDeclareTheSizeItsTypeReads) {
  // OpenEXR reads a known type by the type (a channel list to its empty name, a box as 16
  // bytes) and goes on from there, whatever size the attribute declares: a channel list one
  // channel short of its declared size, or a box declared 20 bytes, would be read one way by
  // the check and another by OpenEXR, which then met a 1.9 GB string the check never saw.
  const std::vector<unsigned char> good = written("exr", spec13x7(3, OIIO::TypeDesc::HALF));
  const std::string channels = std::string("channels") + '\0' + "chlist" + '\0';
  const size_t at = find_text(good, channels) + channels.size();
  const uint32_t declared = uint32_t(good[at]) | uint32_t(good[at + 1]) << 8;
  EXPECT_EQ(declared, 3u * 18u + 1u);  // B, G, R: a name, its null, 16 bytes; the empty name
  std::string m = decode_error(patched32(good, at, declared + 18), "chlist.exr");
  EXPECT_NE(m.find("'channels' of type chlist declares 73 bytes where its value reads 55"),
            std::string::npos)
      << m;
  const std::string window = std::string("dataWindow") + '\0' + "box2i" + '\0';
  m = decode_error(patched32(good, find_text(good, window) + window.size(), 20), "box.exr");
  EXPECT_NE(m.find("'dataWindow' of type box2i declares 20 bytes where its value reads 16"),
            std::string::npos)
      << m;
}

TEST(ContainerCheck, AnExrAttributeNameOverThirtyOneBytesNeedsTheLongNameFlag) {
  // The fuzzer's crash: a 70-byte name in a file without the long-name bit (0x400) made
  // OpenEXR read past the attribute; 31 bytes is the format's limit without that bit.
  std::vector<unsigned char> d = written("exr", spec13x7(3, OIIO::TypeDesc::HALF));
  const size_t at = find_text(d, std::string("lineOrder") + '\0');
  std::vector<unsigned char> longer(d.begin(), d.begin() + std::ptrdiff_t(at));
  const std::string name(40, 'x');
  longer.insert(longer.end(), name.begin(), name.end());
  longer.insert(longer.end(), d.begin() + std::ptrdiff_t(at + 9), d.end());  // "lineOrder"
  EXPECT_NE(decode_error(longer, "long.exr").find("an EXR attribute name is longer than 31 bytes"),
            std::string::npos);
}

TEST(ContainerCheck, AnExrChunkOffsetOutsideTheFileIsAnErrorNotAReadOutsideTheBuffer) {
  // A negative chunk offset made OpenEXR read before the bytes in memory (ASan: heap-buffer-
  // overflow in OpenImageIO's IOMemReader::pread); under tools/sanitize.sh this would report
  // it. A valid scan-line file whose first table entry is then -1, or past the end.
  OIIO::ImageSpec spec = spec13x7(3, OIIO::TypeDesc::HALF);
  spec.attribute("compression", "none");  // one line a chunk: 7 table entries
  const std::vector<unsigned char> good = written("exr", spec);
  size_t table = 0;  // the first entry points just past the 7 entries
  for (size_t i = 8; i + 8 < good.size() && !table; ++i) {
    int64_t v;
    std::memcpy(&v, &good[i], 8);
    if (v == int64_t(i + 7 * 8)) table = i;
  }
  ASSERT_GT(table, 0u);
  for (const int64_t offset : {int64_t(-1), int64_t(-1000), int64_t(good.size()) + 100}) {
    SCOPED_TRACE(offset);
    std::vector<unsigned char> bad = good;
    std::memcpy(&bad[table], &offset, 8);
    try {
      const Image im = decode_image(bad.data(), bad.size(), "offset.exr", UINT64_MAX);
      // OpenEXR may rebuild a broken table by scanning the chunks: then the image is whole.
      EXPECT_EQ(im.width * im.height, 13 * 7);
    } catch (const ImageError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("offset.exr: ", 0), 0u) << e.what();
    }
  }
}

TEST(ContainerCheck, TiffDataPastTheEndOfTheFileIsRefused) {
  // A tag's values, a strip, or a directory past the end: the fuzzer's TIFFs made libtiff
  // allocate what they claimed.
  const std::vector<unsigned char> good = written("tif", spec13x7(3, OIIO::TypeDesc::UINT8));
  ASSERT_EQ(good[0], 'I');
  const uint32_t ifd = uint32_t(good[4]) | uint32_t(good[5]) << 8 | uint32_t(good[6]) << 16 |
                       uint32_t(good[7]) << 24;
  const size_t n = size_t(good[ifd]) | size_t(good[ifd + 1]) << 8;
  size_t strip_counts = 0;  // the entry of tag 279, StripByteCounts
  for (size_t k = 0; k < n; ++k)
    if ((good[ifd + 2 + 12 * k] | good[ifd + 3 + 12 * k] << 8) == 279)
      strip_counts = ifd + 2 + 12 * k;
  ASSERT_GT(strip_counts, 0u);
  // One strip (13x7 RGB fits the default rows a strip): its byte count is the value itself.
  std::string m = decode_error(patched32(good, strip_counts + 8, 50000000u), "strip.tif");
  EXPECT_NE(m.find("TIFF strip or tile 0 claims 48 MiB"), std::string::npos) << m;
  // The strip count claims 2^28 LONGs of byte counts, stored at an offset past the end.
  std::vector<unsigned char> tag = patched32(good, strip_counts + 2, 4);  // LONG
  tag = patched32(tag, strip_counts + 4, 1u << 28);
  m = decode_error(patched32(tag, strip_counts + 8, 4000000000u), "tag.tif");
  EXPECT_NE(m.find("TIFF tag 279 claims 1.0 GiB at offset 4000000000"), std::string::npos) << m;
  m = decode_error(patched32(good, 4, uint32_t(good.size()) + 10), "ifd.tif");
  EXPECT_NE(m.find("TIFF directory 0 lies past the end of the file"), std::string::npos) << m;
}

// A scene's textures (ImageFormats::Gltf, the default of --texture-formats): PNG, JPEG and WebP
// decode, each by its own reader; every other format OpenImageIO writes here is refused before
// any reader sees it, named for the loader's warning (TGA, which has no signature, by its
// extension), and bytes in no format are refused unnamed (the loader refuses those).
TEST(GltfFormats, OnlyPngJpegAndWebpAreDecoded) {
  for (const char* ext : {"png", "jpg", "webp"}) {
    SCOPED_TRACE(ext);
    const std::vector<unsigned char> bytes = written(ext, spec13x7(3, OIIO::TypeDesc::UINT8));
    const Image im =
        decode_image(bytes.data(), bytes.size(), "t.bin", UINT64_MAX, ImageFormats::Gltf);
    EXPECT_EQ(im.width * im.height * im.channels, 13 * 7 * 3);
  }
  const std::vector<std::pair<std::string, std::string>> others = {
      {"tif", "TIFF"}, {"exr", "OpenEXR"}, {"hdr", "Radiance HDR"}, {"bmp", "BMP"},
      {"tga", "TGA"},  {"ppm", "PNM"},     {"sgi", "SGI"},          {"", ""}};
  for (const auto& [ext, format] : others) {
    SCOPED_TRACE(ext);
    const std::vector<unsigned char> bytes = ext.empty()
                                                 ? std::vector<unsigned char>(64, 'x')
                                                 : written(ext, spec13x7(3, OIIO::TypeDesc::UINT8));
    const std::string name = "t." + (ext.empty() ? std::string("png") : ext);
    try {
      decode_image(bytes.data(), bytes.size(), name, UINT64_MAX, ImageFormats::Gltf);
      ADD_FAILURE() << "decoded";
    } catch (const ImageFormatRefused& e) {
      EXPECT_EQ(e.format, format);
      EXPECT_EQ(std::string(e.what()).rfind(name + ": ", 0), 0u) << e.what();
    }
    // Under ImageFormats::Any the same bytes decode (OpenImageIO's PNM and SGI readers read
    // files by name only: those stay refused).
    if (!ext.empty() && ext != "ppm" && ext != "sgi")
      EXPECT_NO_THROW(decode_image(bytes.data(), bytes.size(), name));
  }
  // A PNG that its reader refuses is not offered to the other readers: the PNG reader's error.
  std::vector<unsigned char> cut = written("png", spec13x7(3, OIIO::TypeDesc::UINT8));
  cut.resize(cut.size() / 2);
  const std::string m = decode_error(cut, "cut.png");
  EXPECT_NE(m.find("cannot decode the image"), std::string::npos) << m;
}

// libjpeg holds every coefficient of a progressive JPEG (2 bytes for each of 64 per 8x8 block
// and component) from the moment OpenImageIO opens it; the walk refuses them over the read's
// budget (at least 256 MiB) first. A baseline JPEG decodes row by row: only its texels count.
TEST(ContainerCheck, AProgressiveJpegsCoefficientsCountAgainstTheBudget) {
  OIIO::ImageSpec spec = spec13x7(3, OIIO::TypeDesc::UINT8);
  spec.attribute("jpeg:progressive", 1);
  const std::vector<unsigned char> progressive = written("jpg", spec);
  const std::vector<unsigned char> baseline = written("jpg", spec13x7(3, OIIO::TypeDesc::UINT8));
  // The frame header (SOF2, SOF0): its height and width, big-endian, 3 and 5 bytes in.
  auto sof = [](const std::vector<unsigned char>& b, unsigned char code) {
    for (size_t i = 2; i + 1 < b.size(); ++i)
      if (b[i] == 0xff && b[i + 1] == code) return i + 2;
    return size_t(0);
  };
  const size_t p = sof(progressive, 0xc2), q = sof(baseline, 0xc0);
  ASSERT_GT(p, 0u) << "OpenImageIO wrote no progressive JPEG";
  ASSERT_GT(q, 0u);
  const Image small =
      decode_image(progressive.data(), progressive.size(), "p.jpg", 13 * 7 * 3, ImageFormats::Gltf);
  EXPECT_EQ(small.u8.size(), 13u * 7u * 3u);
  // 16384x16384 (2^28 texels, the most) with OpenImageIO's 4:2:0 sampling: 4 Mi blocks of luma
  // and 2 x 1 Mi of chroma, 128 bytes each.
  for (const bool is_progressive : {true, false}) {
    std::vector<unsigned char> bytes = is_progressive ? progressive : baseline;
    const size_t at = is_progressive ? p : q;
    for (const size_t k : {size_t(3), size_t(5)}) {
      bytes[at + k] = 0x40;
      bytes[at + k + 1] = 0x00;
    }
    const std::string m = decode_error(bytes, is_progressive ? "p.jpg" : "b.jpg", 64 << 20);
    const bool counted =
        m.find("holds 768 MiB of coefficients, over the 256 MiB") != std::string::npos;
    EXPECT_EQ(counted, is_progressive) << m;
  }
  EXPECT_LT(peak_rss_kib(), 1L << 19);  // 512 MiB: nothing was allocated for them
}

TEST(ContainerCheck, TheImageFuzzersFindingsAreRefusedWithOneLine) {
  // Kept from tools/fuzz.sh image (tests/data/fuzz/README.md): 15 EXRs whose attributes claim
  // 0.8 to 2 GB, or a name of 70 bytes, 2 whose channel list is shorter than its declared size,
  // an EXR 6 million pixels wide whose one 32-line chunk OpenEXR allocated (3 GB for 490 bytes),
  // 2 progressive JPEGs (25104x23807, 65296x65496) whose coefficients libjpeg allocated on open,
  // and 2 TIFFs whose data lies past their end, each refused by the container check; an EXR
  // 1,048,592 pixels wide that OpenImageIO read through a 2 GiB buffer of 256 rows, refused by
  // decode_image; and one TIFF (rss-*) that the fuzzer blamed for its process's memory but that
  // needs 135 MB alone, refused by libtiff.
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(PHOTONBOUND_TEST_DATA "/fuzz/images"))
    files.push_back(e.path());
  ASSERT_GE(files.size(), 25u) << "the image fuzz regression inputs are missing";
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    const std::vector<unsigned char> bytes = file_bytes(f.string());
    const std::string m = decode_error(bytes, f.filename().string(), uint64_t(256) << 20);
    // Refused by what the header or the decoder's buffers claim, not by a failed allocation.
    EXPECT_EQ(m.find("alloc"), std::string::npos) << m;
    for (const char c : m) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << m;
    // As a scene's texture: an EXR or TIFF is not decoded at all, a JPEG is refused as above.
    try {
      decode_image(bytes.data(), bytes.size(), "f", uint64_t(256) << 20, ImageFormats::Gltf);
      ADD_FAILURE() << "decoded as a texture";
    } catch (const ImageFormatRefused& e) {
      EXPECT_TRUE(e.format == "OpenEXR" || e.format == "TIFF") << e.what();
    } catch (const ImageError& e) {
      EXPECT_EQ(f.extension(), ".jpg") << e.what();
    }
  }
  EXPECT_LT(peak_rss_kib(), 1L << 20);  // 1 GiB
}

}  // namespace
}  // namespace pb
