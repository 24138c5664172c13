// The boundary index's lists (boundary.h, ESTIMATOR.md section 11, "Geometry"): the
// (triangle, segment) pairs as per-triangle lists, their runs' bounding spheres and the centres
// of the triangles that list segments.
#include "util/parallel.h"
#include "world/boundary.h"
#include "world/boundary_geometry.h"
#include "world/world.h"

#include <algorithm>

namespace pb {

using boundary_geometry::triangle_centre;

// The pairs as per-triangle lists, start_ and list_ (ESTIMATOR.md section 11, "Geometry").
void BoundaryIndex::index_pairs(std::vector<std::pair<uint32_t, uint32_t>>& pairs, uint32_t n) {
  // Sorted by (triangle, segment): the runs were concatenated in segment order, so a stable
  // counting sort by triangle gives std::sort's order in O(pairs + triangles) (at a 4x4 preview,
  // whose radius spans the scene, scenes/unlit.gltf lists 10.7M pairs: 1 s of std::sort).
  {
    std::vector<uint32_t> at(size_t(n) + 1, 0u);
    for (const auto& pr : pairs) ++at[size_t(pr.first) + 1];
    for (uint32_t t = 0; t < n; ++t) at[t + 1] += at[t];
    std::vector<std::pair<uint32_t, uint32_t>> sorted(pairs.size());
    for (const auto& pr : pairs) sorted[at[pr.first]++] = pr;
    pairs.swap(sorted);
  }
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  start_.assign(size_t(n) + 1, 0);
  for (const auto& [t, s] : pairs) ++start_[t + 1];
  for (uint32_t t = 0; t < n; ++t) start_[t + 1] += start_[t];
  list_.resize(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) list_[k] = pairs[k].second;
}

// The lists' runs of kGroup and kGroup^2 entries with their bounding spheres (ESTIMATOR.md
// section 11: a far point skips a run with one test).
void BoundaryIndex::bound_runs(uint32_t n) {
  for (int level = 0; level < 2; ++level) {
    const uint32_t span = level == 0 ? kGroup : kGroup * kGroup;  // list entries per run
    std::vector<uint32_t>& gs = group_start_[level];
    gs.assign(size_t(n) + 1, 0);
    for (uint32_t t = 0; t < n; ++t)
      gs[t + 1] = gs[t] + (start_[t + 1] - start_[t] + span - 1) / span;
    groups_[level].resize(gs[n]);
    parallel_for(n, 4096, [&](size_t b, size_t e) {
      for (size_t t = b; t < e; ++t) {
        for (uint32_t g = gs[t]; g < gs[t + 1]; ++g) {
          const uint32_t first = start_[t] + (g - gs[t]) * span;
          const uint32_t last = std::min(first + span, start_[t + 1]);
          Bounds box;
          for (uint32_t k = first; k < last; ++k) {
            box.extend(segments_[list_[k]].a);
            box.extend(segments_[list_[k]].b);
          }
          const vec3 c = 0.5f * (box.lo + box.hi);
          float radius = 0.0f;
          for (uint32_t k = first; k < last; ++k) {
            const Segment& sg = segments_[list_[k]];
            radius = std::max(radius, glm::length(sg.mid - c) + sg.half);
          }
          groups_[level][g] = {c, radius};
        }
      }
    });
  }
}

// Centres of the triangles with segments, to tell which side of a segment through a point is
// its surface (moments(); ESTIMATOR.md section 11).
void BoundaryIndex::find_centres(const World& world) {
  const uint32_t n = world.triangle_count();
  centre_.assign(n, vec3(0.0f));
  parallel_for(n, 4096, [&](size_t b, size_t e) {
    for (size_t t = b; t < e; ++t) {
      if (start_[t + 1] == start_[t]) continue;
      vec3 v[3];
      world.triangle(uint32_t(t), v[0], v[1], v[2]);
      centre_[t] = triangle_centre(v);
    }
  });
}

size_t BoundaryIndex::memory_bytes() const {
  return segments_.capacity() * sizeof(Segment) + start_.capacity() * sizeof(uint32_t) +
         first_copy_.capacity() * sizeof(uint32_t) +
         (group_start_[0].capacity() + group_start_[1].capacity()) * sizeof(uint32_t) +
         (groups_[0].capacity() + groups_[1].capacity()) * sizeof(Group) +
         list_.capacity() * sizeof(uint32_t) + centre_.capacity() * sizeof(vec3);
}

}  // namespace pb
