// KHR_materials_anisotropy: the anisotropic GGX functions (normalisation of D and of the visible
// normals, equality with the isotropic ones at equal alphas), the Bsdf against the extension's
// BRDF written out here, reciprocity, max_f, the albedo of the draws against quadrature, the follow
// split, and the mirror rule (a lobe is a mirror only when it is narrow in every direction). Per
// draw and by chi-square, reciprocity and albedo: bsdf_properties.h, over the cases below.
#include "bsdf/bsdf.h"
#include "bsdf/microfacet.h"
#include "render/lobe_split.h"
#include "util/rng.h"

#include "bsdf_properties.h"
#include "bsdf_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace pb {
namespace {

using test::BsdfCase;
using test::cases_of;
using test::expect_sample_matches_eval;
using test::metal_rough;
using test::Property;
using test::random_normals;
using test::random_unit;

// Midpoint rule over the slopes (sx, sy) of h = normalize(-sx, -sy, 1), with sx = ax tan(u),
// sy = ay tan(v) and u, v in (-pi/2, pi/2) on an n x n grid: d omega_h = d^2 s / (1 + s^2)^1.5,
// d^2 s = ax ay sec^2 u sec^2 v du dv. The stretch follows the lobe, so a few hundred cells
// resolve it for any alphas.
template <class F>
double over_normals(float ax, float ay, int n, F&& g) {
  double sum = 0.0;
  const double du = kPiD / n;
  for (int i = 0; i < n; ++i) {
    const double u = -kPiD / 2 + (i + 0.5) * du, cu = std::cos(u);
    for (int j = 0; j < n; ++j) {
      const double v = -kPiD / 2 + (j + 0.5) * du, cv = std::cos(v);
      const double sx = ax * std::tan(u), sy = ay * std::tan(v), s2 = 1.0 + sx * sx + sy * sy;
      const vec3 h = glm::normalize(vec3(float(-sx), float(-sy), 1.0f));
      sum += g(h) * double(ax) * ay / (cu * cu * cv * cv) / std::pow(s2, 1.5);
    }
  }
  return sum * du * du;
}

TEST(AnisotropicGgx, DistributionAndVisibleNormalsIntegrateToOne) {
  // int D(h) h.z d omega_h = 1 and, for every wo, int D_wo(h) d omega_h = 1 (Heitz 2018 eq. 3),
  // 400 x 400 cells: the midpoint rule's error on these smooth integrands is below 1e-4.
  const float alphas[][2] = {{0.5f, 0.5f}, {1.0f, 0.09f}, {0.3f, 0.01f}, {0.05f, 0.6f}};
  for (const auto& a : alphas) {
    const double d = over_normals(
        a[0], a[1], 400, [&](const vec3& h) { return double(ggx_d(h, a[0], a[1])) * h.z; });
    EXPECT_NEAR(d, 1.0, 2e-4) << a[0] << " " << a[1];
    for (const vec3 wo : {vec3(0, 0, 1), glm::normalize(vec3(0.8f, 0.3f, 0.5f)),
                          glm::normalize(vec3(-0.2f, 0.9f, 0.1f))}) {
      const double v = over_normals(
          a[0], a[1], 400, [&](const vec3& h) { return double(ggx_vndf(wo, h, a[0], a[1])); });
      EXPECT_NEAR(v, 1.0, 2e-3) << a[0] << " " << a[1] << " wo.z " << wo.z;
    }
  }
}

TEST(AnisotropicGgx, EqualAlphasAreTheIsotropicFunctions) {
  // At alpha_x = alpha_y every function equals its isotropic form (relative 1e-5; the two
  // round differently), so strength 0 and the isotropic path meet.
  Rng rng(601, 0, 0, Stream::Test);
  for (int k = 0; k < 20000; ++k) {
    const float a = 0.01f + 0.99f * rng.next_float();
    vec3 wo = random_unit(rng), wi = random_unit(rng);
    wo.z = std::fabs(wo.z) + 1e-3f;
    wi.z = std::fabs(wi.z) + 1e-3f;
    wo = glm::normalize(wo);
    wi = glm::normalize(wi);
    const vec3 h = glm::normalize(wo + wi);
    auto near = [](float x, float y) { return std::fabs(x - y) <= 1e-5f * std::fabs(y) + 1e-30f; };
    EXPECT_TRUE(near(ggx_d(h, a, a), ggx_d(h, a))) << k;
    EXPECT_TRUE(near(smith_g1(wo, a, a), smith_g1(wo, a))) << k;
    EXPECT_TRUE(near(ggx_visibility(wo, wi, a, a), ggx_visibility(wo.z, wi.z, a))) << k;
    EXPECT_TRUE(near(ggx_vndf(wo, h, a, a), ggx_vndf(wo, h, a))) << k;
    EXPECT_TRUE(near(ggx_reflection_pdf(wo, wi, a, a), ggx_reflection_pdf(wo, wi, a))) << k;
    const float u1 = rng.next_float(), u2 = rng.next_float();
    EXPECT_LT(glm::length(sample_ggx_vndf(wo, a, a, u1, u2) - sample_ggx_vndf(wo, a, u1, u2)),
              1e-5f)
        << k;
  }
}

// The extension's BRDF (its README, "Implementation": BRDF_specularAnisotropicGGX with
// D_GGX_anisotropic and V_GGX_anisotropic, without V's clamp to 1) over glTF's base, in double:
// metal F V D with F = Schlick(base), or the dielectric (1 - F) base / pi + F V D, F = Schlick
// (0.04). T is the direction projected into the tangent plane, B = n x T.
dvec3 extension_brdf(const BsdfParams& p, const dvec3& n, const dvec3& dir, const dvec3& v,
                     const dvec3& l) {
  const double alpha = std::max(double(p.roughness) * p.roughness, 1e-4);
  const double s = p.anisotropy, at = alpha * (1.0 - s * s) + s * s, ab = alpha;
  const dvec3 t = glm::normalize(dir - glm::dot(dir, n) * n), b = glm::cross(n, t);
  const dvec3 h = glm::normalize(v + l);
  const double a2 = at * ab;
  const dvec3 f(ab * glm::dot(t, h), at * glm::dot(b, h), a2 * glm::dot(n, h));
  const double w2 = a2 / glm::dot(f, f);
  const double d = a2 * w2 * w2 / kPiD;
  const double nv = glm::dot(n, v), nl = glm::dot(n, l);
  const double gv = nl * glm::length(dvec3(at * glm::dot(t, v), ab * glm::dot(b, v), nv));
  const double gl = nv * glm::length(dvec3(at * glm::dot(t, l), ab * glm::dot(b, l), nl));
  const double vis = 0.5 / (gv + gl);
  const double w = std::pow(1.0 - glm::dot(v, h), 5.0);
  const dvec3 base(p.base_color);
  if (p.metallic == 1.0f) return (base + (dvec3(1.0) - base) * w) * (vis * d);
  const double fr = 0.04 + 0.96 * w;
  return (1.0 - fr) * base / kPiD + dvec3(fr * vis * d);
}

BsdfParams brushed(vec3 base, float metallic, float roughness, float strength, vec3 dir) {
  BsdfParams p = metal_rough(base, metallic, roughness);
  p.anisotropy = strength;
  p.anisotropy_direction = dir;
  return p;
}

TEST(Anisotropy, EvalIsTheExtensionsBrdf) {
  // Random metals and dielectrics, directions and anisotropy directions (not in the tangent
  // plane: the Bsdf projects them), relative 1e-4 against the double formula.
  Rng rng(602, 0, 0, Stream::Test);
  for (int k = 0; k < 20000; ++k) {
    const vec3 n = random_unit(rng);
    const vec3 dir = random_unit(rng);
    if (std::fabs(glm::dot(dir, n)) > 0.95f) continue;
    const BsdfParams p =
        brushed(vec3(rng.next_float(), rng.next_float(), rng.next_float()), k % 2 ? 1.0f : 0.0f,
                0.1f + 0.9f * rng.next_float(), rng.next_float(), dir);
    const Bsdf bsdf(p, n, n);
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    if (glm::dot(wo, n) < 0.05f || glm::dot(wi, n) < 0.05f) continue;
    const vec3 got = bsdf.eval(wo, wi);
    const dvec3 want = extension_brdf(p, dvec3(n), dvec3(dir), dvec3(wo), dvec3(wi));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-4 * want[c] + 1e-7) << k;
  }
}

TEST(Anisotropy, ReciprocalAndBoundedByMaxF) {
  // f(wo, wi) = f(wi, wo) (relative 1e-5); max_f(wo) bounds eval(wo, wi) for random wi, for wi
  // the lobe draws (near its peak) and grazing wi, over random strengths, roughnesses down to
  // 0.05, shading normals and clear coats.
  Rng rng(603, 0, 0, Stream::Test);
  for (int k = 0; k < 3000; ++k) {
    vec3 ng, ns;
    random_normals(rng, ng, ns);
    BsdfParams p = brushed(vec3(rng.next_float()), rng.next_float(),
                           0.05f + 0.95f * rng.next_float(), rng.next_float(), random_unit(rng));
    if (k % 3 == 0) {
      p.clearcoat = rng.next_float();
      p.clearcoat_roughness = 0.2f + 0.8f * rng.next_float();
    }
    const Bsdf bsdf(p, ng, ns);
    const vec3 wo = random_unit(rng);
    const vec3 cap = bsdf.max_f(wo);
    for (int i = 0; i < 100; ++i) {
      vec3 wi = random_unit(rng);
      if (i % 3 == 1) {
        BsdfSample s;
        if (!bsdf.sample(wo, rng, Transport::Radiance, s) || s.delta) continue;
        wi = s.wi;
      } else if (i % 3 == 2) {
        wi = glm::normalize(vec3(wi.x, wi.y, 0.002f * wi.z));
      }
      const vec3 a = bsdf.eval(wo, wi);
      for (int c = 0; c < 3; ++c) {
        if (p.clearcoat == 0.0f) EXPECT_NEAR(a[c], bsdf.eval(wi, wo)[c], 1e-5f * a[c] + 1e-9f) << k;
        ASSERT_LE(a[c], cap[c] * (1.0f + 1e-5f)) << k << " " << i;
      }
    }
  }
}

// The suite's cases (bsdf_properties.h): 4 x 2 chi-square tests, each failing below p = 1e-4
// (family-wise false alarm about 8e-4 at a fixed seed, which this seed passes). Alphas of at
// least 0.04: the helper's 12 x 12 sub-cells per cell do not resolve narrower lobes at grazing
// views (an isotropic metal of roughness 0.15 fails it at theta 1.3 as well); the albedo test
// below checks the draws of roughness 0.1 against a quadrature that follows the lobe.
std::vector<BsdfCase> anisotropy_cases() {
  const vec3 dir = glm::normalize(vec3(1.0f, 0.3f, 0.2f));
  const vec3 across = glm::normalize(vec3(0.3f, 1.0f, 0.2f));
  BsdfParams coated = brushed(vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.4f, 0.8f, dir);
  coated.clearcoat = 1.0f;
  coated.clearcoat_roughness = 0.3f;
  std::vector<BsdfCase> c =
      cases_of({{"brushed metal r 0.3 s 1", brushed(vec3(0.9f), 1.0f, 0.3f, 1.0f, dir)},
                {"dielectric r 0.2 s 0.6", brushed(vec3(0.2f, 0.4f, 0.8f), 0.0f, 0.2f, 0.6f, dir)},
                {"metal r 0.25 s 0.7 across", brushed(vec3(0.8f), 1.0f, 0.25f, 0.7f, across)},
                {"coated brushed metal", coated}},
               604, 605);
  c[3].exclude(Property::Reciprocity,
               "the clear coat's view weight is not reciprocal (test_bsdf_clearcoat.cpp)");
  return c;
}
PB_BSDF_PROPERTY_CASES(Anisotropy, anisotropy_cases());

TEST(Anisotropy, AlbedoOfTheDrawsMatchesQuadrature) {
  // White brushed metal (F = 1): the mean weight of 2e5 radiance draws against the integral of
  // f cos over wi = reflect(wo, h), 600 x 600 slope cells (d omega_i = 4 |wo.h| d omega_h),
  // within 4 standard errors + 1e-3 for the quadrature; single scattering keeps it <= 1.
  const vec3 n(0, 0, 1), dir(1, 0, 0);
  for (float r : {0.1f, 0.4f})
    for (float s : {0.5f, 1.0f})
      for (const vec3 wo :
           {glm::normalize(vec3(0.6f, 0.0f, 0.8f)), glm::normalize(vec3(0.0f, 0.9f, 0.3f)),
            glm::normalize(vec3(0.7f, -0.6f, 0.4f))}) {
        const BsdfParams p = brushed(vec3(1.0f), 1.0f, r, s, dir);
        const Bsdf bsdf(p, n, n);
        MetalRoughBrdf m;
        m.roughness = r;
        m.anisotropy = s;
        const double quad = over_normals(m.alpha_x(), m.alpha_y(), 600, [&](const vec3& h) {
          const float o_h = glm::dot(wo, h);
          const vec3 wi = 2.0f * o_h * h - wo;
          if (o_h <= 0.0f || wi.z <= 0.0f) return 0.0;
          return double(bsdf.eval(wo, wi).x) * wi.z * 4.0 * o_h;
        });
        Rng rng(606, uint64_t(r * 10), uint64_t(s * 10 + wo.z * 100), Stream::Test);
        double sum = 0.0, sum2 = 0.0;
        const int count = 200000;
        for (int i = 0; i < count; ++i) {
          BsdfSample b;
          const double w = bsdf.sample(wo, rng, Transport::Radiance, b) ? double(b.weight.x) : 0.0;
          sum += w;
          sum2 += w * w;
        }
        const double mean = sum / count;
        const double se = std::sqrt(std::max(0.0, sum2 / count - mean * mean) / count);
        std::printf("roughness %.1f strength %.1f wo.z %.2f: quadrature %.4f, draws %.4f +- %.4f\n",
                    r, s, wo.z, quad, mean, se);
        EXPECT_NEAR(mean, quad, 4.0 * se + 1e-3) << r << " " << s << " " << wo.z;
        EXPECT_LE(quad, 1.0 + 1e-3);
      }
}

TEST(Anisotropy, FollowedAndGatheredPartsSumToTheWhole) {
  // SPPM's split (render/lobe_split.h): base_part + lobe_part = eval (relative 1e-5), and each part
  // samples itself (sample against its own eval and pdf).
  const BsdfCase c = anisotropy_cases()[1];
  const vec3 n = glm::normalize(vec3(0.1f, 0.2f, 1.0f));
  const Bsdf bsdf(c.params, n, n);
  ASSERT_TRUE(has_lobe_below(bsdf, 1.0f));
  const Bsdf base = base_part(bsdf, 1.0f), lobe = lobe_part(bsdf, 1.0f);
  Rng rng(607, 0, 0, Stream::Test);
  for (int k = 0; k < 5000; ++k) {
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    if (glm::dot(wo, n) < 0.05f || glm::dot(wi, n) < 0.05f) continue;
    const vec3 all = bsdf.eval(wo, wi), sum = base.eval(wo, wi) + lobe.eval(wo, wi);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sum[ch], all[ch], 1e-5f * all[ch] + 1e-9f) << k;
    BsdfSample s;
    if (lobe.sample(wo, rng, Transport::Radiance, s))
      expect_sample_matches_eval(lobe, wo, s, n, "lobe part");
    if (base.sample(wo, rng, Transport::Radiance, s))
      expect_sample_matches_eval(base, wo, s, n, "base part");
  }
}

TEST(Anisotropy, AMirrorOnlyWhenNarrowInEveryDirection) {
  // Roughness 0 is a mirror without anisotropy; with it the lobe's alpha along the direction
  // is strength^2 (roughness 0.1 at strength 0.1, above the default --mirror-roughness 0.032),
  // a lobe, followed by SPPM as the isotropic lobe of the same peak, roughness (ax ay)^(1/4):
  // 0.032 here. At strength 0.02 (alpha_x 5e-4) it is a mirror
  // again. A direction along the normal has no tangent part: isotropic.
  const vec3 n(0, 0, 1), dir(1, 0, 0);
  EXPECT_TRUE(Bsdf(brushed(vec3(0.9f), 1.0f, 0.0f, 0.0f, dir), n, n).is_delta());
  const Bsdf wide(brushed(vec3(0.9f), 1.0f, 0.0f, 0.1f, dir), n, n);
  EXPECT_FALSE(wide.has_delta());
  EXPECT_TRUE(has_lobe_below(wide, 0.05f));
  EXPECT_FALSE(has_lobe_below(wide, 0.005f));
  EXPECT_TRUE(Bsdf(brushed(vec3(0.9f), 1.0f, 0.0f, 0.02f, dir), n, n).is_delta());
  const Bsdf along(brushed(vec3(0.9f), 1.0f, 0.5f, 1.0f, n), n, n);
  const Bsdf iso(brushed(vec3(0.9f), 1.0f, 0.5f, 0.0f, n), n, n);
  const vec3 wo = glm::normalize(vec3(0.3f, 0.2f, 0.9f)),
             wi = glm::normalize(vec3(-0.5f, 0.1f, 0.8f));
  EXPECT_EQ(along.eval(wo, wi), iso.eval(wo, wi));
}

}  // namespace
}  // namespace pb
