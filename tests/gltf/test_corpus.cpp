// "Any glTF file renders" (issue 16): a corpus written the way exporters write glTF, made by the
// project's own generators (python3 -m tools.make_scenes --corpus: no camera and no light,
// animations, morph targets, unimplemented extensions, directional and spot lights, a huge ground;
// tools/cpp/make_gltf_corpus: Draco, meshopt, quantised and sparse attributes, a skin without
// inverse bind matrices), renders file by file through the command line with exit code 0, a
// plausible image (finite radiance, not black, not flat) and exactly the expected notes and
// warnings on stderr.
#include "process_fixture.h"

#include "estimator/channels.h"
#include "io/image_io.h"
#include "render/scene_defaults.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <vector>

namespace {

namespace fs = std::filesystem;
using pb::test::quote;

// What stderr says besides the stop line, by file; %s stands for the file's path.
const char* kNoLight =
    "photonbound: note: %s has no light: lit by the default sky, a uniform environment of "
    "radiance 1 (--environment changes it)";
const char* kNoCamera =
    "photonbound: note: %s has no camera: the default view frames its bounds (from +Z, 15 degrees "
    "above, 45 degrees field of view; --look-from, --look-at, --up and --fov change it)";

// Their chrome (metallic 1, roughness 0) is below --mirror-roughness: a perfect mirror, noted.
const char* kChrome =
    "photonbound: note: %s: material 'chrome': roughness below 0.032 (--mirror-roughness) is "
    "rendered as a perfect mirror";

const std::map<std::string, std::vector<std::string>> kExpected = {
    {"exported.glb",
     {"photonbound: warning: %s: 1 animation is ignored; the scene is drawn as the nodes place it",
      kNoLight, kNoCamera, kChrome}},
    {"sun_spot.gltf",
     {"photonbound: warning: %s: light 'spot': range is ignored (inverse-square falloff)",
      kChrome}},
    {"huge_ground.gltf", {}},
    {"draco.glb", {kNoLight, kNoCamera}},
    {"draco.gltf", {}},
    {"meshopt.glb", {kNoLight, kNoCamera}},
    {"meshopt.gltf", {}},
    {"quantised.gltf", {}},
    {"sparse-skin.gltf", {}},
};

std::string with_path(std::string line, const std::string& path) {
  const size_t at = line.find("%s");
  return line.replace(at, 2, path);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

class Corpus : public pb::test::TempDirTest {};

TEST_F(Corpus, EveryFileRendersWithOnlyTheExpectedWarnings) {
  const std::string corpus = path("corpus");
  // The tools are the package `tools` of the source root (python3 -m tools.make_scenes).
  ASSERT_EQ(
      std::system(("cd " + quote(PHOTONBOUND_SOURCE_DIR) + " && " + quote(PHOTONBOUND_PYTHON) +
                   " -m tools.make_scenes --corpus " + quote(corpus) + " >/dev/null")
                      .c_str()),
      0);
  ASSERT_EQ(std::system((quote(PHOTONBOUND_MAKE_CORPUS) + " " + quote(corpus)).c_str()), 0);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(corpus))
    if (e.path().extension() == ".gltf" || e.path().extension() == ".glb")
      files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), kExpected.size());
  for (const fs::path& f : files) {
    const std::string name = f.filename().string();
    SCOPED_TRACE(name);
    const auto expected = kExpected.find(name);
    ASSERT_NE(expected, kExpected.end()) << "a corpus file without expectations";
    const std::string out = path(name + ".exr");
    // Not --quiet: the stop line is part of what a successful run prints.
    const pb::test::Outcome r =
        pb::test::run_photonbound("render " + quote(f.string()) + " -o " + quote(out) +
                                  " --passes 4 --resolution 48x48 --photons-per-pass 20000");
    ASSERT_EQ(r.code, 0) << r.err;
    std::vector<std::string> got = lines(r.err);
    ASSERT_FALSE(got.empty());
    EXPECT_EQ(got.back().rfind("photonbound: stopped (passes) after 4 passes, ", 0), 0u)
        << got.back();
    got.pop_back();
    std::vector<std::string> want;
    for (const std::string& l : expected->second) want.push_back(with_path(l, f.string()));
    EXPECT_EQ(got, want);

    const pb::ExrImage img = pb::read_exr(out);
    double sum = 0.0, lo = INFINITY, hi = 0.0;
    const size_t nc = img.channels.size();
    for (int c = 0; c < 3; ++c) {
      const int k = img.channel_index(pb::channel_name(pb::Channel::Radiance, c));
      ASSERT_GE(k, 0);
      for (size_t p = 0; p < size_t(img.width * img.height); ++p) {
        const float v = img.pixels[p * nc + size_t(k)];
        ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << "pixel " << p << ": " << v;
        sum += v;
        lo = std::min(lo, double(v));
        hi = std::max(hi, double(v));
      }
    }
    const double mean = sum / double(3 * img.width * img.height);
    std::printf("%-18s mean radiance %.4f, min %.4f, max %.4f\n", name.c_str(), mean, lo, hi);
    EXPECT_GE(mean, pb::kDarkRadiance);  // not black (the warning would have been printed too)
    EXPECT_GT(hi, 2.0 * lo + 1e-3);      // not flat: the object stands out of its background
  }
}

}  // namespace
