// The light sampler's textured emitters (lights.h): an emissive triangle whose radiance follows
// an emissive texture (or a MASK cut-out, or BLEND coverage) is cut into pieces chosen by their
// power, and the radiance of a sampled point is looked up, so emission and next-event estimation
// stay unbiased while their choice follows the texture.
#include "lights/lights.h"

#include "scene/texture.h"

#include <algorithm>
#include <cmath>

namespace pb {

namespace {

// Pieces per side: n = 2 sqrt(texels covered), so a piece covers about a quarter of a texel
// (the choice follows the texture to the texel), at most 32 x 32 pieces per triangle.
constexpr int kMaxSplit = 32;

// The texture coordinates of barycentrics b of the mesh's triangle `tri`, as `ref` reads them.
vec2 texture_st(const Mesh& mesh, uint32_t tri, const TextureRef& ref, vec2 b) {
  const vec2 uv[2] = {mesh_uv(mesh, tri, 0, b.x, b.y), mesh_uv(mesh, tri, 1, b.x, b.y)};
  return texture_coords(ref, uv);
}

// What a textured emitter follows: its emissive texture, else the base colour's alpha (MASK,
// BLEND).
const TextureRef& emitter_texture(const Material& mat) {
  return mat.emissive_texture.present() ? mat.emissive_texture : mat.base_color_texture;
}

}  // namespace

vec3 Lights::radiance_at(const Triangle& t, float c1, float c2) const {
  const Source& src = sources_[size_t(t.source)];
  const vec2 b = src.b0 + c1 * src.d1 + c2 * src.d2;  // barycentrics in the mesh triangle
  const vec2 uv[2] = {mesh_uv(*src.mesh, src.tri, 0, b.x, b.y),
                      mesh_uv(*src.mesh, src.tri, 1, b.x, b.y)};
  return emission_at(images_, *src.material, uv, mesh_alpha(*src.mesh, src.tri, b.x, b.y));
}

int Lights::textured_split(const Mesh& mesh, const Material& mat, uint32_t tri,
                           double* texels_out) const {
  const TextureRef& ref = emitter_texture(mat);
  if (texels_out) *texels_out = -1.0;  // no texture, or no finite texel count
  if (!ref.present()) return 1;
  auto st_at = [&](vec2 b) { return texture_st(mesh, tri, ref, b); };
  const Image& im = images_[size_t(ref.image)];
  const vec2 s0 = st_at(vec2(0.0f)), s1 = st_at(vec2(1.0f, 0.0f)), s2 = st_at(vec2(0.0f, 1.0f));
  const vec2 a = s1 - s0, c = s2 - s0;
  const double texels =
      0.5 * std::fabs(double(a.x) * c.y - double(a.y) * c.x) * double(im.width) * double(im.height);
  if (!std::isfinite(texels)) return 1;
  if (texels_out) *texels_out = texels;
  return int(std::clamp(std::ceil(2.0 * std::sqrt(texels)), 1.0, double(kMaxSplit)));
}

void Lights::add_textured(const Mesh& mesh, const Material& mat, uint32_t tri,
                          const Triangle& whole) {
  const TextureRef& ref = emitter_texture(mat);
  const bool coloured = mat.emissive_texture.present();
  auto st_at = [&](vec2 b) { return texture_st(mesh, tri, ref, b); };
  // The brightest texel a lookup inside the texture-space triangle (p0, p1, p2) may read.
  auto brightest = [&](vec2 p0, vec2 p1, vec2 p2) {
    const vec2 lo = glm::min(p0, glm::min(p1, p2)), hi = glm::max(p0, glm::max(p1, p2));
    return max_texel(images_[size_t(ref.image)], ref, lo, hi, true);
  };
  double texels = -1.0;
  const int wanted = textured_split(mesh, mat, tri, &texels);
  // Within the piece budget (lights.h); the choice stays unbiased with any pieces, since the
  // radiance of the sampled point is looked up.
  const int n = std::max(1, int(float(wanted) * split_scale_));
  if (coloured && texels >= 0.0) {
    // A triangle whose texels are all black emits nowhere: one bound over its texture box
    // spares cutting it into n^2 dark pieces (most triangles of a model whose emissive map
    // lights a few details, such as glTF's DamagedHelmet). Read only when that box is not
    // much larger than the texels the pieces would read: a sliver across the image would
    // read all of it.
    const Image& im = images_[size_t(ref.image)];
    const vec2 s0 = st_at(vec2(0.0f)), s1 = st_at(vec2(1.0f, 0.0f)), s2 = st_at(vec2(0.0f, 1.0f));
    const vec2 lo = glm::min(s0, glm::min(s1, s2)), hi = glm::max(s0, glm::max(s1, s2));
    const double box =
        (double(hi.x - lo.x) * im.width + 2.0) * (double(hi.y - lo.y) * im.height + 2.0);
    if (box <= 16.0 * texels + 64.0 && brightest(s0, s1, s2) == 0.0f) return;
  }
  const float step = 1.0f / float(n);
  // Piece with vertex 0 at barycentrics b0 and edges d1, d2 (as oriented as the triangle).
  auto piece = [&](vec2 b0, vec2 d1, vec2 d2) {
    Triangle t = whole;
    t.p0 = whole.p0 + b0.x * whole.e1 + b0.y * whole.e2;
    t.e1 = d1.x * whole.e1 + d1.y * whole.e2;
    t.e2 = d2.x * whole.e1 + d2.y * whole.e2;
    t.area = whole.area / float(n * n);
    // A bound that is positive wherever the piece may emit: its brightest texel (filters
    // included), or the factor when the texture only cuts out. Where it is 0 the piece never
    // emits, and its mean below is not worth the lookups.
    float bound = max_component(mat.emission);
    if (coloured) {
      bound *= brightest(st_at(b0), st_at(b0 + d1), st_at(b0 + d2));
      if (!(bound > 0.0f)) return;
    }
    t.source = int32_t(sources_.size());
    sources_.push_back({&mesh, &mat, tri, b0, d1, d2});
    // Mean radiance: the midpoint rule on the piece's four halves (centroids below).
    const vec2 mid[4] = {
        {1 / 6.0f, 1 / 6.0f}, {2 / 3.0f, 1 / 6.0f}, {1 / 6.0f, 2 / 3.0f}, {1 / 3.0f, 1 / 3.0f}};
    vec3 mean(0.0f);
    for (const vec2& m : mid) mean += 0.25f * radiance_at(t, m.x, m.y);
    t.radiance = mean;
    t.select = std::max(average(mean), 0.1f * bound);
    t.peak = bound;
    if (t.select > 0.0f) {
      triangles_.push_back(t);
    } else {
      sources_.pop_back();  // never emits: no piece
    }
  };
  for (int a = 0; a < n; ++a)
    for (int b = 0; a + b < n; ++b) {
      piece(vec2(float(a), float(b)) * step, vec2(step, 0.0f), vec2(0.0f, step));
      if (a + b + 1 < n)  // the inverted piece of the same lattice cell
        piece(vec2(float(a + 1), float(b + 1)) * step, vec2(-step, 0.0f), vec2(0.0f, -step));
    }
}

}  // namespace pb
