// Where the surface under a kernel disc ends (ESTIMATOR.md section 11). At a point a distance d
// from an edge of its surface, the disc of radius R reaches past the edge, where no photon can
// land; the kernel estimate is then about c L, with c the share of the kernel's mass on the
// surface, and the Laplacian kernel no longer integrates to zero. Only the geometry can give c
// (photons cannot tell "no surface" from "no light"), so the index below finds, once per scene,
// every segment where a surface ends as the gather sees it:
//  - border edges of a triangle (no neighbour shares them) and creases whose neighbour faces
//    away (normals at 90 degrees or more: the gather's same-side test rejects its photons);
//  - blockers: other geometry rising from a surface (a block standing on a floor), cut with the
//    surface's plane;
// and lists, per triangle, the segments within the largest radius of it. moments() then
// integrates the kernel over the part of the disc visible from the point within those
// segments, in polar coordinates about the point (the star-shaped region of the disc the point
// sees along its surface).
#pragma once

#include "estimator/disc_moments.h"
#include "util/math.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace pb {

class World;

class BoundaryIndex {
 public:
  BoundaryIndex() = default;
  // Segments of `world` and, per triangle, those within max_radius of it. work_budget: see
  // work() (a test gives a small one).
  BoundaryIndex(const World& world, float max_radius, size_t work_budget = kWorkBudget);

  // The disc of radius r about p, a point of triangle `triangle` whose normal on the side it is
  // seen from is n. r must not exceed the index's max_radius.
  DiscMoments moments(uint32_t triangle, const vec3& p, const vec3& n, float r) const;
  // A radius up to which moments(triangle, p, n, radius) is the whole disc: the distance from p
  // to the nearest segment within r, rounded down, or r when none is. PPM's points are fixed
  // and their radii only shrink, so one call per point at the initial radius spares every later
  // pass the segment scan of the points far from an edge.
  float clearance(uint32_t triangle, const vec3& p, float r) const;

  size_t segment_count() const { return segments_.size(); }
  // The index was given up (more than kPairBudget + 16 per triangle segment-triangle pairs
  // within the radius, or more than kWorkBudget + 256 per triangle candidates examined): every
  // disc counts as whole.
  bool truncated() const { return truncated_; }
  static constexpr size_t kPairBudget = size_t(1) << 24;
  static constexpr size_t kWorkBudget = size_t(1) << 26;
  // The construction's work: candidate triangles the geometric queries returned and edges
  // compared, what grows with the triangles piled at one place (ESTIMATOR.md section 11). Past
  // the budget plus 256 per triangle the construction stops (each thread finishing the queries
  // it is in: at most three, of at most a candidate per triangle each) and the index is given up.
  // Measured: the shipped scenes and corpora examine at most 54 per triangle (cornell_heavy.glb at
  // 512x512).
  size_t work() const { return work_; }
  // Triangles that repeat another's corners (bit for bit, same winding) are indexed once: how
  // many triangles the index treats as copies of an earlier one.
  size_t coincident_count() const { return coincident_; }
  size_t memory_bytes() const;

  // Directions of the polar quadrature.
  static constexpr int kDirections = 64;

 private:
  struct Segment {
    vec3 a, b;
    // Its bounding sphere (midpoint, half length): moments() rejects the far segments of a
    // large triangle's list with it before the exact distance.
    vec3 mid{0.0f};
    float half = 0.0f;
  };
  std::vector<Segment> segments_;
  std::vector<uint32_t> start_;  // triangle t's segments: list_[start_[t], start_[t + 1])
  std::vector<uint32_t> list_;
  // The list in runs of kGroup entries, each with a bounding sphere of its segments, and the
  // runs in runs of kGroup again (kGroup^2 entries): a floor under a tessellated sphere lists
  // hundreds of short cuts of the sphere's foot, and a point far from them skips each run with
  // one test. Triangle t's runs of level l: groups_[l][group_start_[l][t], ...).
  static constexpr uint32_t kGroup = 8;
  struct Group {
    vec3 centre{0.0f};
    float radius = 0.0f;
  };
  std::vector<uint32_t> group_start_[2];
  std::vector<Group> groups_[2];
  // Calls visit(segment) for triangle t's listed segments in list order, skipping every run
  // (of kGroup^2, then of kGroup) whose bounding sphere skip(group) rejects, until visit returns
  // false. moments() and clearance() both scan this way.
  template <class Skip, class Visit>
  void scan(uint32_t triangle, Skip&& skip, Visit&& visit) const;
  std::vector<vec3> centre_;  // of triangles with segments (zero elsewhere)
  // Per triangle, the first triangle with the same corners (itself when none); empty when no
  // triangle repeats another. Only those first ones are indexed; the queries look them up.
  std::vector<uint32_t> first_copy_;
  bool truncated_ = false;
  size_t work_ = 0;
  size_t coincident_ = 0;

  // The constructor's phases (boundary.cpp), in order. A segment found for a host triangle:
  struct Cut;
  struct Work;  // the work counted against kWorkBudget
  // Which triangles may hold points (first copies only: 0 for a later copy) and first_copy_
  // (boundary_copies.cpp).
  std::vector<uint8_t> find_copies(const World& world);
  static std::vector<Cut> boundary_edges(const World& world, const std::vector<uint8_t>& host,
                                         const std::vector<uint32_t>& first_copy, Work& work);
  static bool add_blockers(const World& world, const std::vector<uint8_t>& host,
                           const std::vector<uint32_t>& first_copy, float max_radius, size_t budget,
                           Work& work, std::vector<Cut>& cuts);
  std::vector<std::pair<uint32_t, uint32_t>> list_near(const World& world,
                                                       const std::vector<Cut>& cuts,
                                                       const std::vector<uint8_t>& host,
                                                       float max_radius, size_t budget, Work& work);
  void index_pairs(std::vector<std::pair<uint32_t, uint32_t>>& pairs, uint32_t n);
  void bound_runs(uint32_t n);
  void find_centres(const World& world);
};

}  // namespace pb
