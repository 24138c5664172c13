// photonbound compare and the EXR round trip it relies on.
#include "app/compare.h"
#include "io/image_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

namespace pb {
namespace {

// A render-like image: radiance, bound, bias and noise channels, every pixel-channel equal.
ExrImage make_render(int w, int h, float l, float bound, float bias, float noise) {
  ExrImage img;
  img.width = w;
  img.height = h;
  for (const char* prefix : {"", "ErrorBound.", "Bias.", "Noise."})
    for (const char* c : {"R", "G", "B"}) img.channels.push_back(std::string(prefix) + c);
  const float values[4] = {l, bound, bias, noise};
  for (int p = 0; p < w * h; ++p)
    for (int q = 0; q < 4; ++q)
      for (int c = 0; c < 3; ++c) img.pixels.push_back(values[q]);
  return img;
}

ExrImage make_reference(int w, int h, const std::vector<float>& per_pixel) {
  ExrImage img;
  img.width = w;
  img.height = h;
  img.channels = {"R", "G", "B"};
  for (float v : per_pixel)
    for (int c = 0; c < 3; ++c) img.pixels.push_back(v);
  return img;
}

TEST(Compare, ErrorsCoverageAndRatioByHand) {
  // Four pixels of radiance 1 with bound 0.25; references 1, 1.1, 1.2, 1.5 give errors
  // 0, 0.1, 0.2, 0.5: three covered, MAE 0.2, RMSE sqrt(0.3/4).
  const ExrImage render = make_render(2, 2, 1.0f, 0.25f, 0.05f, 0.1f);
  const ExrImage ref = make_reference(2, 2, {1.0f, 1.1f, 1.2f, 1.5f});
  const CompareResult r = compare_images(render, ref, "a.exr", "b.exr");
  EXPECT_NEAR(r.mean_abs_error, 0.2, 1e-6);
  EXPECT_NEAR(r.rmse, std::sqrt(0.30 / 4.0), 1e-6);
  EXPECT_NEAR(r.coverage, 0.75, 1e-12);
  EXPECT_NEAR(r.bound_over_error, 0.25 / 0.2, 1e-6);
  EXPECT_EQ(r.bounded, 12u);
  EXPECT_EQ(r.bias_dominated, 0.0);  // |bias| 0.05 < noise 0.1
  EXPECT_NE(to_json(r).find("\"coverage\": 0.75"), std::string::npos) << to_json(r);
}

TEST(Compare, ExactAndUnknownPixelsAreCountedApart) {
  ExrImage render = make_render(2, 1, 2.0f, 0.0f, 0.0f, 0.0f);
  // Second pixel unknown: infinite bound.
  for (int c = 0; c < 3; ++c) render.pixels[12 + 3 + size_t(c)] = INFINITY;
  const CompareResult r = compare_images(render, make_reference(2, 1, {2.0f, 3.0f}), "a", "b");
  EXPECT_EQ(r.exact, 3u);
  EXPECT_EQ(r.unknown, 3u);
  EXPECT_EQ(r.bounded, 0u);
  EXPECT_NEAR(r.mean_abs_error, 0.5, 1e-9);
}

TEST(Compare, RefusesDifferentSizesAndMissingChannels) {
  const ExrImage render = make_render(4, 4, 1.0f, 0.1f, 0.0f, 0.1f);
  try {
    compare_images(render, make_reference(4, 3, std::vector<float>(12, 1.0f)), "r.exr", "ref.exr");
    FAIL() << "different sizes were compared";
  } catch (const ImageError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("r.exr is 4x4"), std::string::npos) << m;
    EXPECT_NE(m.find("ref.exr is 4x3"), std::string::npos) << m;
  }
  const ExrImage plain = make_reference(4, 4, std::vector<float>(16, 1.0f));
  EXPECT_THROW(compare_images(plain, plain, "plain.exr", "ref.exr"), ImageError);
}

TEST(ImageIo, ExrRoundTripKeepsChannelsPixelsAndMetadata) {
  ExrImage img = make_render(3, 2, 0.5f, 0.125f, -0.25f, 0.0625f);
  img.pixels[7] = INFINITY;
  img.metadata = {{"stop_reason", "target-error"}, {"passes_done", "17"}};
  const auto path = std::filesystem::temp_directory_path() /
                    ("pb_roundtrip_" + std::to_string(static_cast<long>(::getpid())) + ".exr");
  write_exr(path.string(), img);
  const ExrImage back = read_exr(path.string());
  std::filesystem::remove(path);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  for (const std::string& c : img.channels) {
    const int a = img.channel_index(c), b = back.channel_index(c);
    ASSERT_GE(b, 0) << c;
    for (size_t p = 0; p < 6; ++p)
      EXPECT_EQ(img.pixels[p * img.channels.size() + size_t(a)],
                back.pixels[p * back.channels.size() + size_t(b)])
          << c;
  }
  EXPECT_NE(std::find(back.metadata.begin(), back.metadata.end(),
                      std::pair<std::string, std::string>{"stop_reason", "target-error"}),
            back.metadata.end());
}

TEST(ImageIo, UnreadableFileIsAnError) {
  EXPECT_THROW(read_exr("/nonexistent/photonbound.exr"), ImageError);
}

// preview's exposure warning: a sun-lit render in lux (values 1e3-1e4) is white at exposure 0 and
// the advice puts its 90th percentile at 0.5; a picture a millionth as bright is black; a normal
// one, or a sky of exactly 1 (white by design, not clipped), gets no word.
TEST(ExposureWarning, NamesTheExposureThatShowsAWhiteOrBlackPicture) {
  std::vector<float> sun(1000);
  for (size_t k = 0; k < sun.size(); ++k) sun[k] = 1000.0f + 9.0f * float(k);  // 1e3 .. 1e4
  const auto white = exposure_warning(sun, 0.0, "sun.exr");
  ASSERT_TRUE(white.has_value());
  // p90 = 1000 + 9 * 900 = 9100: log2(0.5 / 9100) = -14.15, to the half stop -14.
  EXPECT_EQ(*white,
            "photonbound: warning: preview of sun.exr: 100% of the pixels are white at "
            "--exposure 0; --exposure -14 shows them");
  EXPECT_FALSE(exposure_warning(sun, -14.0, "sun.exr").has_value());

  std::vector<float> dark(sun);
  for (float& v : dark) v *= 1e-7f;  // 1e-4 .. 1e-3
  const auto black = exposure_warning(dark, 0.0, "dark.exr");
  ASSERT_TRUE(black.has_value());
  EXPECT_NE(black->find("99% of the pixels are black"), std::string::npos) << *black;
  EXPECT_NE(black->find("--exposure 9 shows them"), std::string::npos)
      << *black;  // log2(0.5 / 9.1e-4) = 9.1

  std::vector<float> sky(1000, 1.0f);  // a sky of radiance 1
  for (size_t k = 0; k < 300; ++k) sky[k] = 0.05f + 0.002f * float(k);
  EXPECT_FALSE(exposure_warning(sky, 0.0, "sky.exr").has_value());
  const auto zero = exposure_warning(std::vector<float>(10, 0.0f), 0.0, "zero.exr");
  ASSERT_TRUE(zero.has_value());  // black, and no exposure shows it
  EXPECT_NE(zero->find("which no exposure shows"), std::string::npos) << *zero;
  EXPECT_FALSE(exposure_warning({}, 0.0, "empty.exr").has_value());
}

}  // namespace
}  // namespace pb
