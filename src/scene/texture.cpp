#include "scene/texture.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace pb {

float srgb_to_linear(float c) {
  // IEC 61966-2-1: linear below 0.04045, a 2.4 power above.
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

namespace {

// The 256 8-bit codes decoded once.
const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = srgb_to_linear(float(i) / 255.0f);
    return t;
  }();
  return table;
}

// Texel index along one axis of n texels for the integer coordinate i, by the wrap mode.
int wrap_index(int i, int n, Wrap w) {
  switch (w) {
    case Wrap::ClampToEdge:
      return std::clamp(i, 0, n - 1);
    case Wrap::MirroredRepeat: {
      const int k = ((i % (2 * n)) + 2 * n) % (2 * n);
      return k < n ? k : 2 * n - 1 - k;
    }
    case Wrap::Repeat:
    default:
      return ((i % n) + n) % n;
  }
}

// The coordinate reduced to one period before it becomes a texel index (so that huge
// coordinates cannot overflow an int): [0, 1] clamped, [0, 1) repeating, [0, 2) mirrored.
float reduce(float s, Wrap w) {
  if (!std::isfinite(s)) return 0.0f;
  switch (w) {
    case Wrap::ClampToEdge:
      return std::clamp(s, 0.0f, 1.0f);
    case Wrap::MirroredRepeat:
      return s - 2.0f * std::floor(0.5f * s);
    case Wrap::Repeat:
    default:
      return s - std::floor(s);
  }
}

}  // namespace

vec2 texture_coords(const TextureRef& t, const vec2 uv[2]) {
  const vec2 p = uv[t.texcoord & 1];
  return vec2(t.m[0] * p.x + t.m[1] * p.y + t.m[2], t.m[3] * p.x + t.m[4] * p.y + t.m[5]);
}

void set_texture_transform(TextureRef& t, vec2 offset, float rotation, vec2 scale) {
  // T R S of KHR_texture_transform with R = [cos sin; -sin cos] (its worked example: offset
  // (0, 1), rotation pi/2 and scale 0.5 map the unit square onto the lower-left quadrant).
  const float c = std::cos(rotation), s = std::sin(rotation);
  t.m[0] = c * scale.x;
  t.m[1] = s * scale.y;
  t.m[2] = offset.x;
  t.m[3] = -s * scale.x;
  t.m[4] = c * scale.y;
  t.m[5] = offset.y;
}

glm::vec4 texel(const Image& im, int x, int y, bool srgb) {
  const size_t at = (size_t(y) * size_t(im.width) + size_t(x)) * size_t(im.channels);
  float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  const int colour = im.channels <= 2 ? 1 : 3;  // grey (+ alpha) or RGB (+ alpha)
  for (int k = 0; k < im.channels && k < 4; ++k) {
    const bool is_colour = k < colour;
    if (!im.u8.empty()) {
      const uint8_t v = im.u8[at + size_t(k)];
      c[k] = srgb && is_colour ? srgb_table()[v] : float(v) * (1.0f / 255.0f);
    } else {
      const float v = std::clamp(im.f32[at + size_t(k)], 0.0f, 1.0f);
      c[k] = srgb && is_colour ? srgb_to_linear(v) : v;
    }
  }
  if (colour == 1) return glm::vec4(c[0], c[0], c[0], im.channels == 2 ? c[1] : 1.0f);
  return glm::vec4(c[0], c[1], c[2], c[3]);
}

glm::vec4 sample_image(const Image& im, const TextureRef& t, vec2 st, bool srgb) {
  const float s = reduce(st.x, t.wrap_s) * float(im.width);
  const float u = reduce(st.y, t.wrap_t) * float(im.height);
  if (t.nearest) {
    const int x = wrap_index(int(std::floor(s)), im.width, t.wrap_s);
    const int y = wrap_index(int(std::floor(u)), im.height, t.wrap_t);
    return texel(im, x, y, srgb);
  }
  // Bilinear between the four nearest texel centres ((i + 0.5) / width).
  const float x = s - 0.5f, y = u - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  const int x0 = wrap_index(int(fx), im.width, t.wrap_s);
  const int x1 = wrap_index(int(fx) + 1, im.width, t.wrap_s);
  const int y0 = wrap_index(int(fy), im.height, t.wrap_t);
  const int y1 = wrap_index(int(fy) + 1, im.height, t.wrap_t);
  const glm::vec4 top = (1.0f - ax) * texel(im, x0, y0, srgb) + ax * texel(im, x1, y0, srgb);
  const glm::vec4 bottom = (1.0f - ax) * texel(im, x0, y1, srgb) + ax * texel(im, x1, y1, srgb);
  return (1.0f - ay) * top + ay * bottom;
}

float max_texel(const Image& im, const TextureRef& t, vec2 lo, vec2 hi, bool srgb) {
  // Texel range a bilinear lookup reads along one axis: floor(s n - 1/2) and the next.
  auto range = [](float a, float b, int n, Wrap w, int& first, int& last) {
    if (w == Wrap::ClampToEdge) {
      a = std::clamp(a, 0.0f, 1.0f);
      b = std::clamp(b, 0.0f, 1.0f);
    }
    const double x0 = std::floor(double(a) * n - 0.5), x1 = std::floor(double(b) * n - 0.5) + 1;
    if (!(x1 - x0 < double(n)) || !std::isfinite(x0)) return false;  // the whole axis
    first = int(x0);
    last = int(x1);
    return true;
  };
  int x0 = 0, x1 = im.width - 1, y0 = 0, y1 = im.height - 1;
  if (!range(lo.x, hi.x, im.width, t.wrap_s, x0, x1)) x0 = 0, x1 = im.width - 1;
  if (!range(lo.y, hi.y, im.height, t.wrap_t, y0, y1)) y0 = 0, y1 = im.height - 1;
  float m = 0.0f;
  for (int y = y0; y <= y1; ++y) {
    const int yy = wrap_index(y, im.height, t.wrap_t);
    for (int x = x0; x <= x1; ++x) {
      const glm::vec4 c = texel(im, wrap_index(x, im.width, t.wrap_s), yy, srgb);
      m = std::max({m, c.x, c.y, c.z});
    }
  }
  return m;
}

vec2 mesh_uv(const Mesh& mesh, size_t tri, int set, float b1, float b2) {
  const std::vector<vec2>& uv = mesh.texcoords[set & 1];
  if (uv.empty()) return vec2(0.0f);
  const uint32_t* i = mesh.indices.data() + 3 * tri;
  return (1.0f - b1 - b2) * uv[i[0]] + b1 * uv[i[1]] + b2 * uv[i[2]];
}

float mesh_alpha(const Mesh& mesh, size_t tri, float b1, float b2) {
  if (mesh.colors.empty()) return 1.0f;
  const uint32_t* i = mesh.indices.data() + 3 * tri;
  return (1.0f - b1 - b2) * mesh.colors[i[0]].w + b1 * mesh.colors[i[1]].w +
         b2 * mesh.colors[i[2]].w;
}

bool cut_out(std::span<const Image> images, const Material& m, const vec2 uv[2],
             float vertex_alpha) {
  if (!m.masked()) return false;
  const float a = m.alpha * lookup(images, m.base_color_texture, uv, false).w * vertex_alpha;
  return a < m.alpha_cutoff;
}

float coverage(std::span<const Image> images, const Material& m, const vec2 uv[2],
               float vertex_alpha) {
  if (m.masked()) return cut_out(images, m, uv, vertex_alpha) ? 0.0f : 1.0f;
  if (!m.blended()) return 1.0f;
  const float a = m.alpha * lookup(images, m.base_color_texture, uv, false).w * vertex_alpha;
  return std::clamp(a, 0.0f, 1.0f);
}

void settle_blend(Scene& scene) {
  for (size_t k = 0; k < scene.materials.size(); ++k) {
    Material& m = scene.materials[k];
    if (!m.blended() || !(m.alpha >= 1.0f)) continue;
    bool opaque = true;
    if (m.base_color_texture.present()) {
      const Image& im = scene.images[size_t(m.base_color_texture.image)];
      const size_t texels = size_t(im.width) * size_t(im.height);
      const int a = im.channels == 2 ? 1 : im.channels >= 4 ? 3 : -1;  // as texel() reads it
      for (size_t t = 0; a >= 0 && t < texels && opaque; ++t) {
        const size_t i = t * size_t(im.channels) + size_t(a);
        opaque = im.u8.empty() ? im.f32[i] >= 1.0f : im.u8[i] == 255;
      }
    }
    for (const Mesh& mesh : scene.meshes)
      if (mesh.material == k)
        for (const glm::vec4& c : mesh.colors) opaque = opaque && c.w >= 1.0f;
    if (opaque) m.alpha_mode = AlphaMode::Opaque;
  }
}

vec3 surface_emission(std::span<const Image> images, const Material& m, const vec2 uv[2]) {
  if (!m.emits()) return vec3(0.0f);
  return m.emission * vec3(lookup(images, m.emissive_texture, uv, true));
}

vec3 emission_at(std::span<const Image> images, const Material& m, const vec2 uv[2],
                 float vertex_alpha) {
  if (!m.emits()) return vec3(0.0f);
  const float c = coverage(images, m, uv, vertex_alpha);
  return c > 0.0f ? c * surface_emission(images, m, uv) : vec3(0.0f);
}

}  // namespace pb
