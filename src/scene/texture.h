// Texture lookups over decoded images (scene.h Image, TextureRef): glTF's texture coordinates,
// KHR_texture_transform, the sampler's wrap modes, bilinear (or, for magFilter NEAREST,
// nearest) filtering, and sRGB decoding. No mipmaps: a lookup is at a point, and SPPM's
// jittered camera paths average a pixel's footprint.
#pragma once

#include "scene/scene.h"

#include <span>

namespace pb {

// The sRGB transfer function inverted (IEC 61966-2-1): encoded value in [0, 1] -> linear.
float srgb_to_linear(float encoded);

// Texture-space coordinates (s, t) of a reference at a point whose TEXCOORD_0 and _1 are uv[0]
// and uv[1]: KHR_texture_transform applied (offset, rotation, scale as the extension's worked
// example reads them: s = cos sx u + sin sy v + ox, t = -sin sx u + cos sy v + oy).
vec2 texture_coords(const TextureRef& t, const vec2 uv[2]);

// The KHR_texture_transform matrix of TextureRef::m from its parameters.
void set_texture_transform(TextureRef& t, vec2 offset, float rotation, vec2 scale);

// The texel (x, y) of an image (column x, row y from the top) as RGBA in [0, 1]: grey images
// give R = G = B, images without alpha A = 1; with `srgb` the colour channels are decoded.
glm::vec4 texel(const Image& image, int x, int y, bool srgb);

// The filtered value at texture coordinates st (0..1 across the image, repeating by the wrap
// modes), texels decoded before they are blended.
glm::vec4 sample_image(const Image& image, const TextureRef& t, vec2 st, bool srgb);

// An upper bound of the colour channels a lookup anywhere in the texture-space box [lo, hi]
// can return (the largest texel a filter there may read).
float max_texel(const Image& image, const TextureRef& t, vec2 lo, vec2 hi, bool srgb);

// The lookup of a reference at a point: 1 (white, opaque) without a texture.
inline glm::vec4 lookup(std::span<const Image> images, const TextureRef& t, const vec2 uv[2],
                        bool srgb) {
  if (!t.present()) return glm::vec4(1.0f);
  return sample_image(images[size_t(t.image)], t, texture_coords(t, uv), srgb);
}

// The texture coordinates of set `set` of a mesh at barycentrics (b1, b2) of triangle `tri`
// (weights 1 - b1 - b2, b1, b2 of its three vertices); (0, 0) when the mesh has no such set.
vec2 mesh_uv(const Mesh& mesh, size_t tri, int set, float b1, float b2);
// COLOR_0's alpha there (1 without COLOR_0).
float mesh_alpha(const Mesh& mesh, size_t tri, float b1, float b2);

// Whether a material's alpha at a point (times COLOR_0's, `vertex_alpha`) is below its cutoff
// (alphaMode MASK): rays pass there.
bool cut_out(std::span<const Image> images, const Material& m, const vec2 uv[2],
             float vertex_alpha = 1.0f);

// The share of rays a material's surface stops at a point: 1 for OPAQUE, 0 or 1 for MASK
// (cut_out), and for BLEND the alpha (baseColorFactor.a x the base colour texture's alpha x
// COLOR_0's) clamped to [0, 1] (docs/materials.md "Alpha").
float coverage(std::span<const Image> images, const Material& m, const vec2 uv[2],
               float vertex_alpha = 1.0f);

// A BLEND material whose coverage is 1 everywhere (alpha factor 1, a base colour texture without
// an alpha below 1, and no COLOR_0 alpha below 1 on its meshes) becomes OPAQUE: the same
// surface, without the per-ray coverage choice (exporters write BLEND for opaque materials).
void settle_blend(Scene& scene);

// A material's emitted radiance at a point of its surface, where a ray met it (emissiveFactor x
// strength x the emissive texture). Either side; one-sidedness is the caller's.
vec3 surface_emission(std::span<const Image> images, const Material& m, const vec2 uv[2]);

// The mean radiance emitted at a point, as the light sampler sees it: surface_emission times
// the coverage there (0 where a MASK material is cut out, alpha x Le under BLEND).
vec3 emission_at(std::span<const Image> images, const Material& m, const vec2 uv[2],
                 float vertex_alpha = 1.0f);

}  // namespace pb
