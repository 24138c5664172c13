// OpenImageIO is a module that image_io loads on first use (src/io/oiio_codec.h): a render that
// reads no image must not load it (0.3 s of dynamic linking, bench/README.md "Outside the pass
// loop"), and what does read or write through it must find it. The dynamic loader itself says
// which files it mapped (LD_DEBUG=files).
#include "io/image_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "process_fixture.h"

namespace pb {
namespace {

// Runs photonbound ARGS in `dir` with the loader's file log on stderr.
test::Outcome run_logged(const std::string& args, const std::string& dir) {
  return test::run_photonbound(args, dir, "LD_DEBUG=files");
}

bool mentions(const std::string& log, const std::string& what) {
  return log.find(what) != std::string::npos;
}

class ImageModule : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("pb_module_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string dir() const { return dir_.string(); }

 private:
  std::filesystem::path dir_;
};

TEST_F(ImageModule, ARenderOfASceneWithoutTexturesNeverLoadsOpenImageIo) {
  const std::string scene = std::string(PHOTONBOUND_SCENES) + "/cornell.gltf";
  const test::Outcome r =
      run_logged("render " + test::quote(scene) + " --resolution 24x24 --passes 2 -o a.exr", dir());
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(mentions(r.err, "libembree3")) << "the loader's log is missing: " << r.err;
  EXPECT_FALSE(mentions(r.err, "libOpenImageIO")) << r.err;
  EXPECT_FALSE(mentions(r.err, "photonbound_oiio")) << r.err;
  // What it wrote is a whole EXR (OpenEXR's writer, read back through the module here).
  const ExrImage img = read_exr(dir() + "/a.exr");
  EXPECT_EQ(img.width, 24);
  EXPECT_EQ(img.height, 24);
  EXPECT_GE(img.channel_index("ErrorBound.G"), 0);
}

TEST_F(ImageModule, ReadingAndWritingThroughItLoadsItOnce) {
  const std::string scene = std::string(PHOTONBOUND_SCENES) + "/cornell.gltf";
  ASSERT_EQ(test::run_photonbound(
                "render " + test::quote(scene) + " --resolution 16x12 --passes 2 -o a.exr", dir())
                .code,
            0);
  const test::Outcome r = run_logged("preview a.exr -o a.png", dir());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(mentions(r.err, "photonbound_oiio.so")) << r.err;
  EXPECT_TRUE(mentions(r.err, "libOpenImageIO")) << r.err;
  std::ifstream f(dir() + "/a.png", std::ios::binary);
  const std::vector<unsigned char> png{std::istreambuf_iterator<char>(f), {}};
  const Image im = decode_image(png.data(), png.size(), "a.png");
  EXPECT_EQ(im.width, 16);
  EXPECT_EQ(im.height, 12);
  EXPECT_EQ(im.channels, 3);
}

}  // namespace
}  // namespace pb
