// The command line as a user meets it: exit codes (0 done, 1 failure, 2 usage), one-line
// messages, and no output file after any failure.
#include "process_fixture.h"

#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using pb::test::Outcome;
using pb::test::quote;

Outcome run(const std::string& args) { return pb::test::run_photonbound(args); }

std::string scene(const std::string& name) { return std::string(PHOTONBOUND_SCENES) + "/" + name; }

class Cli : public pb::test::TempDirTest {
 protected:
  std::string out() const { return path("out.exr"); }
  // Nothing at all may be left in the output folder after a failure (no temporary either).
  bool folder_empty() const { return fs::is_empty(dir_); }
};

void expect_one_line(const Outcome& r) {
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

TEST_F(Cli, HelpAndVersion) {
  EXPECT_EQ(run("--help").code, 0);
  for (const char* cmd : {"render --help", "resume -h", "compare --help"}) {
    const auto r = run(cmd);
    EXPECT_EQ(r.code, 0) << cmd;
    EXPECT_TRUE(r.err.empty()) << cmd << ": " << r.err;  // the usage goes to stdout
  }
  EXPECT_EQ(run("--version").code, 0);
}

TEST_F(Cli, RendersAndWritesOnlyTheImage) {
  const Outcome r = run("render " + quote(scene("cornell.gltf")) + " -o " + quote(out()) +
                        " --passes 2 --resolution 16x16 --photons-per-pass 2000 --quiet");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out()));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(Cli, WarnsWhenTheStartingRadiusIsOfTheSceneSize) {
  // The Cornell box is about 3.5 units across: 1 is ~29% of it, 0.01 well below the 5% limit.
  const std::string base = "render " + quote(scene("cornell.gltf")) + " -o " + quote(out()) +
                           " --passes 2 --resolution 8x8 --photons-per-pass 1000 --quiet";
  Outcome r = run(base + " --radius 1");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: --radius 1 is"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("% of the scene size"), std::string::npos) << r.err;
  r = run(base + " --radius 0.01");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

// PPM traces its camera paths once, so --adaptive paths cannot add any: it says so and renders;
// with a target it warns that the mean-error stop is not calibrated with paths.
TEST_F(Cli, WarnsWhereAdaptivePathsDoesNothingOrIsUncalibrated) {
  const std::string base = "render " + quote(scene("cornell.gltf")) + " -o " + quote(out()) +
                           " --passes 2 --resolution 8x8 --photons-per-pass 1000 --quiet";
  Outcome r = run(base + " --method ppm --adaptive paths");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: --adaptive paths does nothing here"), std::string::npos) << r.err;
  r = run(base + " --adaptive paths");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  // Its mean-error stop is calibrated with the two-scale bias (the default) and not with the
  // Laplacian's alone: a target says so there.
  r = run(base + " --adaptive paths --target-error 0.5");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  r = run(base + " --adaptive paths --target-error 0.5 --bias-model laplacian");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("mean-error stop is not calibrated"), std::string::npos) << r.err;
}

TEST_F(Cli, BadOptionValuesExitWithUsageError) {
  const std::string base =
      "render " + quote(scene("cornell.gltf")) + " -o " + quote(out()) + " --passes 1 ";
  const char* bad[] = {
      "--alpha 0",
      "--alpha 1.5",
      "--alpha nan",
      "--alpha abc",
      "--alpha ''",
      "--alpha -0.5",
      "--alpha inf",
      "--passes 0",
      "--passes -3",
      "--passes 2.5",
      "--passes 99999999999999999999999",
      "--time 0",
      "--time -1",
      "--time nan",
      "--photons-per-pass 0",
      "--radius 0",
      "--radius -1",
      "--max-depth 33",
      "--resolution 0x10",
      "--resolution 10",
      "--resolution axb",
      "--resolution 10x",
      "--threads -1",
      "--seed -1",
      "--direct foo",
      "--confidence 0",
      "--confidence 1",
      "--min-passes 1",
      "--error-metric foo",
      "--target-error 0",
      "--target-error -1",
      "--camera ''",
      "--bogus",
      "--alpha",
      "extra.gltf",
  };
  for (const char* b : bad) {
    const Outcome r = run(base + b);
    EXPECT_EQ(r.code, 2) << b << ": " << r.err;
    expect_one_line(r);
  }
  EXPECT_TRUE(folder_empty());
}

TEST_F(Cli, MissingStopConditionAndArguments) {
  EXPECT_EQ(run("render " + quote(scene("cornell.gltf")) + " -o " + quote(out())).code, 2);
  EXPECT_EQ(run("render -o " + quote(out()) + " --passes 1").code, 2);
  EXPECT_EQ(run("render " + quote(scene("cornell.gltf")) + " --passes 1").code, 2);
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_TRUE(folder_empty());
}

TEST_F(Cli, BadSceneFilesFailWithTheirNameAndNoOutput) {
  const std::string missing = (dir_ / "missing.gltf").string();
  Outcome r = run("render " + quote(missing) + " -o " + quote(out()) + " --passes 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("missing.gltf"), std::string::npos) << r.err;
  expect_one_line(r);

  const std::string broken = (dir_ / "broken.gltf").string();
  std::ofstream(broken) << "{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ ";
  r = run("render " + quote(broken) + " -o " + quote(out()) + " --passes 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("broken.gltf"), std::string::npos) << r.err;
  expect_one_line(r);
  fs::remove(broken);
  EXPECT_TRUE(folder_empty());
}

TEST_F(Cli, UnknownCameraIsAUsageError) {
  const Outcome r = run("render " + quote(scene("cornell.gltf")) + " -o " + quote(out()) +
                        " --passes 1 --camera nosuchcamera");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("nosuchcamera"), std::string::npos);
  EXPECT_TRUE(folder_empty());
}

TEST_F(Cli, UnwritableOutputFailsBeforeRendering) {
  const std::string bad = (dir_ / "no" / "such" / "dir" / "out.exr").string();
  Outcome r = run("render " + quote(scene("cornell.gltf")) + " -o " + quote(bad) + " --passes 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("out.exr"), std::string::npos) << r.err;
  expect_one_line(r);
  const fs::path folder = dir_ / "d.exr";  // a directory where the image should go
  fs::create_directory(folder);
  r = run("render " + quote(scene("cornell.gltf")) + " -o " + quote(folder.string()) +
          " --passes 1");
  EXPECT_EQ(r.code, 1);
  expect_one_line(r);
  EXPECT_TRUE(fs::is_empty(folder));
  fs::remove(folder);
  EXPECT_TRUE(folder_empty());
}

TEST_F(Cli, ResumeRefusesWhatWouldChangeTheImage) {
  const std::string base = "render " + quote(scene("cornell.gltf")) +
                           " --resolution 16x16 --photons-per-pass 2000 --quiet --passes 2";
  const std::string state = (dir_ / "s.pbstate").string();
  ASSERT_EQ(run(base + " -o " + quote(out()) + " --state " + quote(state)).code, 0);
  ASSERT_TRUE(fs::exists(state));
  // Same render continued: fine. Another alpha: refused, naming it.
  const std::string more = (dir_ / "more.exr").string();
  EXPECT_EQ(run(base + " -o " + quote(more) + " --resume " + quote(state) + " --passes 4").code, 0);
  Outcome r = run(base + " -o " + quote(more) + " --resume " + quote(state) + " --alpha 0.5");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("alpha: 0.7 in the state, 0.5 now"), std::string::npos) << r.err;
  expect_one_line(r);
  // `resume` takes everything that shapes the image from the state.
  r = run("resume " + quote(state) + " -o " + quote(more) + " --alpha 0.5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--alpha"), std::string::npos) << r.err;
  EXPECT_EQ(run("resume " + quote(state) + " -o " + quote(more) + " --passes 5 --quiet").code, 0);
  r = run("resume " + quote((dir_ / "nothing.pbstate").string()) + " -o " + quote(more));
  EXPECT_EQ(r.code, 1);
  expect_one_line(r);
}

TEST_F(Cli, ResumeRefusesAChangedSceneFile) {
  const std::string copy = (dir_ / "box.gltf").string();
  fs::copy_file(scene("cornell.gltf"), copy);
  const std::string state = (dir_ / "c.pbstate").string();
  ASSERT_EQ(
      run("render " + quote(copy) + " -o " + quote(out()) +
          " --resolution 16x16 --photons-per-pass 2000 --quiet --passes 2 --state " + quote(state))
          .code,
      0);
  std::ofstream(copy, std::ios::app) << "\n";  // same scene, other bytes: refuse to guess
  const Outcome r = run("resume " + quote(state) + " -o " + quote((dir_ / "r.exr").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("scene"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "r.exr"));
}

// The identity resume checks is the loaded content, not the .gltf bytes alone: an edited
// external buffer is another scene.
TEST_F(Cli, ResumeRefusesAChangedExternalBuffer) {
  fs::copy_file(scene("plane_point_external.gltf"), dir_ / "p.gltf");
  fs::copy_file(scene("plane_point_external.bin"), dir_ / "plane_point_external.bin");
  const std::string state = (dir_ / "p.pbstate").string();
  ASSERT_EQ(
      run("render " + quote((dir_ / "p.gltf").string()) + " -o " + quote(out()) +
          " --resolution 8x8 --photons-per-pass 500 --quiet --passes 2 --state " + quote(state))
          .code,
      0);
  // The lowest byte of the first float: the plane moves by an ulp, the .gltf is untouched.
  {
    std::fstream bin(dir_ / "plane_point_external.bin",
                     std::ios::in | std::ios::out | std::ios::binary);
    char b = 0;
    bin.read(&b, 1);
    bin.seekp(0);
    b ^= 1;
    bin.write(&b, 1);
  }
  const Outcome r = run("resume " + quote(state) + " -o " + quote((dir_ / "r.exr").string()));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("scene"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "r.exr"));
}

}  // namespace
