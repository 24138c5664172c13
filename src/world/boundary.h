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

// The part of a kernel disc its surface reaches (ESTIMATOR.md section 11): the segments within
// the radius, projected into the point's tangent plane (t1, t2 = orthonormal_basis(n)) about
// the quadrature's centre (the point, moved by (sx, sy) into its own triangle when it lies on a
// segment). The region is what the centre sees within the disc without crossing a segment;
// BoundaryIndex::moments() integrates the kernel over it, and the gather counts the photons
// inside it alone ("The photons of the region"): a photon beyond a segment lies on another
// surface (the next of a row of boards, a panel beyond a gap), which the region's mass leaves
// out.
struct RegionSegment {
  double ax, ay, ex, ey;  // from (ax, ay) along (ex, ey)
  double d2;              // its distance from the centre, squared (a region's are in its order)
};

// A region's frame and segments, wherever the segments are kept (DiscRegion, RegionTable).
struct RegionView {
  dvec3 t1{0.0}, t2{0.0};
  double sx = 0.0, sy = 0.0;
  const RegionSegment* seg = nullptr;
  int count = 0;
  // Whether the photon at d = x_photon - point lies in the region: no segment between the centre
  // and its projection.
  bool contains(const vec3& d) const;
};

struct DiscRegion {
  static constexpr int kMaxNear = 64;  // segments kept (beyond: the nearest)
  RegionSegment seg[kMaxNear];
  int count = 0;
  RegionView frame;  // its seg is not set: view() gives the whole
  RegionView view() const {
    RegionView v = frame;
    v.seg = seg;
    v.count = count;
    return v;
  }
};

// The regions of a span of points whose discs are not whole (ESTIMATOR.md section 11), in point
// order: kept where the discs' moments are found (SPPM's camera paths, PPM's disc_pass) for the
// gather, which would otherwise scan the boundary index again (on a house of separate boards
// that scan is most of a pass). Its vectors keep their capacity across clear().
class RegionTable {
 public:
  void clear() {
    heads_.clear();
    segments_.clear();
  }
  void add(uint32_t point, const DiscRegion& region);
  // Reads a table alongside its points, in order.
  class Cursor {
   public:
    explicit Cursor(const RegionTable* t) : t_(t) {}
    // Point k's region, or null when its disc is whole (k ascending across calls).
    const RegionView* at(uint32_t k);

   private:
    const RegionTable* t_;
    size_t next_ = 0;
    RegionView view_;
  };

 private:
  struct Head {
    uint32_t point = 0, first = 0;
    RegionView frame;  // seg: null (the segments are segments_[first, first + count))
  };
  std::vector<Head> heads_;
  std::vector<RegionSegment> segments_;
};

class BoundaryIndex {
 public:
  BoundaryIndex() = default;
  // Segments of `world` and, per triangle, those within max_radius of it. work_budget: see
  // work() (a test gives a small one).
  BoundaryIndex(const World& world, float max_radius, size_t work_budget = kWorkBudget);

  // The disc of radius r about p, a point of triangle `triangle` whose normal on the side it is
  // seen from is n. r must not exceed the index's max_radius.
  DiscMoments moments(uint32_t triangle, const vec3& p, const vec3& n, float r) const;
  // The region those moments integrate over; false when no segment is within r (the whole disc;
  // `out` is then not a region).
  bool region(uint32_t triangle, const vec3& p, const vec3& n, float r, DiscRegion& out) const;
  // The moments of a region region() found for radius r: moments() without the scan.
  static DiscMoments moments_of(const DiscRegion& region, float r);
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
  static void in_space_order(std::vector<Cut>& cuts);
  std::vector<std::pair<uint32_t, uint32_t>> list_near(const World& world,
                                                       const std::vector<Cut>& cuts,
                                                       const std::vector<uint8_t>& host,
                                                       float max_radius, size_t budget, Work& work);
  void index_pairs(std::vector<std::pair<uint32_t, uint32_t>>& pairs, uint32_t n);
  void bound_runs(uint32_t n);
  void find_centres(const World& world);
};

}  // namespace pb
