// The reflection models of bsdf.h against textbook formulas written out independently here
// (Fresnel, Snell), Monte Carlo moments of the samplers with 4-standard-error tolerances, and
// the deterministic specular branches of mirrors and dielectrics.
#include "bsdf/bsdf.h"
#include "scene/scene.h"
#include "util/rng.h"
#include "world/surface.h"

#include "bsdf_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

namespace pb {
namespace {

using test::random_unit;

constexpr double kPi_ = std::numbers::pi;

// Fresnel's equations for unpolarised light, in double, from the refractive indices n1 (incident
// side) and n2, with Snell's law n1 sin_i = n2 sin_t (Hecht, Optics, section 4.6).
double fresnel_reference(double cos_i, double n1, double n2) {
  const double sin_i = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
  const double sin_t = n1 * sin_i / n2;
  if (sin_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
  const double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

vec3 unit(float x, float y, float z) { return glm::normalize(vec3(x, y, z)); }

// Mean and standard error of a sample.
struct Moments {
  double n = 0, sum = 0, sum2 = 0;
  void add(double x) {
    n += 1;
    sum += x;
    sum2 += x * x;
  }
  double mean() const { return sum / n; }
  double stderr_() const {
    const double m = mean();
    return std::sqrt(std::max(0.0, sum2 / n - m * m) / (n - 1));
  }
};

// ---------------------------------------------------------------------------------------------
// Fresnel

TEST(Fresnel, NormalIncidence) {
  // ((eta - 1)/(eta + 1))^2 = 0.04 for both 1.5 and 1/1.5; float evaluation: 1e-6.
  for (float eta : {1.5f, 1.0f / 1.5f, 1.33f, 2.4f}) {
    const double r = (double(eta) - 1.0) / (double(eta) + 1.0);
    EXPECT_NEAR(fresnel_dielectric(1.0f, eta), r * r, 1e-6) << "eta=" << eta;
  }
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.5f), 0.04, 1e-6);
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f / 1.5f), 0.04, 1e-6);
  // Index-matched: no reflection at any angle.
  for (float c : {0.1f, 0.5f, 0.9f}) EXPECT_NEAR(fresnel_dielectric(c, 1.0f), 0.0, 1e-7);
}

TEST(Fresnel, TotalInternalReflectionBeyondCriticalAngle) {
  // Dense to less dense, eta = 1/1.5: critical angle asin(2/3) = 41.81 degrees.
  const float eta = 1.0f / 1.5f;
  const double theta_c = std::asin(double(eta));
  for (int k = 0; k <= 200; ++k) {
    const double th = theta_c + 1e-3 + (kPi_ / 2 - theta_c - 1e-3) * k / 200.0;
    EXPECT_EQ(fresnel_dielectric(float(std::cos(th)), eta), 1.0f) << "theta=" << th;
  }
  EXPECT_EQ(fresnel_dielectric(0.0f, eta), 1.0f);
  // Just inside the critical angle reflection is strong but partial.
  const float below = fresnel_dielectric(float(std::cos(theta_c - 0.02)), eta);
  EXPECT_LT(below, 1.0f);
  EXPECT_GT(below, 0.3f);
  // Rare to dense never totally reflects before grazing.
  EXPECT_LT(fresnel_dielectric(0.01f, 1.5f), 1.0f);
}

TEST(Fresnel, InUnitIntervalEverywhere) {
  for (float eta : {1.0f / 2.4f, 1.0f / 1.5f, 0.95f, 1.0f, 1.05f, 1.5f, 2.4f}) {
    for (int k = -10; k <= 1010; ++k) {
      const float c = float(k) / 1000.0f;  // includes slightly out-of-range cosines
      const float f = fresnel_dielectric(c, eta);
      EXPECT_GE(f, 0.0f) << "cos=" << c << " eta=" << eta;
      EXPECT_LE(f, 1.0f) << "cos=" << c << " eta=" << eta;
      EXPECT_TRUE(std::isfinite(f));
    }
  }
}

TEST(Fresnel, MatchesTextbookFresnelEquations) {
  // Sweep 0..89.75 degrees in 0.25-degree steps for several interfaces (one step lands 0.004
  // degrees from the critical angle of 1.33 -> 1). The reference is evaluated in double at the
  // same float cosine. Float rounding of sin2_t (~1.2e-7) is amplified by 1/(2 cos_t) through
  // the square root, so the tolerance is 2e-6 + 1e-6 / cos_t (cos_t of the reference); the
  // largest err * cos_t measured over a 0.0025-degree sweep is 3.7e-7. Beyond the critical angle
  // both must be exactly 1.
  for (double n2 : {1.5, 1.33, 2.4}) {
    for (int flip = 0; flip < 2; ++flip) {
      const double n1 = flip ? n2 : 1.0;
      const double nt = flip ? 1.0 : n2;
      const float eta = float(nt / n1);
      for (int k = 0; k < 360; ++k) {
        const double th = k * 0.25 * kPi_ / 180.0;
        const float c = float(std::cos(th));
        const double ref = fresnel_reference(double(c), n1, nt);
        const double sin_t = n1 * std::sqrt(1.0 - double(c) * c) / nt;
        if (sin_t >= 1.0) {
          EXPECT_EQ(fresnel_dielectric(c, eta), 1.0f) << "theta=" << k * 0.25;
          continue;
        }
        const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
        EXPECT_NEAR(fresnel_dielectric(c, eta), ref, 2e-6 + 1e-6 / cos_t)
            << "theta=" << k * 0.25 << " n1=" << n1 << " n2=" << nt;
      }
    }
  }
  // Brewster's angle (rare to dense, n = 1.5): the p-component vanishes, so R = rs^2 / 2.
  const double thb = std::atan(1.5);
  const double cb = std::cos(thb), sb = std::sin(thb);
  const double ct = std::sqrt(1.0 - sb * sb / 2.25);
  const double rs = (cb - 1.5 * ct) / (cb + 1.5 * ct);
  EXPECT_NEAR(fresnel_dielectric(float(cb), 1.5f), 0.5 * rs * rs, 1e-6);
}

TEST(Fresnel, SameReflectanceFromBothSides) {
  // Stokes relations: R(theta_i, eta) = R(theta_t, 1/eta) with sin_t = sin_i / eta. Both sides
  // in float; the dense-side evaluation is close to its critical angle when theta_i is grazing,
  // so (as in the textbook sweep) rounding is amplified by 1/cos_i: tolerance
  // 2e-6 + 4e-6 / cos_i; the largest err * cos_i measured over a 0.01-degree sweep is 1.3e-6.
  for (float eta : {1.5f, 1.33f, 2.4f}) {
    for (int k = 0; k <= 178; ++k) {
      const double th = k * 0.5 * kPi_ / 180.0;
      const double sin_t = std::sin(th) / eta;
      const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
      const float a = fresnel_dielectric(float(std::cos(th)), eta);
      const float b = fresnel_dielectric(float(cos_t), 1.0f / eta);
      EXPECT_NEAR(a, b, 2e-6 + 4e-6 / std::cos(th)) << "theta=" << k * 0.5 << " eta=" << eta;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Refraction

TEST(Refract, SnellsLawUnitLengthAndOtherSide) {
  // Float geometry: sin and length to 1e-5.
  Rng rng(101, 0, 0, Stream::Test);
  for (float eta : {1.5f, 1.0f / 1.5f, 1.33f, 2.4f}) {
    for (int k = 0; k < 500; ++k) {
      const vec3 n = random_unit(rng);
      vec3 w = random_unit(rng);
      if (glm::dot(w, n) < 0.0f) w = -w;
      const float cos_i = glm::dot(w, n);
      if (cos_i < 1e-3f) continue;
      const float sin_i = std::sqrt(std::max(0.0f, 1.0f - cos_i * cos_i));
      vec3 wt;
      const bool ok = refract(w, n, eta, wt);
      if (sin_i / eta >= 1.0f - 1e-5f) continue;  // TIR region is tested separately
      ASSERT_TRUE(ok) << "eta=" << eta << " sin_i=" << sin_i;
      EXPECT_NEAR(glm::length(wt), 1.0f, 1e-5f);
      EXPECT_LT(glm::dot(wt, n), 0.0f);
      const float cos_t = -glm::dot(wt, n);
      const float sin_t = glm::length(wt + cos_t * n);  // tangential component
      EXPECT_NEAR(sin_t, sin_i / eta, 1e-5f) << "eta=" << eta;
      // In the plane of incidence, tangential part opposite to w's tangential part.
      const vec3 wtan = w - cos_i * n, ttan = wt + cos_t * n;
      if (sin_i > 1e-3f) {
        EXPECT_NEAR(glm::dot(glm::normalize(wtan), glm::normalize(ttan)), -1.0f, 1e-4f);
      }
    }
  }
}

TEST(Refract, RoundTripReturnsOriginalDirection) {
  // w -> wt (eta) -> back through the same interface from the other side (normal -n, 1/eta).
  // Float: near grazing (on either side) the inverse map amplifies rounding by 1/cos, so the
  // tolerance on |back - w| is 1e-6 + 4e-6 / min(cos_i, cos_t); the largest
  // |back - w| * min(cos_i, cos_t) measured over 300k random cases is 1.2e-6. Exactly grazing
  // directions (cos_i < 0.01) are skipped: their transmitted direction sits on the critical
  // angle, where rounding alone decides whether the way back is total internal reflection.
  Rng rng(102, 0, 0, Stream::Test);
  for (float eta : {1.5f, 1.0f / 1.5f, 2.4f}) {
    int tested = 0;
    for (int k = 0; k < 500; ++k) {
      const vec3 n = random_unit(rng);
      vec3 w = random_unit(rng);
      if (glm::dot(w, n) < 0.0f) w = -w;
      if (glm::dot(w, n) < 0.01f) continue;
      vec3 wt, back;
      if (!refract(w, n, eta, wt)) continue;
      ASSERT_TRUE(refract(wt, -n, 1.0f / eta, back));
      const float m = std::min(glm::dot(w, n), -glm::dot(wt, n));
      EXPECT_LE(glm::length(back - w), 1e-6f + 4e-6f / m) << "eta=" << eta;
      ++tested;
    }
    // eta = 1/1.5 transmits only within 41.8 degrees: ~25% of the hemisphere (~125 of 500).
    EXPECT_GT(tested, 100);
  }
}

TEST(Refract, TotalInternalReflectionExactlyWhenSinExceedsEta) {
  // eta < 1: refract fails iff sin_i > eta. Angles within 1e-4 of the critical sine are skipped
  // (float rounding decides there).
  const vec3 n(0.0f, 0.0f, 1.0f);
  for (float eta : {1.0f / 1.5f, 1.0f / 2.4f, 0.9f}) {
    for (int k = 0; k <= 2000; ++k) {
      const double th = (kPi_ / 2 - 1e-4) * k / 2000.0;
      const float s = float(std::sin(th));
      if (std::fabs(s - eta) < 1e-4f) continue;
      const vec3 w(s, 0.0f, float(std::cos(th)));
      vec3 wt;
      EXPECT_EQ(refract(w, n, eta, wt), !(s > eta)) << "eta=" << eta << " sin=" << s;
    }
  }
  // eta > 1 never totally reflects.
  for (int k = 0; k <= 100; ++k) {
    const double th = (kPi_ / 2 - 1e-3) * k / 100.0;
    vec3 wt;
    EXPECT_TRUE(refract(vec3(float(std::sin(th)), 0.0f, float(std::cos(th))), n, 1.5f, wt));
  }
}

// ---------------------------------------------------------------------------------------------
// Lambertian and samplers

TEST(Lambertian, EnergyEqualsAlbedo) {
  // int f cos dw over the hemisphere = rho, by uniform hemisphere sampling (pdf 1/(2 pi)):
  // estimator 2 pi f cos. 200k samples, tolerance 4 standard errors (computed from the sample).
  const vec3 rho(0.2f, 0.5f, 0.9f);
  const vec3 f = lambertian(rho);
  Moments m[3];
  for (int k = 0; k < 200000; ++k) {
    Rng rng(103, 0, uint64_t(k), Stream::Test);
    const double cos_t = rng.next_double();  // uniform hemisphere: cos uniform in [0, 1)
    for (int c = 0; c < 3; ++c) m[c].add(2.0 * kPi_ * double(f[c]) * cos_t);
  }
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(m[c].mean(), rho[c], 4.0 * m[c].stderr_()) << "channel " << c;
    EXPECT_NEAR(double(f[c]), rho[c] / kPi_, 1e-7);
  }
}

TEST(Samplers, CosineHemisphereMoments) {
  // pdf cos/pi: E[cos] = 2/3, E[cos^2] = 1/2, E[tangential components] = 0. 200k samples per
  // normal, 4 standard errors. Includes the poles and near-pole normals where orthonormal bases
  // are fragile.
  const std::vector<vec3> normals = {
      vec3(0, 0, 1),         vec3(0, 0, -1),          unit(1e-7f, 0, -1), unit(0, 1e-4f, -1),
      unit(1e-4f, 1e-4f, 1), unit(0.3f, -0.5f, 0.8f), unit(1, 0, 0),      unit(-0.2f, 0.9f, -0.1f)};
  for (size_t ni = 0; ni < normals.size(); ++ni) {
    const vec3 n = normals[ni];
    vec3 t, b;
    orthonormal_basis(n, t, b);
    Moments mc, mc2, mt, mb;
    for (int k = 0; k < 200000; ++k) {
      Rng rng(104, ni, uint64_t(k), Stream::Test);
      const float u1 = rng.next_float(), u2 = rng.next_float();
      const vec3 d = sample_cosine_hemisphere(n, u1, u2);
      ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
      const float c = glm::dot(d, n);
      ASSERT_GE(c, -1e-6f) << "below the hemisphere, normal " << ni;
      mc.add(c);
      mc2.add(double(c) * c);
      // Tangential components in a basis built here from an independent cross product.
      const vec3 a = std::fabs(n.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 1, 0);
      const vec3 t2 = glm::normalize(glm::cross(n, a)), b2 = glm::cross(n, t2);
      mt.add(glm::dot(d, t2));
      mb.add(glm::dot(d, b2));
    }
    EXPECT_NEAR(mc.mean(), 2.0 / 3.0, 4.0 * mc.stderr_()) << "normal " << ni;
    EXPECT_NEAR(mc2.mean(), 0.5, 4.0 * mc2.stderr_()) << "normal " << ni;
    EXPECT_NEAR(mt.mean(), 0.0, 4.0 * mt.stderr_()) << "normal " << ni;
    EXPECT_NEAR(mb.mean(), 0.0, 4.0 * mb.stderr_()) << "normal " << ni;
  }
}

TEST(Samplers, UniformSphereMoments) {
  // Unit length; E[x] = E[y] = E[z] = 0, E[z^2] = E[x^2] = 1/3; 200k samples, 4 standard errors.
  Moments mx, my, mz, mz2, mx2;
  for (int k = 0; k < 200000; ++k) {
    Rng rng(105, 0, uint64_t(k), Stream::Test);
    const vec3 d = sample_uniform_sphere(rng.next_float(), rng.next_float());
    ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
    mx.add(d.x);
    my.add(d.y);
    mz.add(d.z);
    mz2.add(double(d.z) * d.z);
    mx2.add(double(d.x) * d.x);
  }
  EXPECT_NEAR(mx.mean(), 0.0, 4.0 * mx.stderr_());
  EXPECT_NEAR(my.mean(), 0.0, 4.0 * my.stderr_());
  EXPECT_NEAR(mz.mean(), 0.0, 4.0 * mz.stderr_());
  EXPECT_NEAR(mz2.mean(), 1.0 / 3.0, 4.0 * mz2.stderr_());
  EXPECT_NEAR(mx2.mean(), 1.0 / 3.0, 4.0 * mx2.stderr_());
}

TEST(Samplers, UniformConeStaysInsideAndHasRightMeanCosine) {
  // Uniform in solid angle within the cone: cos uniform on [cos_max, 1], E[cos] = (1+cos_max)/2;
  // every direction inside (dot >= cos_max - 1e-6). 100k samples per case, 4 standard errors.
  const std::vector<vec3> axes = {vec3(0, 0, 1), vec3(0, 0, -1), unit(0.5f, -0.5f, 0.7f),
                                  unit(1e-6f, 0, -1)};
  int case_id = 0;
  for (const vec3& axis : axes) {
    for (float cos_max : {0.999f, 0.9f, 0.5f, 0.0f, -0.5f}) {
      Moments mc;
      for (int k = 0; k < 100000; ++k) {
        Rng rng(106, uint64_t(case_id), uint64_t(k), Stream::Test);
        const vec3 d = sample_uniform_cone(axis, cos_max, rng.next_float(), rng.next_float());
        ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
        const float c = glm::dot(d, axis);
        ASSERT_GE(c, cos_max - 1e-6f) << "outside the cone, cos_max " << cos_max;
        mc.add(c);
      }
      EXPECT_NEAR(mc.mean(), (1.0 + cos_max) / 2.0, 4.0 * mc.stderr_() + 1e-7)
          << "cos_max " << cos_max;
      ++case_id;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Shading normals

TEST(ShadingNormals, AdjointFactorIsOneWithoutShadingNormal) {
  Rng rng(107, 0, 0, Stream::Test);
  for (int k = 0; k < 1000; ++k) {
    const vec3 n = random_unit(rng), wo = random_unit(rng), wi = random_unit(rng);
    if (std::fabs(glm::dot(wo, n)) < 1e-3f || std::fabs(glm::dot(wi, n)) < 1e-3f) continue;
    EXPECT_NEAR(adjoint_shading_factor(wo, wi, n, n), 1.0f, 1e-5f);
  }
}

TEST(ShadingNormals, AdjointFactorIsRatioOfProjections) {
  // Veach eq. 5.19 factors as g(wo)/g(wi) with g(w) = |w.ns|/|w.ng|. Properties that fail if the
  // roles of wo and wi or ns and ng are confused: (1) factor * g(wi) is independent of wi;
  // (2) factor(wo,wi) * factor(wi,wo) = 1; (3) a hand-computed case. Float: 1e-4 relative
  // (directions are kept >= 0.05 away from grazing so the ratios are well conditioned).
  Rng rng(108, 0, 0, Stream::Test);
  const vec3 ng(0, 0, 1);
  int tested = 0;
  for (int k = 0; k < 2000; ++k) {
    const vec3 ns = glm::normalize(ng + 0.6f * random_unit(rng));
    const vec3 wo = random_unit(rng), wi = random_unit(rng), wi2 = random_unit(rng);
    auto ok = [&](const vec3& w) {
      return std::fabs(glm::dot(w, ng)) > 0.05f && std::fabs(glm::dot(w, ns)) > 0.05f;
    };
    if (!ok(wo) || !ok(wi) || !ok(wi2)) continue;
    auto g = [&](const vec3& w) { return std::fabs(glm::dot(w, ns)) / std::fabs(glm::dot(w, ng)); };
    const float f1 = adjoint_shading_factor(wo, wi, ng, ns);
    const float f2 = adjoint_shading_factor(wo, wi2, ng, ns);
    EXPECT_NEAR(f1 * g(wi), g(wo), 1e-4f * g(wo));
    EXPECT_NEAR(f1 * g(wi), f2 * g(wi2), 1e-4f * g(wo));
    EXPECT_NEAR(f1 * adjoint_shading_factor(wi, wo, ng, ns), 1.0f, 1e-4f);
    // Independent of which side the normals are given on.
    EXPECT_NEAR(adjoint_shading_factor(wo, wi, -ng, -ns), f1, 1e-5f * f1);
    ++tested;
  }
  EXPECT_GT(tested, 300);
  // Hand-computed: ns tilted by 30 degrees; wo along ns, wi along ng:
  // |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|) = 1 * 1 / (cos30 * cos30) = 4/3.
  const vec3 ns30(0.5f, 0.0f, std::sqrt(3.0f) / 2.0f);
  EXPECT_NEAR(adjoint_shading_factor(ns30, ng, ng, ns30), 4.0f / 3.0f, 1e-5f);
  EXPECT_NEAR(adjoint_shading_factor(ng, ns30, ng, ns30), 3.0f / 4.0f, 1e-5f);
  // Degenerate: wo in the geometric tangent plane gives 0 rather than inf/nan.
  EXPECT_EQ(adjoint_shading_factor(vec3(1, 0, 0), ng, ng, ng), 0.0f);
}

// ---------------------------------------------------------------------------------------------
// Specular branches

// The three plain glTF materials these tests exercise: Lambertian (metallic 0, specular 0),
// a smooth metal (a mirror) and smooth glass bounding a volume.
enum class Model { Lambertian, Mirror, Dielectric };

Material make_material(Model model, vec3 color, float ior = 1.5f) {
  Material m = model == Model::Lambertian ? Material::lambertian(color)
               : model == Model::Mirror   ? Material::metal(color, 0.0f)
                                          : Material::glass(ior);
  m.base_color = color;
  return m;
}

Surface make_surface(const Material& m, vec3 ng, vec3 ns) {
  Surface s;
  s.ng = ng;
  s.ns = ns;
  s.material = &m;
  s.bsdf = Bsdf(m, ng, ns);
  return s;
}

void expect_mirror_image(const vec3& wo, const vec3& r, const vec3& n, const char* what) {
  // Angle in = angle out about n and in the plane of incidence: r + wo is parallel to n.
  EXPECT_NEAR(glm::dot(r, n), glm::dot(wo, n), 1e-5f) << what;
  const vec3 s = r + wo;
  EXPECT_NEAR(glm::length(glm::cross(s, n)), 0.0f, 1e-5f) << what;
  EXPECT_NEAR(glm::length(r), 1.0f, 1e-5f) << what;
}

TEST(SpecularBranches, MirrorReflectsWithSchlicksFresnelOfBaseColor) {
  // glTF appendix B's metal at h = n: F = base + (1 - base) (1 - cos)^5, base colour at normal
  // incidence, white at grazing. Float: 1e-6.
  const Material m = make_material(Model::Mirror, vec3(0.9f, 0.6f, 0.3f));
  const vec3 n(0, 0, 1);
  const Surface s = make_surface(m, n, n);
  for (const vec3& wo : {unit(0.3f, 0.2f, 0.9f), unit(-0.9f, 0.1f, 0.1f), vec3(0, 0, 1)}) {
    for (Transport mode : {Transport::Radiance, Transport::Importance}) {
      SpecularBranch br[kMaxDeltaBranches];
      ASSERT_EQ(s.bsdf.delta_branches(wo, mode, br), 1);
      const double w5 = std::pow(1.0 - double(wo.z), 5.0);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(br[0].weight[c], m.base_color[c] + (1.0 - m.base_color[c]) * w5, 1e-6);
      expect_mirror_image(wo, br[0].dir, n, "mirror");
      EXPECT_GT(glm::dot(br[0].dir, n), 0.0f);
    }
  }
  // From the back side the mirror reflects about -ng.
  SpecularBranch br[kMaxDeltaBranches];
  const vec3 wo = unit(0.2f, 0.1f, -0.8f);
  ASSERT_EQ(s.bsdf.delta_branches(wo, Transport::Radiance, br), 1);
  expect_mirror_image(wo, br[0].dir, -n, "mirror back");
  EXPECT_LT(br[0].dir.z, 0.0f);
}

TEST(SpecularBranches, DielectricFromOutsideSplitsByFresnel) {
  // Entering glass (ior 1.5) from the front: reflection with weight F and refraction with weight
  // (1-F) tint / eta^2 (radiance) or (1-F) tint (importance), eta = 1.5. F is checked against the
  // double-precision textbook reference; float: 2e-5.
  const vec3 n(0, 0, 1);
  const Material white = make_material(Model::Dielectric, vec3(1.0f), 1.5f);
  const Material tinted = make_material(Model::Dielectric, vec3(0.9f, 0.5f, 0.2f), 1.5f);
  const Surface sw = make_surface(white, n, n);
  const Surface st = make_surface(tinted, n, n);
  for (int k = 0; k < 89; ++k) {
    const double th = k * kPi_ / 180.0;
    const vec3 wo(float(std::sin(th)), 0.0f, float(std::cos(th)));
    const double F = fresnel_reference(double(wo.z), 1.0, 1.5);
    SpecularBranch imp[kMaxDeltaBranches], rad[kMaxDeltaBranches], tr[kMaxDeltaBranches];
    ASSERT_EQ(sw.bsdf.delta_branches(wo, Transport::Importance, imp), 2) << k;
    ASSERT_EQ(sw.bsdf.delta_branches(wo, Transport::Radiance, rad), 2) << k;
    ASSERT_EQ(st.bsdf.delta_branches(wo, Transport::Radiance, tr), 2) << k;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(imp[0].weight[c], F, 2e-5) << "theta=" << k;
      EXPECT_NEAR(imp[0].weight[c] + imp[1].weight[c], 1.0f, 2e-6f) << "theta=" << k;
      EXPECT_NEAR(rad[1].weight[c], (1.0 - F) / 2.25, 2e-5) << "theta=" << k;
      EXPECT_NEAR(tr[0].weight[c], F, 2e-5) << "reflection is not tinted";
      EXPECT_NEAR(tr[1].weight[c], (1.0 - F) / 2.25 * tinted.base_color[c], 2e-5);
    }
    expect_mirror_image(wo, imp[0].dir, n, "dielectric reflection");
    EXPECT_EQ(imp[0].dir, rad[0].dir);
    EXPECT_EQ(imp[1].dir, rad[1].dir);
    // Transmitted direction: below the surface and obeying Snell's law with eta = 1.5.
    EXPECT_LT(imp[1].dir.z, 0.0f);
    EXPECT_NEAR(glm::length(imp[1].dir), 1.0f, 1e-5f);
    EXPECT_NEAR(std::sqrt(1.0f - imp[1].dir.z * imp[1].dir.z), std::sin(th) / 1.5, 2e-5);
  }
}

TEST(SpecularBranches, DielectricFromInside) {
  // Leaving the glass (wo on the back side of ng): eta = 1/1.5, critical angle 41.81 degrees.
  // Beyond it exactly one branch, the mirror image about -ng, weight 1. Below it two branches
  // with the radiance transmission weight (1-F) * 1.5^2 and importance weights summing to 1.
  const vec3 n(0, 0, 1);
  const Material glass = make_material(Model::Dielectric, vec3(1.0f), 1.5f);
  const Surface s = make_surface(glass, n, n);
  const double theta_c = std::asin(1.0 / 1.5);
  for (int k = 0; k < 90; ++k) {
    const double th = k * kPi_ / 180.0;
    if (std::fabs(th - theta_c) < 1e-3) continue;
    const vec3 wo(float(std::sin(th)), 0.0f, -float(std::cos(th)));
    SpecularBranch imp[kMaxDeltaBranches], rad[kMaxDeltaBranches];
    const int ni = s.bsdf.delta_branches(wo, Transport::Importance, imp);
    const int nr = s.bsdf.delta_branches(wo, Transport::Radiance, rad);
    expect_mirror_image(wo, imp[0].dir, -n, "inside reflection");
    EXPECT_LT(imp[0].dir.z, 0.0f);
    if (th > theta_c) {
      ASSERT_EQ(ni, 1) << "theta=" << k;
      ASSERT_EQ(nr, 1) << "theta=" << k;
      EXPECT_EQ(imp[0].weight, vec3(1.0f));
      EXPECT_EQ(rad[0].weight, vec3(1.0f));
    } else {
      ASSERT_EQ(ni, 2) << "theta=" << k;
      ASSERT_EQ(nr, 2) << "theta=" << k;
      const double F = fresnel_reference(std::cos(th), 1.5, 1.0);
      EXPECT_NEAR(imp[0].weight.x, F, 2e-5) << "theta=" << k;
      EXPECT_NEAR(imp[0].weight.x + imp[1].weight.x, 1.0f, 2e-6f);
      EXPECT_NEAR(rad[1].weight.x, (1.0 - F) * 2.25, 5e-5) << "theta=" << k;
      EXPECT_GT(imp[1].dir.z, 0.0f);  // out of the glass
      EXPECT_NEAR(std::sqrt(1.0f - imp[1].dir.z * imp[1].dir.z), 1.5 * std::sin(th), 2e-5);
    }
  }
}

TEST(SpecularBranches, WhiteDielectricConservesPhotonEnergyWithShadingNormals) {
  // A smooth dielectric with a white tint is lossless: in Importance (photon) mode the branch
  // weights must sum to 1 for every geometry, shading normal or not (either both Fresnel
  // branches, or one reflection of weight 1 when no transmission is possible). Float: 1e-5.
  //
  // Deterministic case: ng = +z, ns tilted 20 degrees toward -x; the path is inside the glass
  // (wo on the back side) at 60 degrees from -ng toward +x, i.e. 40 degrees from -ns. About ns
  // that is below the critical angle (41.8 degrees), so F < 1, but the refraction about ns
  // (74.6 degrees from ns, 94.6 from +z) lands back inside, and about ng (60 > 41.8 degrees)
  // refraction is impossible: the whole energy must go into the reflection.
  const vec3 ng(0, 0, 1);
  const float phi = 20.0f * kPi / 180.0f, th = 60.0f * kPi / 180.0f;
  const vec3 ns(-std::sin(phi), 0.0f, std::cos(phi));
  const vec3 wo(std::sin(th), 0.0f, -std::cos(th));
  const Material glass = make_material(Model::Dielectric, vec3(1.0f), 1.5f);
  {
    const Surface s = make_surface(glass, ng, ns);
    SpecularBranch br[kMaxDeltaBranches];
    const int nb = s.bsdf.delta_branches(wo, Transport::Importance, br);
    float sum = br[0].weight.x;
    if (nb == 2) sum += br[1].weight.x;
    EXPECT_NEAR(sum, 1.0f, 1e-5f) << nb << " branch(es), reflection weight " << br[0].weight.x;
  }
  // Random sweep: shading normals tilted up to ~17 degrees, directions on both sides.
  Rng rng(110, 0, 0, Stream::Test);
  int bad = 0, tested = 0;
  float worst = 1.0f;
  for (int k = 0; k < 20000; ++k) {
    vec3 nsr = glm::normalize(ng + 0.3f * random_unit(rng));
    if (glm::dot(nsr, ng) < 0.0f) nsr = -nsr;
    const vec3 w = random_unit(rng);
    if (std::fabs(glm::dot(w, ng)) < 1e-3f) continue;
    const Surface s = make_surface(glass, ng, nsr);
    SpecularBranch br[kMaxDeltaBranches];
    const int nb = s.bsdf.delta_branches(w, Transport::Importance, br);
    float sum = br[0].weight.x;
    if (nb == 2) sum += br[1].weight.x;
    ++tested;
    if (std::fabs(sum - 1.0f) > 1e-5f) {
      ++bad;
      worst = std::min(worst, sum);
    }
  }
  EXPECT_EQ(bad, 0) << "of " << tested << " random configurations lose energy; worst sum " << worst;
}

TEST(SpecularBranches, TiltedShadingNormalKeepsDirectionsOnCorrectSide) {
  // ng = +z, ns tilted 30 degrees toward +x. For wo at 55 degrees toward -x, the mirror image
  // about ns points below the true surface (r.ng = 2(wo.ns)(ns.ng) - wo.ng < 0); the branch must
  // still leave on the front side. Then a random sweep over tilts and directions: reflections
  // always on wo's side of ng, refractions always on the other side, unit length.
  const vec3 ng(0, 0, 1);
  const vec3 ns30(0.5f, 0.0f, std::sqrt(3.0f) / 2.0f);
  const float a55 = 55.0f * kPi / 180.0f;
  const vec3 wo(-std::sin(a55), 0.0f, std::cos(a55));
  ASSERT_LT(glm::dot(reflect(wo, ns30), ng), 0.0f);  // the naive mirror image is below
  for (Model model : {Model::Mirror, Model::Dielectric}) {
    const Material m = make_material(model, vec3(1.0f), 1.5f);
    const Surface s = make_surface(m, ng, ns30);
    SpecularBranch br[kMaxDeltaBranches];
    const int nb = s.bsdf.delta_branches(wo, Transport::Radiance, br);
    ASSERT_GE(nb, 1);
    EXPECT_GT(glm::dot(br[0].dir, ng), 0.0f);
    EXPECT_NEAR(glm::length(br[0].dir), 1.0f, 1e-5f);
    if (nb == 2) EXPECT_LT(glm::dot(br[1].dir, ng), 0.0f);
  }

  Rng rng(109, 0, 0, Stream::Test);
  for (int k = 0; k < 5000; ++k) {
    const vec3 nsr = glm::normalize(ng + 0.7f * random_unit(rng));
    vec3 w = random_unit(rng);
    if (std::fabs(glm::dot(w, ng)) < 1e-3f) continue;
    const float side = glm::dot(w, ng) > 0.0f ? 1.0f : -1.0f;
    for (Model model : {Model::Mirror, Model::Dielectric}) {
      const Material m = make_material(model, vec3(1.0f), 1.5f);
      const Surface s = make_surface(m, ng, glm::dot(nsr, ng) > 0.0f ? nsr : -nsr);
      SpecularBranch br[kMaxDeltaBranches];
      const int nb = s.bsdf.delta_branches(w, Transport::Importance, br);
      ASSERT_GE(nb, 1);
      ASSERT_LE(nb, 2);
      EXPECT_GT(side * glm::dot(br[0].dir, ng), 0.0f) << "reflection on the wrong side, k=" << k;
      EXPECT_NEAR(glm::length(br[0].dir), 1.0f, 1e-5f);
      if (nb == 2) {
        EXPECT_LT(side * glm::dot(br[1].dir, ng), 0.0f) << "refraction on the wrong side, k=" << k;
        EXPECT_NEAR(glm::length(br[1].dir), 1.0f, 1e-5f);
      }
      for (int b = 0; b < nb; ++b) {
        EXPECT_TRUE(is_finite(br[b].weight));
        EXPECT_GE(br[b].weight.x, 0.0f);
      }
    }
  }
}

}  // namespace
}  // namespace pb

namespace pb {
namespace {

// World keeps one Bsdf per untextured material and moves it to each hit's frame
// (Bsdf::move_to_frame): where Bsdf::frame_free says so, that is the Bsdf built at the hit, bit for
// bit: eval, the delta probability and every draw (the same random numbers), over random frames
// with tilted shading normals and random directions, for the glTF parts that may be frame free.
// A clear coat or an anisotropy direction depends on the frame: not frame free.
TEST(BsdfFrame, AFrameFreeBsdfMovedToAFrameIsTheOneBuiltThere) {
  std::vector<Material> mats = {Material::lambertian(vec3(0.6f, 0.3f, 0.2f)),
                                Material::metal(vec3(0.9f, 0.6f, 0.3f), 0.4f),
                                Material::metal(vec3(0.9f), 0.01f), Material::glass(1.5f)};
  Material dielectric = Material::metal(vec3(0.5f), 0.3f);
  dielectric.metallic = 0.0f;
  mats.push_back(dielectric);
  Material rough_glass = Material::glass(1.4f);
  rough_glass.roughness = 0.3f;
  mats.push_back(rough_glass);
  Material sheen = Material::lambertian(vec3(0.4f));
  sheen.sheen_color = vec3(0.8f, 0.5f, 0.2f);
  sheen.sheen_roughness = 0.5f;
  mats.push_back(sheen);
  Material dt = dielectric;
  dt.diffuse_transmission = 0.5f;
  mats.push_back(dt);
  Material film = dielectric;
  film.iridescence = 1.0f;
  mats.push_back(film);
  for (size_t k = 0; k < mats.size(); ++k) {
    SCOPED_TRACE("material " + std::to_string(k));
    const BsdfParams p = BsdfParams::of(mats[k]);
    ASSERT_TRUE(Bsdf::frame_free(p));
    const Bsdf plain(p, vec3(0, 0, 1), vec3(0, 0, 1));
    for (uint64_t i = 0; i < 200; ++i) {
      Rng rng(11, k, i, Stream::Test);
      const vec3 ng = sample_uniform_sphere(rng.next_float(), rng.next_float());
      const vec3 ns =
          glm::normalize(ng + 0.3f * sample_uniform_sphere(rng.next_float(), rng.next_float()));
      const Bsdf built(p, ng, ns);
      Bsdf moved = plain;
      moved.move_to_frame(ng, ns);
      const vec3 wo = sample_uniform_sphere(rng.next_float(), rng.next_float());
      const vec3 wi = sample_uniform_sphere(rng.next_float(), rng.next_float());
      const vec3 a = built.eval(wo, wi), b = moved.eval(wo, wi);
      ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << i;
      ASSERT_EQ(built.delta_probability(wo), moved.delta_probability(wo)) << i;
      Rng r1(12, k, i, Stream::Test), r2(12, k, i, Stream::Test);
      BsdfSample s1, s2;
      const bool ok1 = built.sample(wo, r1, Transport::Importance, s1);
      ASSERT_EQ(ok1, moved.sample(wo, r2, Transport::Importance, s2)) << i;
      if (!ok1) continue;
      ASSERT_EQ(std::memcmp(&s1.wi, &s2.wi, sizeof s1.wi), 0) << i;
      ASSERT_EQ(std::memcmp(&s1.weight, &s2.weight, sizeof s1.weight), 0) << i;
      ASSERT_EQ(s1.pdf, s2.pdf) << i;
    }
  }
  Material coat = dielectric;
  coat.clearcoat = 0.5f;
  EXPECT_FALSE(Bsdf::frame_free(BsdfParams::of(coat)));
  Material aniso = dielectric;
  aniso.anisotropy = 0.5f;
  EXPECT_FALSE(Bsdf::frame_free(BsdfParams::of(aniso)));
}

}  // namespace
}  // namespace pb
