// The boundary index's queries (boundary.h): the clearance of a point and the moments of the
// part of its disc it sees along its surface (ESTIMATOR.md section 11).
#include "estimator/kernel.h"
#include "world/boundary.h"
#include "world/boundary_geometry.h"

#include <algorithm>
#include <cmath>

namespace pb {

namespace {

using boundary_geometry::segment_distance2;

constexpr int kK = BoundaryIndex::kDirections;

struct Directions {
  double c[kK], s[kK];
  Directions() {
    for (int k = 0; k < kK; ++k) {
      const double th = (double(k) + 0.5) * 2.0 * kPiD / kK;
      c[k] = std::cos(th);
      s[k] = std::sin(th);
    }
  }
};
const Directions& directions() {
  static const Directions d;
  return d;
}

// Segments near a point, in its tangent plane about it: segment i runs from (ax, ay) along
// (ex, ey). The polar quadrature of moments() (ESTIMATOR.md section 11) works on these.
struct Projected {
  static constexpr int kMaxNear = 64;
  double ax[kMaxNear], ay[kMaxNear], ex[kMaxNear], ey[kMaxNear];
  int count = 0;

  // Whether a segment passes within 1e-4 r of the centre (r2 = r^2).
  bool through_centre(double r2) const {
    double min_d2 = INFINITY;
    for (int i = 0; i < count; ++i) {
      const double len2 = ex[i] * ex[i] + ey[i] * ey[i];
      const double s =
          len2 > 0.0 ? std::clamp(-(ax[i] * ex[i] + ay[i] * ey[i]) / len2, 0.0, 1.0) : 0.0;
      const double qx = ax[i] + s * ex[i], qy = ay[i] + s * ey[i];
      min_d2 = std::min(min_d2, qx * qx + qy * qy);
    }
    return min_d2 < 1e-8 * r2;
  }

  // Moves the centre 1e-3 r (at most the distance) towards (cx, cy).
  void shift(double cx, double cy, float r) {
    const double len = std::sqrt(cx * cx + cy * cy);
    if (!(len > 0.0)) return;
    const double shift = std::min(1e-3 * double(r), len);
    for (int i = 0; i < count; ++i) {
      ax[i] -= shift * cx / len;
      ay[i] -= shift * cy / len;
    }
  }

  // In each direction of the quadrature the visible extent rho (the first segment the ray meets,
  // or r). A segment not through the centre subtends less than pi, so only the directions
  // within the arc between its end points' angles (one more each side, for rounding) can meet
  // it; the exact test decides.
  void visible_extents(double r, double rho[kK]) const {
    const Directions& dir = directions();
    std::fill(rho, rho + kK, r);
    constexpr double step = 2.0 * kPiD / kK;
    for (int i = 0; i < count; ++i) {
      const double ta = std::atan2(ay[i], ax[i]), tb = std::atan2(ay[i] + ey[i], ax[i] + ex[i]);
      double width = tb - ta;
      if (width > kPiD) width -= 2.0 * kPiD;
      if (width < -kPiD) width += 2.0 * kPiD;
      const double from = width >= 0.0 ? ta : tb;
      // Direction k sits at (k + 0.5) step.
      const int k0 = int(std::floor(from / step - 0.5)) - 1;
      const int k1 = int(std::ceil((from + std::fabs(width)) / step - 0.5)) + 1;
      for (int kk = k0; kk <= k1 && kk < k0 + kK; ++kk) {
        const int k = ((kk % kK) + kK) % kK;
        const double dx = dir.c[k], dy = dir.s[k];
        // p + t d = a + s e: t = cross(a, e) / cross(d, e), s = cross(a, d) / cross(d, e).
        const double den = dx * ey[i] - dy * ex[i];
        if (std::fabs(den) < 1e-300) continue;
        const double t = (ax[i] * ey[i] - ay[i] * ex[i]) / den;
        const double s = (ax[i] * dy - ay[i] * dx) / den;
        if (t >= 0.0 && s >= 0.0 && s <= 1.0) rho[k] = std::min(rho[k], t);
      }
    }
  }
};

}  // namespace

template <class Skip, class Visit>
void BoundaryIndex::scan(uint32_t triangle, Skip&& skip, Visit&& visit) const {
  const uint32_t begin = start_[triangle], end = start_[triangle + 1];
  for (uint32_t k = begin; k < end; ++k) {
    const uint32_t at = k - begin;
    if (at % (kGroup * kGroup) == 0 &&
        skip(groups_[1][group_start_[1][triangle] + at / (kGroup * kGroup)])) {
      k += kGroup * kGroup - 1;  // the run's last entry; the loop's ++k starts the next run
      continue;
    }
    if (at % kGroup == 0 && skip(groups_[0][group_start_[0][triangle] + at / kGroup])) {
      k += kGroup - 1;
      continue;
    }
    if (!visit(segments_[list_[k]])) return;
  }
}

float BoundaryIndex::clearance(uint32_t triangle, const vec3& p, float r) const {
  if (start_.empty()) return r;
  if (!first_copy_.empty()) triangle = first_copy_[triangle];  // copies share its list
  double nearest = double(r) * double(r);
  // A run whose bounding sphere is farther than the nearest segment so far holds none nearer
  // (with a 1e-4 relative margin for float rounding).
  scan(
      triangle,
      [&](const Group& g) {
        const float d = glm::length(p - g.centre) - g.radius;
        return d > 0.0f && double(d) * double(d) > nearest * 1.0002;
      },
      [&](const Segment& s) {
        nearest = std::min(nearest, segment_distance2(p, s.a, s.b));
        return true;
      });
  if (nearest >= double(r) * double(r)) return r;
  // Rounded down, so that a radius at or below it squares to less than every segment's
  // distance squared, as moments() tests.
  return std::nextafter(float(std::sqrt(nearest)), 0.0f) * (1.0f - 1e-6f);
}

DiscMoments BoundaryIndex::moments(uint32_t triangle, const vec3& p, const vec3& n, float r) const {
  DiscMoments m;
  if (start_.empty()) return m;
  if (!first_copy_.empty()) triangle = first_copy_[triangle];
  // The segments within r of p, projected into p's tangent plane.
  Projected near;
  const double r2 = double(r) * double(r);
  vec3 t1, t2;
  orthonormal_basis(n, t1, t2);
  // Beyond radius + r from a bounding sphere's centre nothing inside it is within r (a 1e-4
  // relative margin covers float rounding; the exact distance decides the rest).
  const auto far = [&](const vec3& c, float radius) {
    const vec3 d = p - c;
    const float reach = (radius + r) * 1.0001f;
    return glm::dot(d, d) > reach * reach;
  };
  scan(
      triangle, [&](const Group& g) { return far(g.centre, g.radius); },
      [&](const Segment& s) {
        if (far(s.mid, s.half) || segment_distance2(p, s.a, s.b) >= r2) return true;
        const dvec3 a = dvec3(s.a) - dvec3(p), b = dvec3(s.b) - dvec3(p);
        const int i = near.count;
        near.ax[i] = glm::dot(a, dvec3(t1));
        near.ay[i] = glm::dot(a, dvec3(t2));
        near.ex[i] = glm::dot(b, dvec3(t1)) - near.ax[i];
        near.ey[i] = glm::dot(b, dvec3(t2)) - near.ay[i];
        return ++near.count < Projected::kMaxNear;
      });
  if (near.count == 0) return m;
  // A point on a segment (a pixel centre that sees exactly the line where two walls meet) sees
  // nothing along it: every ray meets the segment at t = 0. Such a point belongs to the side of
  // its own triangle, so the quadrature's centre moves 1e-3 r towards that triangle's centre;
  // the moments change by O(1e-3) (the disc's part beyond the segment is then about half).
  if (near.through_centre(r2)) {
    const dvec3 toward = dvec3(centre_[triangle]) - dvec3(p);
    near.shift(glm::dot(toward, dvec3(t1)), glm::dot(toward, dvec3(t2)), r);
  }
  double rho[kK];
  near.visible_extents(double(r), rho);
  return kernel::polar_moments(rho, kK, double(r));
}

}  // namespace pb
