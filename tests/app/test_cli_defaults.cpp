// What the command line says and does for scenes that lack something (issue 16): the default
// view and sky with one note each, the environment options and their errors, the warning for a
// black image, --camera naming the cameras there are, and resume refusing an edited map.
#include "process_fixture.h"

#include "io/image_io.h"
#include "render/scene_defaults.h"
#include "scene_builder.h"

#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using pb::test::Outcome;
using pb::test::quote;

Outcome run(const std::string& args) { return pb::test::run_photonbound(args); }

std::string scene(const std::string& name) { return std::string(PHOTONBOUND_SCENES) + "/" + name; }

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

class CliDefaults : public pb::test::TempDirTest {
 protected:
  std::string out() const { return path("out.exr"); }
  std::string quick() const {
    return " -o " + quote(out()) + " --passes 2 --resolution 16x16 --photons-per-pass 2000";
  }
};

// A file with neither camera nor light renders as shipped: one note for the default sky, one for
// the default view, the note that its chrome (roughness 0) is a perfect mirror, and the stop line.
TEST_F(CliDefaults, NoCameraNoLightRendersWithOneNoteEach) {
  const Outcome r = run("render " + quote(scene("unlit.gltf")) + quick());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(count(r.err, "\n"), 4u) << r.err;
  EXPECT_NE(r.err.find("note: " + scene("unlit.gltf") + ": material 'chrome': roughness below"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("note: " + scene("unlit.gltf") + " has no light: lit by the default sky"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("note: " + scene("unlit.gltf") + " has no camera: the default view"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("photonbound: stopped (passes) after 2 passes"), std::string::npos);
  // Given a view and an environment, nothing is assumed and nothing is said but the stop line.
  const Outcome given = run("render " + quote(scene("unlit.gltf")) + quick() +
                            " --look-from 3,2,4 --environment 0.5,0.6,0.7 --quiet");
  EXPECT_EQ(given.code, 0) << given.err;
  EXPECT_EQ(given.err, "");
}

TEST_F(CliDefaults, AWrongCameraNameListsTheCameras) {
  const Outcome r = run("render " + quote(scene("cornell.gltf")) + quick() + " --camera top");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("has no perspective camera named 'top' (its cameras: 'camera')"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(count(r.err, "\n"), 1u);
}

// Looking away from everything with no environment: black, and said so; a dim environment:
// nearly black, with the hint to brighten the preview.
TEST_F(CliDefaults, BlackImagesAreWarnedAbout) {
  const std::string sky = " --look-from 0,3,0 --look-at 0,10,0.1";
  Outcome r = run("render " + quote(scene("plane_point.gltf")) + quick() + sky);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: " + scene("plane_point.gltf") +
                       ": the image is black (mean radiance 0): no light reaches what the camera "
                       "sees and the scene has no environment (--environment)"),
            std::string::npos)
      << r.err;
  r = run("render " + quote(scene("plane_point.gltf")) + quick() + sky + " --environment 1e-5");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("the image is nearly black (mean radiance 1e-05)"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("photonbound preview --exposure"), std::string::npos) << r.err;
  r = run("render " + quote(scene("plane_point.gltf")) + quick() + sky + " --environment 0.5");
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

// Lit only by its materials' emission, an image can be bright on average and black almost
// everywhere (a sample model with emissive details and no light of its own): over 75% of the
// pixels below the preview's black level is called mostly black, and --environment is named;
// with a punctual light or an environment the darkness is what the author lit, and nothing is
// said.
TEST(DarkImageWarning, AnImageLitOnlyByEmissionAndMostlyBlackNamesTheEnvironment) {
  pb::test::SceneBuilder b;
  b.quad(pb::vec3(0), pb::vec3(1, 0, 0), pb::vec3(0, 1, 0),
         b.material(pb::vec3(0.5f), pb::vec3(1.0f)));
  auto image = [](int bright) {  // 4 x 4, `bright` pixels at radiance 1, the rest 0
    pb::ExrImage im;
    im.width = im.height = 4;
    im.channels = {"R", "G", "B"};
    im.pixels.assign(48, 0.0f);
    for (int p = 0; p < bright; ++p) im.pixels[size_t(3 * p + 1)] = 1.0f;
    return im;
  };
  // 15 of 16 dark: the mean, 1/48, is far above the black level (1.5e-4).
  const auto w = pb::dark_image_warning(image(1), b.scene);
  ASSERT_TRUE(w.has_value());
  EXPECT_NE(w->find("the image is mostly black (94% of the pixels): its only light is the "
                    "emission of its materials"),
            std::string::npos)
      << *w;
  EXPECT_NE(w->find("--environment 1 is the default sky"), std::string::npos) << *w;
  EXPECT_FALSE(pb::dark_image_warning(image(4), b.scene).has_value());  // 75%: not over
  pb::Scene lit = b.scene;
  lit.lights.push_back(
      {"lamp", pb::PunctualKind::Point, pb::vec3(0, 0, 1), pb::vec3(0, 0, -1), pb::vec3(1.0f)});
  EXPECT_FALSE(pb::dark_image_warning(image(1), lit).has_value());
  pb::Scene sky = b.scene;
  sky.environment = pb::Environment{"--environment 0.5", 1, 1, {pb::vec3(0.5f)}};
  EXPECT_FALSE(pb::dark_image_warning(image(1), sky).has_value());
  // A wholly black image keeps the black-image warning.
  const auto black = pb::dark_image_warning(image(0), b.scene);
  ASSERT_TRUE(black.has_value());
  EXPECT_EQ(black->find("the image is black (mean radiance 0)"), 0u) << *black;
}

TEST_F(CliDefaults, EnvironmentErrorsNameTheFile) {
  const std::string missing = path("missing.exr");
  Outcome r =
      run("render " + quote(scene("unlit.gltf")) + quick() + " --environment " + quote(missing));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out()));
  r = run("render " + quote(scene("unlit.gltf")) + quick() + " --environment sky.png");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--environment: 'sky.png' is neither a colour"), std::string::npos);
  // A black environment and no light: nothing to render.
  r = run("render " + quote(scene("unlit.gltf")) + quick() + " --environment 0");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no light: the scene has none and --environment 0 is black"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out()));
}

// A Radiance .hdr written by hand (flat RGBE scanlines): 4 x 2, the top row bright. Lit by it
// from above, the plane is brighter than lit by the same map upside down.
void write_hdr(const std::string& file, bool bright_top) {
  std::ofstream f(file, std::ios::binary);
  f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n";
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const bool bright = (y == 0) == bright_top;
      const unsigned char px[4] = {128, 128, 128,
                                   (unsigned char)(bright ? 130 : 127)};  // 2 or 0.25
      f.write(reinterpret_cast<const char*>(px), 4);
    }
}

double mean_red(const std::string& exr) {
  const pb::ExrImage img = pb::read_exr(exr);
  const int r = img.channel_index("R");
  double sum = 0.0;
  for (size_t p = 0; p < size_t(img.width * img.height); ++p)
    sum += img.pixels[p * img.channels.size() + size_t(r)];
  return sum / double(img.width * img.height);
}

// The default view is written as the values that reproduce it (view_from, view_at, view_up,
// view_fov, in the file's coordinates): given back as --look-from, --look-at, --up and --fov,
// the same seed renders the same image to float rounding of the camera frame (mean within
// 1e-4 relative; measured 3e-6 on DamagedHelmet).
TEST_F(CliDefaults, TheViewRenderedIsInTheMetadataAndReproducesIt) {
  ASSERT_EQ(run("render " + quote(scene("unlit.gltf")) + quick() + " --quiet").code, 0);
  const pb::ExrImage img = pb::read_exr(out());
  std::string from, at, up, fov;
  for (const auto& [k, v] : img.metadata) {
    if (k == "photonbound:view_from" || k == "view_from") from = v;
    if (k == "photonbound:view_at" || k == "view_at") at = v;
    if (k == "photonbound:view_up" || k == "view_up") up = v;
    if (k == "photonbound:view_fov" || k == "view_fov") fov = v;
  }
  ASSERT_FALSE(from.empty() || at.empty() || up.empty() || fov.empty());
  EXPECT_NEAR(std::stod(fov), 45.0, 1e-4);  // the default view's
  const std::string again = path("again.exr");
  const Outcome r =
      run("render " + quote(scene("unlit.gltf")) + " -o " + quote(again) +
          " --passes 2 --resolution 16x16 --photons-per-pass 2000 --quiet" + " --look-from " +
          from + " --look-at " + at + " --up " + up + " --fov " + fov);
  ASSERT_EQ(r.code, 0) << r.err;
  const double a = mean_red(out()), b = mean_red(again);
  EXPECT_NEAR(b, a, 1e-4 * a);
}

// The plane (rho 0.5, facing up, its point light too) under each map: the difference is rho / pi
// times the difference of the irradiances from above, pi (2 - 0.25), = 0.875. Next-event noise
// of 128 samples per image: ~0.05 each.
TEST_F(CliDefaults, EnvironmentMapsFromExrAndHdr) {
  write_hdr(path("up.hdr"), true);
  write_hdr(path("down.hdr"), false);
  const std::string base = "render " + quote(scene("plane_point.gltf")) +
                           " --passes 2 --resolution 8x8 --photons-per-pass 1000 --quiet";
  for (const char* map : {"up.hdr", "down.hdr"}) {
    const Outcome r = run(base + " -o " + quote(path(std::string(map) + ".exr")) +
                          " --environment " + quote(path(map)));
    EXPECT_EQ(r.code, 0) << r.err;
  }
  const double difference = mean_red(path("up.hdr.exr")) - mean_red(path("down.hdr.exr"));
  EXPECT_NEAR(difference, 0.875, 0.25);
  // An EXR photonbound wrote is a map too (its R, G, B channels are read by name).
  const Outcome e = run(base + " -o " + quote(path("exr.exr")) + " --environment " +
                        quote(path("up.hdr.exr")) + " --environment-scale 2");
  EXPECT_EQ(e.code, 0) << e.err;
}

// The map is part of the render's identity: an edited map is another render. A map given by a
// relative path is kept as an absolute one, like the scene: resume works from anywhere.
TEST_F(CliDefaults, ResumeRefusesAnEditedMap) {
  write_hdr(path("sky.hdr"), true);
  const std::string state = path("s.pbstate");
  ASSERT_EQ(pb::test::run_photonbound("render " + quote(scene("unlit.gltf")) + quick() +
                                          " --quiet --environment sky.hdr --state " + quote(state),
                                      dir_.string())
                .code,
            0);
  EXPECT_EQ(
      run("resume " + quote(state) + " -o " + quote(path("a.exr")) + " --passes 3 --quiet").code,
      0);
  write_hdr(path("sky.hdr"), false);
  const Outcome r = run("resume " + quote(state) + " -o " + quote(path("b.exr")) + " --passes 4");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("scene"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("b.exr")));
}

}  // namespace
