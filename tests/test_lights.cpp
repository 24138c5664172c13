// Light sampling: spherical-triangle directions and next-event estimates against exact answers.
#include "photonbound/lights.h"
#include "photonbound/rng.h"

#include <gtest/gtest.h>

namespace pb {
namespace {

// Moller-Trumbore: does the ray p + t d (t > 0) hit triangle (v0, v1, v2)?
bool hits(const vec3& p, const vec3& d, const vec3& v0, const vec3& v1, const vec3& v2) {
  const glm::dvec3 e1 = glm::dvec3(v1 - v0), e2 = glm::dvec3(v2 - v0), dd(d);
  const glm::dvec3 h = glm::cross(dd, e2);
  const double det = glm::dot(e1, h);
  if (std::fabs(det) < 1e-15) return false;
  const glm::dvec3 s = glm::dvec3(p - v0);
  const double u = glm::dot(s, h) / det;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(dd, q) / det;
  const double t = glm::dot(e2, q) / det;
  const double eps = 1e-5;
  return u > -eps && v > -eps && u + v < 1 + eps && t > 0;
}

// Every sampled direction points into the triangle, and the samples are uniform in solid
// angle: the solid-angle estimate of the projected solid angle (integral of the cosine to the
// triangle's normal) agrees with an independent area-sampling estimate. 200k samples each; the
// tolerance is 4 combined standard errors.
TEST(SphericalTriangle, DirectionsHitTheTriangleUniformlyInSolidAngle) {
  const vec3 tris[][4] = {
      {vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0), vec3(0.2f, 0.3f, 0.5f)},
      {vec3(-1, 0, -1), vec3(1, 0, -1), vec3(0, 0, 1), vec3(0.1f, 0.05f, 0.0f)},  // close
      {vec3(0, 0, 0), vec3(3, 0, 0), vec3(0, 0.2f, 0), vec3(1.5f, 0.05f, 2.0f)},  // thin
  };
  for (const auto& tri : tris) {
    const vec3 p = tri[3];
    const vec3 n = glm::normalize(glm::cross(tri[1] - tri[0], tri[2] - tri[0]));
    const int kSamples = 200000;
    double sum_sa = 0.0, sq_sa = 0.0, sum_area = 0.0, sq_area = 0.0;
    float omega = 0.0f;
    for (int i = 0; i < kSamples; ++i) {
      Rng rng(5, 0, uint64_t(i), Stream::Test);
      vec3 d;
      ASSERT_TRUE(sample_spherical_triangle(tri[0], tri[1], tri[2], p, rng.next_float(),
                                            rng.next_float(), d, omega));
      ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
      ASSERT_TRUE(hits(p, d, tri[0], tri[1], tri[2])) << i;
      const double f = std::fabs(glm::dot(d, n)) * omega;
      sum_sa += f;
      sq_sa += f * f;
      // Area sampling of the same integral: |cos_l| A / d^2 ... times |cos to n| = cos_l.
      const float s = std::sqrt(rng.next_float()), u2 = rng.next_float();
      const vec3 y = tri[0] + (1 - s) * (tri[1] - tri[0]) + u2 * s * (tri[2] - tri[0]);
      const vec3 w = y - p;
      const double d2 = glm::dot(w, w);
      const double cos_l = std::fabs(glm::dot(glm::normalize(w), n));
      const double area = 0.5 * glm::length(glm::cross(tri[1] - tri[0], tri[2] - tri[0]));
      const double g = cos_l * cos_l * area / d2;
      sum_area += g;
      sq_area += g * g;
    }
    const double n_ = kSamples;
    const double m1 = sum_sa / n_, m2 = sum_area / n_;
    const double se = std::sqrt((sq_sa / n_ - m1 * m1) / n_ + (sq_area / n_ - m2 * m2) / n_);
    EXPECT_NEAR(m1, m2, 4.0 * se) << "triangle at " << p.x << "," << p.y << "," << p.z;
  }
}

TEST(SphericalTriangle, RefusesDegenerateAndTinySolidAngles) {
  vec3 d;
  float omega;
  // Receiver in the triangle's plane, and a triangle seen edge-on from far away.
  EXPECT_FALSE(sample_spherical_triangle(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0), vec3(2, 2, 0),
                                         0.5f, 0.5f, d, omega));
  EXPECT_FALSE(sample_spherical_triangle(vec3(0, 0, 0), vec3(1e-3f, 0, 0), vec3(0, 1e-3f, 0),
                                         vec3(0, 0, 100), 0.5f, 0.5f, d, omega));
}

}  // namespace
}  // namespace pb
