// Triangles piled at one place (issue 36): one triangle instanced 65,536 times where it stands, or
// a mesh that lists one face many times. Every copy is a candidate in every geometric query of
// every other, so the boundary index's phases would examine N^2 pairs (minutes of setup), and
// copies sharing all three edges would hide each other's borders (a lone triangle listed twice
// would have none). Copies with the same three corners, bit for bit and in the same winding (so
// the same face normal), are one surface to the gather: the index is built over the first of each
// set, the others have no edges, cuts or lists of their own, and the queries look up the first.
#include "util/parallel.h"
#include "world/boundary.h"
#include "world/world.h"

#include <algorithm>
#include <cstring>

namespace pb {

namespace {

// A triangle's corners as bit patterns, rotated so that the smallest corner comes first (the
// same triangle whichever corner a mesh lists first; the winding kept).
struct CornerKey {
  uint32_t bits[9];
  uint32_t triangle;
};

CornerKey corner_key(const World& world, uint32_t t) {
  vec3 v[3];
  world.triangle(t, v[0], v[1], v[2]);
  uint32_t c[3][3];
  for (int k = 0; k < 3; ++k) std::memcpy(c[k], &v[k], 12);
  int first = 0;
  for (int k = 1; k < 3; ++k)
    if (std::memcmp(c[k], c[first], 12) < 0) first = k;
  CornerKey key;
  for (int k = 0; k < 3; ++k) std::memcpy(key.bits + 3 * k, c[(first + k) % 3], 12);
  key.triangle = t;
  return key;
}

}  // namespace

std::vector<uint8_t> BoundaryIndex::find_copies(const World& world) {
  const uint32_t n = world.triangle_count();
  std::vector<uint8_t> host(n);
  for (uint32_t t = 0; t < n; ++t) host[t] = world.may_hold_points(world.material_of(t));
  std::vector<CornerKey> keys(n);
  parallel_for(n, 4096, [&](size_t b, size_t e) {
    for (size_t t = b; t < e; ++t) keys[t] = corner_key(world, uint32_t(t));
  });
  std::sort(keys.begin(), keys.end(), [](const CornerKey& x, const CornerKey& y) {
    const int c = std::memcmp(x.bits, y.bits, sizeof x.bits);
    return c < 0 || (c == 0 && x.triangle < y.triangle);
  });
  coincident_ = 0;
  for (size_t i = 1; i < keys.size(); ++i)
    coincident_ += std::memcmp(keys[i].bits, keys[i - 1].bits, sizeof keys[i].bits) == 0;
  first_copy_.clear();
  if (coincident_ == 0) return host;
  first_copy_.resize(n);
  for (size_t i = 0; i < keys.size();) {
    size_t j = i + 1;
    while (j < keys.size() && std::memcmp(keys[i].bits, keys[j].bits, sizeof keys[i].bits) == 0)
      ++j;
    // The set holds points where any copy may (the camera sees whichever copy Embree reports).
    const uint32_t first = keys[i].triangle;
    for (size_t k = i; k < j; ++k) {
      const uint32_t t = keys[k].triangle;
      first_copy_[t] = first;
      if (t != first) {
        host[first] = host[first] || host[t];
        host[t] = 0;
      }
    }
    i = j;
  }
  return host;
}

}  // namespace pb
