// KHR_materials_sheen through the Bsdf: the Charlie terms and the albedo table against the
// extension's formulas and a finer quadrature, eval against its layering written out here,
// reciprocity, max_f, and furnaces: a sheen over black reflects E, a white sheen over a white base
// no more than 1. Per draw and by chi-square, reciprocity and albedo: bsdf_properties.h, over the
// cases below.
#include "bsdf/bsdf.h"
#include "bsdf/sheen.h"
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

using test::Basis;
using test::brdf_of;
using test::BsdfCase;
using test::cases_of;
using test::chi_square;
using test::metal_rough;
using test::Property;
using test::random_normals;
using test::random_unit;

// The extension's formulas, written out from its text in double.
double spec_d(double cos_h, double alpha) {
  const double inv = 1.0 / alpha;
  return (2.0 + inv) * std::pow(std::max(0.0, 1.0 - cos_h * cos_h), 0.5 * inv) / (2.0 * kPiD);
}
double spec_l(double x, double alpha) {
  const double t = (1.0 - alpha) * (1.0 - alpha);
  auto mix = [t](double u, double v) { return u * (1.0 - t) + v * t; };
  return mix(21.5473, 25.3245) /
             (1.0 + mix(3.82987, 3.32435) * std::pow(x, mix(0.19823, 0.16801))) +
         mix(-1.97760, -1.27393) * x + mix(-4.32054, -4.85967);
}
double spec_lambda(double c, double alpha) {
  return c < 0.5 ? std::exp(spec_l(c, alpha))
                 : std::exp(2.0 * spec_l(0.5, alpha) - spec_l(1.0 - c, alpha));
}
double spec_v(double co, double ci, double alpha) {
  const double v = 1.0 / ((1.0 + spec_lambda(co, alpha) + spec_lambda(ci, alpha)) * 4.0 * co * ci);
  return std::clamp(v, 0.0, 1.0);
}
// E by the midpoint rule over the half vector (wi = reflect(wo, h), d omega_i = 4 (wo.h)
// d omega_h): 3000 cells in theta_h (D's peak along the horizon is about sqrt(alpha) >= 0.07
// wide, so at least 130 cells span it) and 240 in phi_h over [0, pi], in double.
double fine_albedo(double mu, double roughness) {
  const double r = std::max(roughness, double(kMinSheenRoughness)), alpha = r * r;
  const dvec3 wo(std::sqrt(1.0 - mu * mu), 0.0, mu);
  double sum = 0.0;
  constexpr int kTheta = 3000, kPhi = 240;
  for (int i = 0; i < kTheta; ++i) {
    const double th = (i + 0.5) / kTheta * kPiD / 2;
    const double d = spec_d(std::cos(th), alpha);
    for (int j = 0; j < kPhi; ++j) {
      const double phi = kPiD * (j + 0.5) / kPhi;
      const dvec3 m(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
      const double o_h = glm::dot(wo, m);
      const dvec3 wi = 2.0 * o_h * m - wo;
      if (o_h <= 0.0 || wi.z <= 0.0) continue;
      sum += d * spec_v(mu, wi.z, alpha) * wi.z * 4.0 * o_h * std::sin(th);
    }
  }
  return sum * (kPiD / 2 / kTheta) * (2.0 * kPiD / kPhi);
}

BsdfParams sheened(vec3 base, float metallic, float roughness, vec3 sheen, float sheen_rough,
                   float specular = 1.0f) {
  BsdfParams p = metal_rough(base, metallic, roughness);
  p.specular = specular;
  p.sheen_color = sheen;
  p.sheen_roughness = sheen_rough;
  return p;
}

TEST(Sheen, CharlieTermsAreTheExtensions) {
  // D and V against the extension's formulas (relative 1e-4, float against double), and D's
  // largest value along the horizon.
  Rng rng(501, 0, 0, Stream::Test);
  for (int k = 0; k < 5000; ++k) {
    const float r = kMinSheenRoughness + (1.0f - kMinSheenRoughness) * rng.next_float();
    const float alpha = sheen_alpha(r);
    const float c = rng.next_float(), co = 0.01f + 0.99f * rng.next_float(),
                ci = 0.01f + 0.99f * rng.next_float();
    const double d = spec_d(c, alpha), v = spec_v(co, ci, alpha);
    EXPECT_NEAR(charlie_d(c, alpha), d, 1e-4 * d + 1e-7) << r;
    EXPECT_NEAR(charlie_visibility(co, ci, alpha), v, 1e-4 * v + 1e-7) << r;
    EXPECT_LE(charlie_d(c, alpha), charlie_d_max(alpha) * (1.0f + 1e-6f));
  }
  EXPECT_NEAR(charlie_d(0.0f, 0.25f), charlie_d_max(0.25f), 1e-6f);
}

TEST(Sheen, AlbedoTableMatchesAFinerQuadrature) {
  // sheen_albedo's table (33 x 33, bilinear) against the midpoint rule on 3000 x 240 cells
  // (itself within 1e-7 of an 8000 x 800 grid over wi), off the table's nodes: within 4e-3,
  // which bilinear interpolation reaches at the smallest roughness, where E changes by 0.3
  // between nodes (measured 3.1e-3 there, below 1e-3 from roughness 0.3), and E above 0
  // (toward the horizon at small roughness it exceeds 1: the model as defined).
  double worst = 0.0;
  for (double r : {0.07, 0.13, 0.3, 0.55, 0.81, 1.0})
    for (double mu : {0.02, 0.11, 0.37, 0.64, 0.93, 1.0}) {
      const double want = fine_albedo(mu, r), got = sheen_albedo(float(mu), float(r));
      worst = std::max(worst, std::fabs(got - want));
      EXPECT_NEAR(got, want, 4e-3) << "roughness " << r << " mu " << mu;
      EXPECT_GT(got, 0.0);
    }
  std::printf("sheen albedo table: largest difference %.2e\n", worst);
}

TEST(Sheen, EvalIsTheExtensionsAlbedoScaling) {
  // f = sheen D V + max(0, min(1 - max(sheen) E(wo), 1 - max(sheen) E(wi))) f_material, in a
  // frame about ns of the test's own: relative 1e-4 (E from the same table; D and V from the
  // formulas).
  Rng rng(502, 0, 0, Stream::Test);
  int tested = 0;
  for (int k = 0; k < 20000; ++k) {
    vec3 ng, ns;
    random_normals(rng, ng, ns);
    const vec3 sheen(rng.next_float(), rng.next_float(), rng.next_float());
    const float sr = rng.next_float();
    const BsdfParams p = sheened(vec3(rng.next_float(), rng.next_float(), rng.next_float()),
                                 rng.next_float(), 0.1f + 0.9f * rng.next_float(), sheen, sr);
    const Bsdf bsdf(p, ng, ns);
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    const float side = glm::dot(wo, ng) > 0.0f ? 1.0f : -1.0f;
    const vec3 value = bsdf.eval(wo, wi);
    const Basis f(side * ns);
    const vec3 lo = f.local(wo), li = f.local(wi);
    if (glm::dot(wi, ng) * side <= 0.0f || lo.z <= 0.0f || li.z <= 0.0f) {
      EXPECT_EQ(value, vec3(0.0f));
      continue;
    }
    if (lo.z < 1e-3f || li.z < 1e-3f) continue;
    const double alpha = sheen_alpha(sr), m = max_component(sheen);
    const double s =
        std::max(0.0, std::min(1.0 - m * sheen_albedo(lo.z, sr), 1.0 - m * sheen_albedo(li.z, sr)));
    const double dv = spec_d(glm::normalize(lo + li).z, alpha) * spec_v(lo.z, li.z, alpha);
    const vec3 base = brdf_of(p).eval(lo, li);
    for (int c = 0; c < 3; ++c) {
      const double want = sheen[c] * dv + s * base[c];
      EXPECT_NEAR(value[c], want, 1e-4 * want + 1e-7) << k;
    }
    ++tested;
  }
  EXPECT_GT(tested, 3000);
}

TEST(Sheen, ReciprocalAndBoundedByMaxF) {
  // The sheen and its min-form scaling are symmetric: f(wo, wi) = f(wi, wo) (relative 1e-5);
  // max_f(wo) bounds eval(wo, wi) for random wi and wi along the horizon, where D peaks.
  Rng rng(503, 0, 0, Stream::Test);
  for (int k = 0; k < 4000; ++k) {
    const vec3 n(0, 0, 1);
    const BsdfParams p =
        sheened(vec3(rng.next_float()), rng.next_float(), 0.05f + 0.95f * rng.next_float(),
                vec3(rng.next_float(), rng.next_float(), rng.next_float()), rng.next_float());
    const Bsdf bsdf(p, n, n);
    const vec3 wo = random_unit(rng);
    const vec3 cap = bsdf.max_f(wo);
    for (int i = 0; i < 100; ++i) {
      vec3 wi = random_unit(rng);
      if (i % 2) wi = glm::normalize(vec3(wi.x, wi.y, 0.002f * wi.z));  // grazing
      const vec3 a = bsdf.eval(wo, wi), b = bsdf.eval(wi, wo);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a[c], b[c], 1e-5f * a[c] + 1e-9f) << k;
        ASSERT_LE(a[c], cap[c] * (1.0f + 1e-5f)) << k;
      }
    }
  }
}

// The suite's cases (bsdf_properties.h): 6 x 2 chi-square tests, each failing below p = 1e-4
// (family-wise false alarm about 1.2e-3 at a fixed seed, which this seed passes).
std::vector<BsdfCase> sheen_cases() {
  BsdfParams coat = sheened(vec3(0.6f, 0.2f, 0.2f), 0.0f, 0.8f, vec3(0.9f), 0.3f);
  coat.clearcoat = 1.0f;
  BsdfParams rough_coat = sheened(vec3(0.3f), 0.0f, 0.5f, vec3(0.5f, 0.7f, 0.9f), 0.6f);
  rough_coat.clearcoat = 0.5f;
  rough_coat.clearcoat_roughness = 0.3f;
  std::vector<BsdfCase> c = cases_of(
      {{"sheen 0.3 over Lambertian", sheened(vec3(0.5f), 0.0f, 1.0f, vec3(1.0f), 0.3f, 0.0f)},
       {"sheen 0.9 over glossy dielectric",
        sheened(vec3(0.2f, 0.4f, 0.8f), 0.0f, 0.4f, vec3(0.8f, 0.6f, 0.5f), 0.9f)},
       {"sheen 0.1 over rough metal", sheened(vec3(0.9f), 1.0f, 0.6f, vec3(0.4f), 0.1f)},
       {"sheen over smooth metal", sheened(vec3(0.9f), 1.0f, 0.0f, vec3(0.7f), 0.5f)},
       {"sheen under a smooth coat", coat},
       {"sheen under a rough coat", rough_coat}},
      504, 505);
  for (BsdfCase* x : {&c[4], &c[5]})
    x->exclude(Property::Reciprocity,
               "the clear coat's view weight is not reciprocal (test_bsdf_clearcoat.cpp)");
  return c;
}
PB_BSDF_PROPERTY_CASES(Sheen, sheen_cases());

TEST(Sheen, FurnacesOverBlackAndOverWhite) {
  // Radiance albedo (2e5 draws, absorbed 0): a white sheen over a black base reflects its own
  // E (the fine quadrature, within 4 standard errors + 3e-3 for the table); over a white
  // Lambertian the albedo scaling keeps the sum at most 1 (+ 4 standard errors), and above
  // the base's own (1 - max(sheen) E) share.
  const vec3 n(0, 0, 1);
  for (float r : {0.1f, 0.4f, 0.9f})
    for (double mu : {0.95, 0.6, 0.25, 0.08}) {
      const vec3 wo(float(std::sqrt(1.0 - mu * mu)), 0.0f, float(mu));
      const Bsdf black(sheened(vec3(0.0f), 0.0f, 1.0f, vec3(1.0f), r, 0.0f), n, n);
      const Bsdf white(sheened(vec3(1.0f), 0.0f, 1.0f, vec3(1.0f), r, 0.0f), n, n);
      Rng rng(506, uint64_t(r * 10), uint64_t(mu * 100), Stream::Test);
      auto albedo = [&](const Bsdf& b) {
        double sum = 0.0, sum2 = 0.0;
        const int count = 200000;
        for (int i = 0; i < count; ++i) {
          BsdfSample s;
          const double w = b.sample(wo, rng, Transport::Radiance, s) ? double(s.weight.x) : 0.0;
          sum += w;
          sum2 += w * w;
        }
        const double mean = sum / count;
        return std::pair(mean, std::sqrt(std::max(0.0, sum2 / count - mean * mean) / count));
      };
      const double e = fine_albedo(mu, r);
      const auto [b_mean, b_se] = albedo(black);
      const auto [w_mean, w_se] = albedo(white);
      std::printf(
          "roughness %.1f mu %.2f: E %.4f, over black %.4f +- %.4f, over white %.4f +- "
          "%.4f\n",
          r, mu, e, b_mean, b_se, w_mean, w_se);
      EXPECT_NEAR(b_mean, e, 4.0 * b_se + 3e-3) << r << " " << mu;
      EXPECT_LE(w_mean, 1.0 + 4.0 * w_se) << r << " " << mu;
      EXPECT_GT(w_mean, b_mean) << r << " " << mu;
    }
}

}  // namespace
}  // namespace pb
