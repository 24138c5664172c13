// The render's own memory (render_memory.h): a render estimated beyond --max-memory is refused
// in one line before any work starts, and leaves nothing behind.
#include "process_fixture.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using pb::test::Outcome;
using pb::test::quote;
using pb::test::run_photonbound;

class Memory : public pb::test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    fs::copy_file(std::string(PHOTONBOUND_SCENES) + "/cornell.gltf", scene());
  }
  std::string scene() const { return path("scene.gltf"); }
  Outcome render(const std::string& args) const {
    return run_photonbound("render " + quote(scene()) + " -o " + quote(path("out.exr")) +
                           " --passes 1 --quiet " + args);
  }
  // Exit code 2 and one line holding every phrase; only the scene file left in the folder.
  void expect_refused(const Outcome& r, const std::vector<std::string>& phrases) const {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
    for (const std::string& p : phrases) EXPECT_NE(r.err.find(p), std::string::npos) << r.err;
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir_)) files += e.path().string() != scene();
    EXPECT_EQ(files, 0u);
  }
};

TEST_F(Memory, AResolutionBeyondTheLimitIsRefusedBeforeTheSceneLoads) {
  // 16384^2 pixels at about 640 bytes each: 160 GiB. It ran for 9 s and ended with a bare
  // "std::bad_alloc"; --max-memory is given so that the machine's size does not matter.
  expect_refused(render("--resolution 16384x16384 --max-memory 64G"),
                 {"photonbound: the render needs about 160 GiB (160 GiB for 268435456 pixels",
                  "over the 64 GiB of --max-memory; lower --resolution or --photons-per-pass"});
}

TEST_F(Memory, PhotonsAndTheSceneCountToo) {
  // A pass of 1e9 photons keeps about 170 bytes of hits and grid each; the scene's part is
  // known once it is loaded (the camera then gives the image size).
  expect_refused(render("--photons-per-pass 1000000000 --max-memory 64G"),
                 {"158 GiB for a pass of photons", "for the scene", "over the 64 GiB"});
}

TEST_F(Memory, ARenderWithinTheLimitRuns) {
  const Outcome r = render("--resolution 8x8 --photons-per-pass 1000 --max-memory 1G");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(path("out.exr")));
}

}  // namespace
