// Morton codes on a 2^10 lattice per axis (30 bits): the spatial order of the photon hits
// (render/photon_pass.cpp) and of the boundary index's segments (world/boundary.cpp).
#pragma once

#include "util/math.h"

#include <algorithm>
#include <cstdint>

namespace pb {

inline constexpr int kMortonBits = 10;

// Bit i of the 10-bit x moves to bit 3i ("magic bits" Morton spreading).
inline uint32_t morton_spread(uint32_t x) {
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

// Lattice cell of v along one axis, scale = 2^10 / the bounds' extent (0 for a flat axis); NaN
// and values below the bounds go to cell 0.
inline uint32_t morton_cell(float v, float lo, float scale) {
  constexpr float kTop = float((1u << kMortonBits) - 1);
  const float u = (v - lo) * scale;
  return u > 0.0f ? uint32_t(std::min(u, kTop)) : 0u;
}

// The code of p within bounds starting at lo, with morton_scale's per-axis scale.
inline uint32_t morton_code(const vec3& p, const vec3& lo, const vec3& scale) {
  return morton_spread(morton_cell(p.x, lo.x, scale.x)) |
         morton_spread(morton_cell(p.y, lo.y, scale.y)) << 1 |
         morton_spread(morton_cell(p.z, lo.z, scale.z)) << 2;
}

// The per-axis scale of bounds [lo, hi]: 2^10 cells across each axis that has an extent.
inline vec3 morton_scale(const vec3& lo, const vec3& hi) {
  const vec3 extent = hi - lo;
  const float cells = float(1u << kMortonBits);
  return vec3(extent.x > 0.0f ? cells / extent.x : 0.0f, extent.y > 0.0f ? cells / extent.y : 0.0f,
              extent.z > 0.0f ? cells / extent.z : 0.0f);
}

}  // namespace pb
