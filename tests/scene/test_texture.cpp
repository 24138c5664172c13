// Texture lookups (texture.h) against values computed by hand: sRGB decoding, texel channels,
// bilinear weights, the three wrap modes, nearest filtering, KHR_texture_transform (the
// extension's worked example), barycentric texture coordinates, MASK cut-outs and emission;
// tangent frames for normal textures (tangents.h); decoding PNG and JPEG from memory.
#include "io/image_io.h"
#include "scene/tangents.h"
#include "scene/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

namespace pb {
namespace {

// sRGB decoding written out (IEC 61966-2-1) in double.
double srgb(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// A 2 x 2 RGB image: texel (x, y) has R = 10 + 100 x + 50 y, G = 200, B = 60 x (8-bit).
Image two_by_two() {
  Image im;
  im.width = im.height = 2;
  im.channels = 3;
  im.u8.resize(12);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      uint8_t* t = im.u8.data() + 3 * (2 * y + x);
      t[0] = uint8_t(10 + 100 * x + 50 * y);
      t[1] = 200;
      t[2] = uint8_t(60 * x);
    }
  return im;
}

double red(int x, int y) { return (10 + 100 * x + 50 * y) / 255.0; }

TEST(Texture, SrgbDecodingIsTheStandardCurve) {
  EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
  EXPECT_NEAR(srgb_to_linear(1.0f), 1.0, 1e-6);
  EXPECT_NEAR(srgb_to_linear(0.04f), 0.04 / 12.92, 1e-8);  // the linear segment
  EXPECT_NEAR(srgb_to_linear(0.5f), 0.214041, 1e-6);       // ((0.555 / 1.055)^2.4)
  for (int v = 0; v < 256; ++v) {
    Image im;
    im.width = im.height = im.channels = 1;
    im.u8 = {uint8_t(v)};
    EXPECT_NEAR(texel(im, 0, 0, true).x, srgb(v / 255.0), 2e-7) << v;  // the 8-bit table
    EXPECT_NEAR(texel(im, 0, 0, false).x, v / 255.0, 1e-7) << v;
  }
}

TEST(Texture, TexelChannels) {
  // Grey gives R = G = B, grey + alpha puts the second channel in A, RGB has A = 1; alpha is
  // never sRGB-decoded.
  Image grey{"g", 1, 1, 1, {128}, {}}, grey_a{"ga", 1, 1, 2, {128, 64}, {}},
      rgb{"rgb", 1, 1, 3, {0, 128, 255}, {}}, rgba{"rgba", 1, 1, 4, {0, 128, 255, 64}, {}};
  const glm::vec4 g = texel(grey, 0, 0, true), ga = texel(grey_a, 0, 0, true);
  EXPECT_NEAR(g.x, srgb(128 / 255.0), 1e-7);
  EXPECT_EQ(g.x, g.y);
  EXPECT_EQ(g.x, g.z);
  EXPECT_EQ(g.w, 1.0f);
  EXPECT_NEAR(ga.w, 64 / 255.0, 1e-7);
  EXPECT_EQ(texel(rgb, 0, 0, false).w, 1.0f);
  const glm::vec4 c = texel(rgba, 0, 0, true);
  EXPECT_NEAR(c.y, srgb(128 / 255.0), 1e-7);
  EXPECT_NEAR(c.w, 64 / 255.0, 1e-7);
  // Float images (16-bit PNGs decode to floats) are clamped to [0, 1] and decoded the same way.
  Image f{"f", 1, 1, 1, {}, {0.5f}};
  EXPECT_NEAR(texel(f, 0, 0, true).x, srgb(0.5), 1e-6);
}

TEST(Texture, BilinearWeightsBetweenTexelCentres) {
  const Image im = two_by_two();
  TextureRef t;
  t.wrap_s = t.wrap_t = Wrap::ClampToEdge;
  // Texel centres are at 0.25 and 0.75: there a lookup returns the texel itself.
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x)
      EXPECT_NEAR(sample_image(im, t, vec2(0.25f + 0.5f * x, 0.25f + 0.5f * y), false).x, red(x, y),
                  1e-6);
  // (0.4, 0.6): x = 0.4 * 2 - 0.5 = 0.3 and y = 0.7 texels from texel (0, 0).
  const double want =
      0.7 * 0.3 * red(0, 0) + 0.7 * 0.7 * red(0, 1) + 0.3 * 0.3 * red(1, 0) + 0.3 * 0.7 * red(1, 1);
  // Weights (1 - 0.3)(1 - 0.7), (1 - 0.3) 0.7, 0.3 (1 - 0.7), 0.3 0.7 as written above.
  EXPECT_NEAR(sample_image(im, t, vec2(0.4f, 0.6f), false).x, want, 1e-6);
  EXPECT_NEAR(sample_image(im, t, vec2(0.4f, 0.6f), false).y, 200 / 255.0, 1e-6);
  // Colour textures are decoded before they are blended: halfway between B = 0 and B = 60.
  EXPECT_NEAR(sample_image(im, t, vec2(0.5f, 0.25f), true).z,
              0.5 * srgb(0.0) + 0.5 * srgb(60 / 255.0), 1e-6);
}

TEST(Texture, WrapModes) {
  const Image im = two_by_two();
  TextureRef repeat, clamp, mirror;
  clamp.wrap_s = clamp.wrap_t = Wrap::ClampToEdge;
  mirror.wrap_s = mirror.wrap_t = Wrap::MirroredRepeat;
  auto r = [&](const TextureRef& t, float s, float u) {
    return sample_image(im, t, {s, u}, false).x;
  };
  // At s = 0 the lookup sits between texel -1 and texel 0: repeat wraps to texel 1, clamp and
  // mirror stay on texel 0.
  EXPECT_NEAR(r(repeat, 0.0f, 0.25f), 0.5 * red(1, 0) + 0.5 * red(0, 0), 1e-6);
  EXPECT_NEAR(r(clamp, 0.0f, 0.25f), red(0, 0), 1e-6);
  EXPECT_NEAR(r(mirror, 0.0f, 0.25f), red(0, 0), 1e-6);
  // Periods: repeat 1, mirror 2 (s = 1.25 mirrors to 0.75), clamp holds the edge.
  EXPECT_NEAR(r(repeat, 3.25f, 0.25f), red(0, 0), 1e-6);
  EXPECT_NEAR(r(repeat, -0.75f, 0.25f), red(0, 0), 1e-6);
  EXPECT_NEAR(r(mirror, 1.25f, 0.25f), red(1, 0), 1e-6);
  EXPECT_NEAR(r(mirror, 2.25f, 0.25f), red(0, 0), 1e-6);
  EXPECT_NEAR(r(mirror, -0.25f, 0.25f), red(0, 0), 1e-6);
  EXPECT_NEAR(r(clamp, -3.0f, 0.75f), red(0, 1), 1e-6);
  EXPECT_NEAR(r(clamp, 7.0f, 0.75f), red(1, 1), 1e-6);
  // Each axis has its own mode; huge and non-finite coordinates stay in range.
  TextureRef mixed;
  mixed.wrap_t = Wrap::ClampToEdge;
  EXPECT_NEAR(r(mixed, 1.25f, 5.0f), red(0, 1), 1e-6);
  EXPECT_TRUE(std::isfinite(r(repeat, 1e30f, -1e30f)));
  EXPECT_TRUE(std::isfinite(r(mirror, NAN, INFINITY)));
}

TEST(Texture, NearestFilterTakesTheTexelUnderThePoint) {
  const Image im = two_by_two();
  TextureRef t;
  t.nearest = true;
  EXPECT_NEAR(sample_image(im, t, vec2(0.49f, 0.51f), false).x, red(0, 1), 1e-6);
  EXPECT_NEAR(sample_image(im, t, vec2(0.51f, 0.01f), false).x, red(1, 0), 1e-6);
  EXPECT_NEAR(sample_image(im, t, vec2(1.51f, 0.01f), false).x, red(1, 0), 1e-6);  // repeat
}

TEST(Texture, TransformFollowsTheExtensionsWorkedExample) {
  // KHR_texture_transform's example: offset (0, 1), rotation pi/2, scale 0.5 "utilizes only the
  // lower left quadrant of the source image, rotated clockwise 90 degrees".
  TextureRef t;
  set_texture_transform(t, vec2(0.0f, 1.0f), 1.57079632679f, vec2(0.5f));
  auto st = [&](float u, float v) {
    const vec2 uv[2] = {vec2(u, v), vec2(0.0f)};
    return texture_coords(t, uv);
  };
  auto expect = [](vec2 a, vec2 b) {
    EXPECT_NEAR(a.x, b.x, 1e-6);
    EXPECT_NEAR(a.y, b.y, 1e-6);
  };
  expect(st(0, 0), vec2(0.0f, 1.0f));  // the image's bottom-left corner
  expect(st(1, 0), vec2(0.0f, 0.5f));
  expect(st(0, 1), vec2(0.5f, 1.0f));
  expect(st(1, 1), vec2(0.5f, 0.5f));
  // Scale applies before rotation (T R S): rotation 0 and scale (2, 3) with offset (0.1, 0.2).
  TextureRef s;
  set_texture_transform(s, vec2(0.1f, 0.2f), 0.0f, vec2(2.0f, 3.0f));
  s.texcoord = 1;  // the second set
  const vec2 uv[2] = {vec2(9.0f), vec2(0.5f, 0.25f)};
  expect(texture_coords(s, uv), vec2(1.1f, 0.95f));
  // Rotation 0.3 with scale (2, 3): s = cos 2u + sin 3v, t = -sin 2u + cos 3v.
  TextureRef r;
  set_texture_transform(r, vec2(0.0f), 0.3f, vec2(2.0f, 3.0f));
  const vec2 p[2] = {vec2(0.2f, 0.7f), vec2(0.0f)};
  const double c = std::cos(0.3), sn = std::sin(0.3);
  expect(texture_coords(r, p), vec2(float(c * 0.4 + sn * 2.1), float(-sn * 0.4 + c * 2.1)));
}

TEST(Texture, MeshCoordinatesCutOutsAndEmission) {
  Mesh m;
  m.positions = {vec3(0), vec3(1, 0, 0), vec3(0, 1, 0)};
  m.indices = {0, 1, 2};
  m.texcoords[0] = {vec2(0.0f), vec2(1.0f, 0.0f), vec2(0.0f, 1.0f)};
  const vec2 uv = mesh_uv(m, 0, 0, 0.25f, 0.5f);  // 0.25 of vertex 1, 0.5 of vertex 2
  EXPECT_NEAR(uv.x, 0.25f, 1e-7);
  EXPECT_NEAR(uv.y, 0.5f, 1e-7);
  EXPECT_EQ(mesh_uv(m, 0, 1, 0.25f, 0.5f), vec2(0.0f));  // no TEXCOORD_1
  // A MASK material: alpha = factor x texture alpha, cut where below the cutoff.
  std::vector<Image> images(1);
  images[0] = Image{"a", 2, 1, 4, {255, 255, 255, 255, 255, 255, 255, 51}, {}};
  Material mat = Material::lambertian(vec3(1.0f));
  mat.alpha_mode = AlphaMode::Mask;
  mat.alpha = 0.8f;
  mat.alpha_cutoff = 0.5f;
  mat.base_color_texture.image = 0;
  mat.base_color_texture.nearest = true;
  const vec2 left[2] = {vec2(0.25f, 0.5f), vec2(0.0f)}, right[2] = {vec2(0.75f, 0.5f), vec2(0.0f)};
  EXPECT_FALSE(cut_out(images, mat, left));  // 0.8 x 1
  EXPECT_TRUE(cut_out(images, mat, right));  // 0.8 x 0.2
  mat.alpha_mode = AlphaMode::Opaque;
  EXPECT_FALSE(cut_out(images, mat, right));
  // Emission: factor x sRGB texture, 0 where cut out.
  mat.alpha_mode = AlphaMode::Mask;
  mat.emission = vec3(2.0f, 1.0f, 0.5f);
  images.push_back(Image{"e", 1, 1, 3, {128, 255, 0}, {}});
  mat.emissive_texture.image = 1;
  const vec3 e = emission_at(images, mat, left);
  EXPECT_NEAR(e.x, 2.0 * srgb(128 / 255.0), 1e-6);
  EXPECT_NEAR(e.y, 1.0, 1e-6);
  EXPECT_EQ(e.z, 0.0f);
  EXPECT_EQ(emission_at(images, mat, right), vec3(0.0f));
}

TEST(Texture, MaxTexelBoundsEveryLookupInTheBox) {
  // Random 8 x 8 image, random boxes: no lookup inside a box exceeds the bound, and the bound is
  // a texel a lookup near the box may read (here: at most the image's maximum).
  std::mt19937 gen(7);
  Image im{"r", 8, 8, 3, {}, {}};
  for (int k = 0; k < 8 * 8 * 3; ++k) im.u8.push_back(uint8_t(gen() % 256));
  for (Wrap w : {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat}) {
    TextureRef t;
    t.wrap_s = t.wrap_t = w;
    for (int trial = 0; trial < 200; ++trial) {
      std::uniform_real_distribution<float> d(-1.5f, 2.5f), size(0.0f, 0.4f);
      const vec2 lo(d(gen), d(gen)), hi = lo + vec2(size(gen), size(gen));
      const float bound = max_texel(im, t, lo, hi, true);
      for (int k = 0; k < 50; ++k) {
        std::uniform_real_distribution<float> a(0.0f, 1.0f);
        const vec2 p = lo + (hi - lo) * vec2(a(gen), a(gen));
        const glm::vec4 c = sample_image(im, t, p, true);
        EXPECT_LE(std::max({c.x, c.y, c.z}), bound + 1e-6f);
      }
    }
  }
}

TEST(Tangents, FollowTheTextureAxesAndTheirHandedness) {
  // A quad in z = 0 facing +z, u to the right (+x) and t (v) down the image, i.e. along -y: the
  // tangent is +x and cross(n, t) = +y points up the image, w = +1. Mirroring u (u along -x)
  // gives t = -x with w = -1: the bitangent stays +y.
  Mesh m;
  m.positions = {vec3(-1, -1, 0), vec3(1, -1, 0), vec3(1, 1, 0), vec3(-1, 1, 0)};
  m.normals.assign(4, vec3(0, 0, 1));
  m.indices = {0, 1, 2, 0, 2, 3};
  const std::vector<vec2> st = {vec2(0, 1), vec2(1, 1), vec2(1, 0), vec2(0, 0)};
  for (const glm::vec4& t : compute_tangents(m, st)) {
    EXPECT_NEAR(t.x, 1.0f, 1e-6);
    EXPECT_NEAR(t.y, 0.0f, 1e-6);
    EXPECT_EQ(t.w, 1.0f);
  }
  std::vector<vec2> mirrored = st;
  for (vec2& p : mirrored) p.x = 1.0f - p.x;
  for (const glm::vec4& t : compute_tangents(m, mirrored)) {
    EXPECT_NEAR(t.x, -1.0f, 1e-6);
    EXPECT_EQ(t.w, -1.0f);
  }
  // Tilted normals: the tangent is made orthogonal to the vertex normal.
  m.normals.assign(4, glm::normalize(vec3(0.5f, 0, 1)));
  for (const glm::vec4& t : compute_tangents(m, st)) {
    EXPECT_NEAR(glm::dot(vec3(t), m.normals[0]), 0.0f, 1e-6);
    EXPECT_NEAR(glm::length(vec3(t)), 1.0f, 1e-6);
  }
  // Degenerate coordinates (all equal) still give unit tangents orthogonal to the normal.
  const std::vector<vec2> flat(4, vec2(0.5f));
  for (const glm::vec4& t : compute_tangents(m, flat)) {
    EXPECT_NEAR(glm::length(vec3(t)), 1.0f, 1e-6);
    EXPECT_NEAR(glm::dot(vec3(t), m.normals[0]), 0.0f, 1e-6);
  }
}

std::vector<unsigned char> file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

TEST(DecodeImage, PngFromMemoryKeepsItsTexels) {
  // write_png (8-bit RGB) then decode the bytes: the same texels, 8-bit.
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() / ("pb_decode_" + std::to_string(getpid()) + ".png");
  std::vector<unsigned char> rgb;
  for (int k = 0; k < 3 * 5 * 2; ++k) rgb.push_back(uint8_t(k * 8));
  write_png(p.string(), 5, 2, rgb);
  const std::vector<unsigned char> bytes = file_bytes(p.string());
  std::filesystem::remove(p);
  const Image im = decode_image(bytes.data(), bytes.size(), "x.png");
  EXPECT_EQ(im.width, 5);
  EXPECT_EQ(im.height, 2);
  EXPECT_EQ(im.channels, 3);
  EXPECT_EQ(im.u8, rgb);
  EXPECT_TRUE(im.f32.empty());
}

TEST(DecodeImage, ATruncatedPngIsOneErrorNamingItAndNothingOnStderr) {
  // A PNG cut inside its image data: libpng reports it on stderr by itself ("libpng error:
  // IDAT: ...", naming no file); that text must come once, in the ImageError naming the image.
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() / ("pb_trunc_" + std::to_string(getpid()) + ".png");
  std::vector<unsigned char> rgb(3 * 64 * 64);
  std::mt19937 noise(7);  // incompressible: the IDAT holds most of the file
  for (unsigned char& v : rgb) v = uint8_t(noise() >> 24);
  write_png(p.string(), 64, 64, rgb);
  std::vector<unsigned char> bytes = file_bytes(p.string());
  std::filesystem::remove(p);
  ASSERT_GT(bytes.size(), 4000u);
  bytes.resize(bytes.size() / 2);
  testing::internal::CaptureStderr();
  std::string message;
  try {
    decode_image(bytes.data(), bytes.size(), "cut.png");
  } catch (const ImageError& e) {
    message = e.what();
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "");
  EXPECT_EQ(message.rfind("cut.png: cannot decode the image: ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(DecodeImage, JpegFromMemoryAndBadBytes) {
  // tests/data/textures/solid_200_100_50.jpg: 8 x 8 texels of (200, 100, 50), quality 100.
  const std::vector<unsigned char> bytes =
      file_bytes(std::string(PHOTONBOUND_TEST_DATA) + "/textures/solid_200_100_50.jpg");
  ASSERT_FALSE(bytes.empty());
  const Image im = decode_image(bytes.data(), bytes.size(), "solid.jpg");
  ASSERT_EQ(im.width, 8);
  ASSERT_EQ(im.channels, 3);
  for (int k = 0; k < 8 * 8; ++k) {  // JPEG at quality 100: within 2 of the original
    EXPECT_NEAR(im.u8[3 * k + 0], 200, 2);
    EXPECT_NEAR(im.u8[3 * k + 1], 100, 2);
    EXPECT_NEAR(im.u8[3 * k + 2], 50, 2);
  }
  const std::vector<unsigned char> junk = {'n', 'o', 't', ' ', 'a', 'n', ' ', 'i', 'm', 'g'};
  try {
    decode_image(junk.data(), junk.size(), "junk.png");
    ADD_FAILURE() << "expected an ImageError";
  } catch (const ImageError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("junk.png: ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  // A KTX2 file (its 12-byte identifier, then anything) is named as such, not looked up as a
  // file of that name in the working directory.
  std::vector<unsigned char> ktx2 = {0xab, 'K',  'T',  'X',  ' ',  '2',
                                     '0',  0xbb, '\r', '\n', 0x1a, '\n'};
  ktx2.resize(64, 0);
  try {
    decode_image(ktx2.data(), ktx2.size(), "lamp.ktx2");
    ADD_FAILURE() << "expected an ImageError";
  } catch (const ImageError& e) {
    EXPECT_EQ(std::string(e.what()),
              "lamp.ktx2: cannot decode the image: it is KTX2 (Basis Universal), which "
              "photonbound does not read");
  }
}

}  // namespace
}  // namespace pb
