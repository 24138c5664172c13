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

// The polar quadrature of moments() (ESTIMATOR.md section 11) on a region's segments.

// The distance squared from the centre to segment q.
double distance2(const RegionSegment& q) {
  const double len2 = q.ex * q.ex + q.ey * q.ey;
  const double s = len2 > 0.0 ? std::clamp(-(q.ax * q.ex + q.ay * q.ey) / len2, 0.0, 1.0) : 0.0;
  const double qx = q.ax + s * q.ex, qy = q.ay + s * q.ey;
  return qx * qx + qy * qy;
}

// The distance squared from the centre to the nearest segment.
double nearest2(const DiscRegion& g) {
  double min_d2 = INFINITY;
  for (int i = 0; i < g.count; ++i) min_d2 = std::min(min_d2, distance2(g.seg[i]));
  return min_d2;
}

// Moves the centre 1e-3 r (at most the distance) towards (cx, cy).
void shift(DiscRegion& g, double cx, double cy, float r) {
  const double len = std::sqrt(cx * cx + cy * cy);
  if (!(len > 0.0)) return;
  const double shift = std::min(1e-3 * double(r), len);
  g.frame.sx = shift * cx / len;
  g.frame.sy = shift * cy / len;
  for (int i = 0; i < g.count; ++i) {
    g.seg[i].ax -= g.frame.sx;
    g.seg[i].ay -= g.frame.sy;
  }
}

// In each direction of the quadrature the visible extent rho (the first segment the ray meets,
// or r). A segment not through the centre subtends less than pi, so only the directions within
// the arc between its end points' angles (one more each side, for rounding) can meet it; the
// exact test decides.
void visible_extents(const DiscRegion& g, double r, double rho[kK]) {
  const Directions& dir = directions();
  std::fill(rho, rho + kK, r);
  constexpr double step = 2.0 * kPiD / kK;
  for (int i = 0; i < g.count; ++i) {
    const double ax = g.seg[i].ax, ay = g.seg[i].ay, ex = g.seg[i].ex, ey = g.seg[i].ey;
    const double ta = std::atan2(ay, ax), tb = std::atan2(ay + ey, ax + ex);
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
      const double den = dx * ey - dy * ex;
      if (std::fabs(den) < 1e-300) continue;
      const double t = (ax * ey - ay * ex) / den;
      const double s = (ax * dy - ay * dx) / den;
      if (t >= 0.0 && s >= 0.0 && s <= 1.0) rho[k] = std::min(rho[k], t);
    }
  }
}

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

bool BoundaryIndex::region(uint32_t triangle, const vec3& p, const vec3& n, float r,
                           DiscRegion& out) const {
  out.count = 0;
  if (start_.empty()) return false;
  if (!first_copy_.empty()) triangle = first_copy_[triangle];
  // The segments within r of p, projected into p's tangent plane.
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
  // Past kMaxNear the nearest are kept (by their distance in space, held in d2 until the plane's
  // replaces it below), so that which segments count does not depend on the lists' order (a
  // floor under a tessellated sphere lists hundreds of short cuts of its foot).
  int farthest = -1;  // once full: the kept segment farthest from p
  scan(
      triangle, [&](const Group& g) { return far(g.centre, g.radius); },
      [&](const Segment& s) {
        if (far(s.mid, s.half)) return true;
        const double d2 = segment_distance2(p, s.a, s.b);
        if (d2 >= r2) return true;
        int i = out.count;
        if (i == DiscRegion::kMaxNear) {
          if (d2 >= out.seg[farthest].d2) return true;
          i = farthest;
        } else {
          ++out.count;
        }
        const dvec3 a = dvec3(s.a) - dvec3(p), b = dvec3(s.b) - dvec3(p);
        RegionSegment& q = out.seg[i];
        q.ax = glm::dot(a, dvec3(t1));
        q.ay = glm::dot(a, dvec3(t2));
        q.ex = glm::dot(b, dvec3(t1)) - q.ax;
        q.ey = glm::dot(b, dvec3(t2)) - q.ay;
        q.d2 = d2;
        if (out.count == DiscRegion::kMaxNear) {
          farthest = 0;
          for (int j = 1; j < out.count; ++j)
            if (out.seg[j].d2 > out.seg[farthest].d2) farthest = j;
        }
        return true;
      });
  if (out.count == 0) return false;
  out.frame = RegionView{};
  out.frame.t1 = dvec3(t1);
  out.frame.t2 = dvec3(t2);
  // A point on a segment (a pixel centre that sees exactly the line where two walls meet) sees
  // nothing along it: every ray meets the segment at t = 0. Such a point belongs to the side of
  // its own triangle, so the quadrature's centre moves 1e-3 r towards that triangle's centre;
  // the moments change by O(1e-3) (the disc's part beyond the segment is then about half).
  if (nearest2(out) < 1e-8 * r2) {
    const dvec3 toward = dvec3(centre_[triangle]) - dvec3(p);
    shift(out, glm::dot(toward, out.frame.t1), glm::dot(toward, out.frame.t2), r);
  }
  // Nearest first, each with its distance: a photon's chord reaches only the segments nearer
  // than the photon (RegionView::contains).
  for (int i = 0; i < out.count; ++i) out.seg[i].d2 = distance2(out.seg[i]);
  std::sort(out.seg, out.seg + out.count,
            [](const RegionSegment& a, const RegionSegment& b) { return a.d2 < b.d2; });
  return true;
}

DiscMoments BoundaryIndex::moments(uint32_t triangle, const vec3& p, const vec3& n, float r) const {
  DiscRegion region;
  if (!this->region(triangle, p, n, r, region)) return DiscMoments{};
  return moments_of(region, r);
}

DiscMoments BoundaryIndex::moments_of(const DiscRegion& region, float r) {
  double rho[kK];
  visible_extents(region, double(r), rho);
  return kernel::polar_moments(rho, kK, double(r));
}

bool RegionView::contains(const vec3& d) const {
  const dvec3 dd(d);
  const double ux = glm::dot(dd, t1) - sx, uy = glm::dot(dd, t2) - sy;
  const double u2 = ux * ux + uy * uy;
  // The chord from the centre to u crosses segment i where t u = a + s e with t, s in [0, 1]:
  // t = cross(a, e) / cross(u, e), s = cross(a, u) / cross(u, e). Every point of the chord is
  // within |u| of the centre, so the segments farther than that (the rest, nearest first) cannot.
  for (int i = 0; i < count; ++i) {
    const RegionSegment& q = seg[i];
    if (q.d2 > u2) break;
    const double den = ux * q.ey - uy * q.ex;
    if (den == 0.0) continue;  // parallel: it cannot cut the chord
    const double t = (q.ax * q.ey - q.ay * q.ex) / den;
    const double s = (q.ax * uy - q.ay * ux) / den;
    if (t >= 0.0 && t <= 1.0 && s >= 0.0 && s <= 1.0) return false;
  }
  return true;
}

void RegionTable::add(uint32_t point, const DiscRegion& region) {
  Head h;
  h.point = point;
  h.first = uint32_t(segments_.size());
  h.frame = region.frame;
  h.frame.seg = nullptr;
  h.frame.count = region.count;
  segments_.insert(segments_.end(), region.seg, region.seg + region.count);
  heads_.push_back(h);
}

const RegionView* RegionTable::Cursor::at(uint32_t k) {
  if (!t_) return nullptr;
  while (next_ < t_->heads_.size() && t_->heads_[next_].point < k) ++next_;
  if (next_ == t_->heads_.size() || t_->heads_[next_].point != k) return nullptr;
  const Head& h = t_->heads_[next_];
  view_ = h.frame;
  view_.seg = t_->segments_.data() + h.first;
  return &view_;
}

}  // namespace pb
