// Uniform sampling of the solid angle a triangle subtends (lights.h), for next-event estimation
// near area lights.
#include "lights/lights.h"

#include <algorithm>
#include <cmath>

namespace pb {

bool sample_spherical_triangle(const vec3& v0, const vec3& v1, const vec3& v2, const vec3& p,
                               float u0, float u1, vec3& dir, float& solid_angle) {
  // Arvo 1995, "Stratified sampling of spherical triangles", in the form of pbrt-v4's
  // SampleSphericalTriangle, in double: the arcs and angles lose float precision quickly. The
  // solid angle is Van Oosterom & Strackee's (1983) for unit vectors,
  //   tan(omega / 2) = |a.(b x c)| / (1 + a.b + b.c + c.a),
  // one atan2 where the spherical excess alpha + beta + gamma - pi needs three acos and loses
  // the small triangle's area to cancellation against pi; the angle alpha at a enters only
  // through its cosine and sine, the dot and cross of the two great circles' unit normals.
  using glm::dvec3;
  const dvec3 a = glm::normalize(dvec3(v0) - dvec3(p));
  const dvec3 b = glm::normalize(dvec3(v1) - dvec3(p));
  const dvec3 c = glm::normalize(dvec3(v2) - dvec3(p));
  dvec3 n_ab = glm::cross(a, b), n_ca = glm::cross(c, a);
  const dvec3 n_bc = glm::cross(b, c);
  const double l_ab = glm::length(n_ab), l_ca = glm::length(n_ca);
  if (!(l_ab > 1e-12 && glm::dot(n_bc, n_bc) > 1e-24 && l_ca > 1e-12)) return false;
  n_ab /= l_ab;
  n_ca /= l_ca;
  const double area =  // the solid angle, in [0, 2 pi]
      2.0 * std::atan2(std::fabs(glm::dot(a, n_bc)),
                       1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a));
  // Below this the triangle is too small to sample by its arcs; above 2 pi - eps the receiver
  // is almost in the triangle's plane. Both fall back to area sampling.
  if (!(area > 3e-4 && area < 6.22)) return false;
  const double cos_alpha = std::clamp(glm::dot(n_ab, -n_ca), -1.0, 1.0);
  const double sin_alpha = glm::length(glm::cross(n_ab, n_ca));

  // Choose the sub-triangle area A' uniformly, then the point on arc b-c' for it.
  // Arvo's phi = A' + pi - alpha, through sin(A' + pi) = -sin A' and cos(A' + pi) = -cos A'.
  const double sub = double(u0) * area;  // A'
  const double sin_ap = -std::sin(sub), cos_ap = -std::cos(sub);
  const double sin_phi = sin_ap * cos_alpha - cos_ap * sin_alpha;
  const double cos_phi = cos_ap * cos_alpha + sin_ap * sin_alpha;
  const double k1 = cos_phi + cos_alpha;
  const double k2 = sin_phi - sin_alpha * glm::dot(a, b);
  double cos_bp = (k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) /
                  ((k2 * sin_phi + k1 * cos_phi) * sin_alpha);
  cos_bp = std::clamp(cos_bp, -1.0, 1.0);
  const double sin_bp = std::sqrt(std::max(0.0, 1.0 - cos_bp * cos_bp));
  const dvec3 c_perp = c - glm::dot(c, a) * a;
  if (!(glm::length(c_perp) > 0.0)) return false;
  const dvec3 cp = cos_bp * a + sin_bp * glm::normalize(c_perp);
  const double cos_theta = 1.0 - double(u1) * (1.0 - glm::dot(cp, b));
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  const dvec3 cp_perp = cp - glm::dot(cp, b) * b;
  const double l = glm::length(cp_perp);
  const dvec3 w = l > 0.0 ? cos_theta * b + sin_theta * (cp_perp / l) : b;
  dir = vec3(glm::normalize(w));
  solid_angle = float(area);
  return std::isfinite(dir.x) && std::isfinite(dir.y) && std::isfinite(dir.z);
}

}  // namespace pb
