// KHR_materials_clearcoat through the Bsdf: eval against the extension's formula written out
// here, max_f (the coat is not reciprocal: photons see the adjoint), and furnaces whose albedo is
// known in closed form or by quadrature. Per draw and by chi-square (both transport directions),
// albedo: bsdf_properties.h, over the cases below.
#include "bsdf/bsdf.h"
#include "render/lobe_split.h"
#include "util/rng.h"

#include "bsdf_properties.h"
#include "bsdf_test_util.h"

#include "microfacet_quadrature.h"

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
using test::expect_sample_matches_eval;
using test::metal_rough;
using test::Property;
using test::random_normals;
using test::random_unit;

BsdfParams coated(vec3 base, float metallic, float roughness, float coat, float coat_roughness,
                  float specular = 1.0f, float transmission = 0.0f) {
  BsdfParams p = metal_rough(base, metallic, roughness);
  p.specular = specular;
  p.transmission = transmission;
  p.clearcoat = coat;
  p.clearcoat_roughness = coat_roughness;
  p.follows_transmission = false;  // smooth glass under the coat (rough: test_bsdf_rough_glass.cpp)
  return p;
}

// The extension's weight, written from its text: clearcoat (0.04 + 0.96 (1 - |v.n_c|)^5).
double coat_k(double coat, const vec3& v, const vec3& nc) {
  return coat * (0.04 + 0.96 * std::pow(1.0 - std::fabs(double(glm::dot(v, nc))), 5.0));
}

TEST(Clearcoat, EvalIsTheExtensionsFresnelCoat) {
  // f = (1 - k) f_material + k D V about n_c, k = clearcoat (0.04 + 0.96 (1 - |wo.n_c|)^5),
  // against MetalRoughBrdf in a frame about ns and GGX D and V in a frame about n_c (both
  // independent of the Bsdf's): relative 1e-4, 1e-7 absolute, as the uncoated test.
  Rng rng(401, 0, 0, Stream::Test);
  int tested = 0;
  for (int k = 0; k < 20000; ++k) {
    vec3 ng, ns, nc;
    random_normals(rng, ng, ns, nc);
    BsdfParams p =
        coated(vec3(rng.next_float(), rng.next_float(), rng.next_float()), rng.next_float(),
               0.1f + 0.9f * rng.next_float(), rng.next_float(), 0.05f + 0.9f * rng.next_float());
    p.coat_normal = nc;
    const Bsdf bsdf(p, ng, ns);
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    const float side = glm::dot(wo, ng) > 0.0f ? 1.0f : -1.0f;
    const vec3 value = bsdf.eval(wo, wi);
    if (glm::dot(wi, ng) * side <= 0.0f) {
      EXPECT_EQ(value, vec3(0.0f));
      continue;
    }
    const Basis fs(side * ns), fc(side * nc);
    const vec3 lo = fs.local(wo), li = fs.local(wi), co = fc.local(wo), ci = fc.local(wi);
    // Near a horizon the frames' rounding decides the side: skip.
    if (std::min({std::fabs(lo.z), std::fabs(li.z), std::fabs(co.z), std::fabs(ci.z)}) < 1e-3f)
      continue;
    const double kc = coat_k(p.clearcoat, wo, nc);
    const float alpha = ggx_alpha(p.clearcoat_roughness);
    // Each layer only above its own normal's horizon, on wo's side.
    const double dv = co.z > 0.0f && ci.z > 0.0f ? double(ggx_d(glm::normalize(co + ci), alpha)) *
                                                       double(ggx_visibility(co.z, ci.z, alpha))
                                                 : 0.0;
    const vec3 base = lo.z > 0.0f && li.z > 0.0f ? brdf_of(p).eval(lo, li) : vec3(0.0f);
    for (int c = 0; c < 3; ++c) {
      const double want = (1.0 - kc) * double(base[c]) + kc * dv;
      EXPECT_NEAR(value[c], want, 1e-4 * want + 1e-7) << k;
    }
    ++tested;
  }
  EXPECT_GT(tested, 3000);
}

TEST(Clearcoat, NotReciprocalExactlyByTheViewWeight) {
  // f(wo, wi) - f(wi, wo) is the coat's view weight at work: for a black base under a rough
  // coat, f(wo, wi) / f(wi, wo) = k(wo) / k(wi) (D V is symmetric): relative 1e-4.
  const vec3 n(0, 0, 1);
  const Bsdf bsdf(coated(vec3(0.0f), 0.0f, 0.5f, 0.8f, 0.4f, 0.0f), n, n);
  Rng rng(402, 0, 0, Stream::Test);
  int tested = 0;
  for (int k = 0; k < 20000; ++k) {
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    if (wo.z < 0.05f || wi.z < 0.05f) continue;
    const float a = bsdf.eval(wo, wi).x, b = bsdf.eval(wi, wo).x;
    if (!(a > 1e-6f)) continue;
    EXPECT_NEAR(a / b, coat_k(0.8, wo, n) / coat_k(0.8, wi, n), 1e-4 * a / b) << k;
    ++tested;
  }
  EXPECT_GT(tested, 2000);
}

TEST(Clearcoat, MaxFBoundsEveryValue) {
  // The sparse-photon cap (ESTIMATOR.md section 12) holds under a coat: random directions and
  // directions next to either mirror direction.
  Rng rng(403, 0, 0, Stream::Test);
  for (int k = 0; k < 2000; ++k) {
    vec3 ng, ns, nc;
    random_normals(rng, ng, ns, nc);
    const float rough = 0.033f + 0.967f * rng.next_float();
    const float coat_rough = k % 3 == 0 ? 0.0f : 0.033f + 0.5f * rng.next_float();
    BsdfParams p = coated(vec3(rng.next_float(), rng.next_float(), rng.next_float()),
                          rng.next_float(), rough, rng.next_float(), coat_rough);
    p.coat_normal = nc;
    const Bsdf bsdf(p, ng, ns);
    const vec3 wo = random_unit(rng);
    const vec3 cap = bsdf.max_f(wo);
    const float side = glm::dot(wo, ng) > 0.0f ? 1.0f : -1.0f;
    const vec3 ms = reflect(wo, side * ns), mc = reflect(wo, side * nc);
    for (int i = 0; i < 600; ++i) {
      const vec3 near = i % 3 == 1 ? mc : ms;
      const float spread = 0.5f * (i % 3 == 1 ? coat_rough * coat_rough : rough * rough);
      const vec3 wi =
          i % 3 == 0 ? random_unit(rng) : glm::normalize(near + spread * random_unit(rng));
      const vec3 f = bsdf.eval(wo, wi);
      for (int c = 0; c < 3; ++c) ASSERT_LE(f[c], cap[c] * (1.0f + 1e-5f)) << k;
    }
  }
}

// The suite's cases (bsdf_properties.h), each under a coat normal of its own: drawn beside ng
// per draw in the per-draw tests, nc below in the chi-square test (views 0.4 and 1.2; 14 tests
// each failing below p = 1e-4, a family-wise false alarm rate about 1.4e-3 at a fixed seed,
// which this seed passes). Not tested for reciprocity (the reason below). Continuous draws are
// expected where a lobe is rough, delta draws where the coat is smooth or glass transmits.
std::vector<BsdfCase> clearcoat_cases() {
  std::vector<BsdfCase> cases = cases_of(
      {{"rough coat over glossy dielectric",
        coated(vec3(0.7f, 0.4f, 0.2f), 0.0f, 0.5f, 1.0f, 0.2f)},
       {"rough coat over metal", coated(vec3(0.95f, 0.64f, 0.54f), 1.0f, 0.3f, 0.7f, 0.1f)},
       {"smooth coat over glossy mixture", coated(vec3(0.5f), 0.5f, 0.6f, 1.0f, 0.0f)},
       {"smooth coat over Lambertian",
        coated(vec3(0.6f, 0.3f, 0.3f), 0.0f, 1.0f, 1.0f, 0.0f, 0.0f)},
       {"rough coat over smooth metal", coated(vec3(0.9f), 1.0f, 0.0f, 1.0f, 0.3f)},
       {"smooth coat over thin glass", coated(vec3(0.8f), 0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f)},
       {"rough coat over thin glass", coated(vec3(0.8f), 0.0f, 0.4f, 0.5f, 0.3f, 1.0f, 0.6f)}},
      404, 405, {0.4, 1.2});
  for (BsdfCase& c : cases) {
    c.exclude(Property::Reciprocity,
              "its view weight is not reciprocal (NotReciprocalExactlyByTheViewWeight above)");
    c.tilt_coat_normal = true;
    c.chi_nc = glm::normalize(vec3(-0.15f, 0.1f, 1.0f));
    const BsdfParams& p = c.params;
    c.min_continuous = p.clearcoat_roughness > 0.0f || p.roughness > 0.0f ? 1000 : 0;
    c.min_delta = p.clearcoat_roughness == 0.0f || p.transmission > 0.0f ? 500 : 0;
  }
  return cases;
}
PB_BSDF_PROPERTY_CASES(Clearcoat, clearcoat_cases());

TEST(Clearcoat, FollowedAndGatheredPartsSumToTheWholeAndEachSamplesItself) {
  // SPPM follows the lobes below --follow-roughness (render/lobe_split.h): under a coat that is the
  // coat's lobe, the base's, or both. base_part(R) + lobe_part(R) is eval() (relative 1e-5),
  // each part's max_f bounds it, each part samples itself (weight = part eval cos / part pdf,
  // relative 2e-3), and lobe_probability is in (0, 1]. R = 0.5 follows a coat of 0.2 and a base
  // lobe of 0.3, and gathers a base lobe of 0.6.
  const float below = 0.5f;
  struct Split {
    const char* name;
    BsdfParams p;
    bool lobe, coat;  // followed
  };
  const Split splits[] = {
      {"coat 0.2 over dielectric 0.6", coated(vec3(0.7f, 0.4f, 0.2f), 0.0f, 0.6f, 1.0f, 0.2f),
       false, true},
      {"coat 0.2 over metal 0.3", coated(vec3(0.9f, 0.6f, 0.5f), 1.0f, 0.3f, 0.8f, 0.2f), true,
       true},
      {"smooth coat over mixture 0.3", coated(vec3(0.5f), 0.5f, 0.3f, 1.0f, 0.0f), true, false},
      {"coat 0.7 over dielectric 0.3", coated(vec3(0.5f), 0.0f, 0.3f, 1.0f, 0.7f), true, false}};
  Rng rng(409, 0, 0, Stream::Test);
  for (const Split& c : splits) {
    const vec3 z(0, 0, 1);
    EXPECT_TRUE(has_lobe_below(Bsdf(c.p, z, z), below)) << c.name;
    EXPECT_FALSE(has_lobe_below(Bsdf(c.p, z, z), 0.1f)) << c.name;
    int drawn[2] = {0, 0};
    for (int k = 0; k < 4000; ++k) {
      vec3 ng, ns, nc;
      random_normals(rng, ng, ns, nc);
      BsdfParams p = c.p;
      p.coat_normal = nc;
      const Bsdf bsdf(p, ng, ns);
      const Bsdf parts[2] = {base_part(bsdf, below), lobe_part(bsdf, below)};
      const vec3 wo = random_unit(rng), wi = random_unit(rng);
      const vec3 n = glm::dot(wo, ng) > 0.0f ? ns : -ns;
      if (glm::dot(wo, n) < 0.02f) continue;
      const vec3 whole = bsdf.eval(wo, wi), sum = parts[0].eval(wo, wi) + parts[1].eval(wo, wi);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(sum[ch], whole[ch], 1e-5f * whole[ch] + 1e-9f) << c.name;
      const float p_lobe = lobe_probability(bsdf, wo, below);
      EXPECT_TRUE(p_lobe > 0.0f && p_lobe < 1.0f) << c.name;
      for (int part = 0; part < 2; ++part) {
        const Bsdf& b = parts[part];
        const vec3 bound = b.max_f(wo), value = b.eval(wo, wi);
        for (int ch = 0; ch < 3; ++ch) EXPECT_LE(value[ch], bound[ch] * (1.0f + 1e-5f)) << c.name;
        BsdfSample s;
        if (!b.sample(wo, rng, Transport::Radiance, s)) continue;
        ASSERT_FALSE(s.delta) << c.name;
        expect_sample_matches_eval(b, wo, s, ns, c.name);
        ++drawn[part];
      }
    }
    EXPECT_GT(drawn[0], 1000) << c.name;
    EXPECT_GT(drawn[1], 1000) << c.name;
  }
  // The followed part under a coat of 0.2 over black: its albedo by sampling is k x the D V
  // albedo by quadrature (4 standard errors + 2e-4), as the whole's was.
  const Bsdf lobe = lobe_part(
      Bsdf(coated(vec3(0.0f), 0.0f, 0.6f, 1.0f, 0.2f, 0.0f), vec3(0, 0, 1), vec3(0, 0, 1)), below);
  MetalRoughBrdf dv;
  dv.base_color = vec3(1.0f);
  dv.metallic = 1.0f;
  dv.roughness = 0.2f;
  for (double mu : {0.9, 0.3}) {
    const vec3 wo = quad::at_cos(mu);
    Rng r(410, uint64_t(mu * 10), 0, Stream::Test);
    double sum = 0.0, sum2 = 0.0;
    const int count = 200000;
    for (int i = 0; i < count; ++i) {
      BsdfSample s;
      const double w = lobe.sample(wo, r, Transport::Radiance, s) ? double(s.weight.x) : 0.0;
      sum += w;
      sum2 += w * w;
    }
    const double mean = sum / count, se = std::sqrt((sum2 / count - mean * mean) / count);
    const double want = coat_k(1.0, wo, vec3(0, 0, 1)) * quad::albedo(dv, wo).x;
    EXPECT_NEAR(mean, want, 4.0 * se + 2e-4) << mu;
  }
}

TEST(Clearcoat, DeltaBranchesAreTheUncoatedTimesOneMinusKPlusTheCoatMirror) {
  const vec3 n(0, 0, 1);
  const Basis f(n);
  const vec3 wo = f.world(1.1, 0.3);
  const double k = coat_k(0.75, wo, n);
  // Smooth metal under a smooth coat, both about n: one mirror, F_metal (1 - k) + k.
  const BsdfParams metal = coated(vec3(0.9f, 0.5f, 0.2f), 1.0f, 0.0f, 0.75f, 0.0f);
  SpecularBranch b[kMaxDeltaBranches], u[kMaxDeltaBranches];
  ASSERT_EQ(Bsdf(metal, n, n).delta_branches(wo, Transport::Radiance, b), 1);
  BsdfParams bare = metal;
  bare.clearcoat = 0.0f;
  ASSERT_EQ(Bsdf(bare, n, n).delta_branches(wo, Transport::Radiance, u), 1);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(b[0].weight[c], u[0].weight[c] * (1.0 - k) + k, 1e-6) << c;
  // Thin glass under a coat whose normal is tilted: reflection, transmission, the coat mirror.
  BsdfParams glass = coated(vec3(1.0f), 0.0f, 0.0f, 0.75f, 0.0f, 1.0f, 1.0f);
  const vec3 nc = glm::normalize(vec3(0.2f, 0.0f, 1.0f));
  glass.coat_normal = nc;
  const Bsdf coated_glass(glass, n, n);
  ASSERT_EQ(coated_glass.delta_branches(wo, Transport::Radiance, b), 3);
  glass.clearcoat = 0.0f;
  ASSERT_EQ(Bsdf(glass, n, n).delta_branches(wo, Transport::Radiance, u), 2);
  const double kc = coat_k(0.75, wo, nc);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(b[i].weight.x, u[i].weight.x * (1.0 - kc), 1e-6);
  EXPECT_NEAR(b[2].weight.x, kc, 1e-6);
  EXPECT_NEAR(glm::dot(b[2].dir, nc), glm::dot(wo, nc), 1e-6);  // a mirror about n_c
  EXPECT_LT(glm::length(glm::cross(b[2].dir + wo, nc)), 1e-5f);
  // White thin glass conserves: the three sum to 1 (Schlick's F + the rest, times 1 - k, + k).
  EXPECT_NEAR(b[0].weight.x + b[1].weight.x + b[2].weight.x, 1.0, 1e-5);
}

TEST(Clearcoat, FurnacesInClosedFormAndByQuadrature) {
  // Radiance albedo (mean weight of 2e5 draws, absorbed 0) at four views, against:
  //  - a smooth coat over a white Lambertian: k + (1 - k) x 1 = 1 exactly in expectation;
  //  - a smooth coat over black: k (the mirror's weight; the black base's draws weigh 0);
  //  - a rough coat (0.3) over black: k(wo) x the albedo of D V, which is a white metal's
  //    (Schlick's F of base colour 1 is 1), by quadrature;
  //  - photons under that rough coat: the integral of f(wi, wo) wi.z = integral of k(wi) D V
  //    wi.z, by the same quadrature with k(wi) inside.
  // Within 4 standard errors + 2e-4 (quadrature).
  const vec3 n(0, 0, 1);
  const Bsdf white(coated(vec3(1.0f), 0.0f, 1.0f, 1.0f, 0.0f, 0.0f), n, n);
  const Bsdf black(coated(vec3(0.0f), 0.0f, 1.0f, 0.9f, 0.0f, 0.0f), n, n);
  const Bsdf rough(coated(vec3(0.0f), 0.0f, 1.0f, 0.9f, 0.3f, 0.0f), n, n);
  MetalRoughBrdf dv;
  dv.base_color = vec3(1.0f);
  dv.metallic = 1.0f;
  dv.roughness = 0.3f;
  for (double mu : {1.0, 0.7, 0.4, 0.15}) {
    const vec3 wo = quad::at_cos(mu);
    Rng rng(406, uint64_t(mu * 100), 0, Stream::Test);
    auto albedo = [&](const Bsdf& b, Transport mode) {
      double sum = 0.0, sum2 = 0.0;
      const int count = 200000;
      for (int i = 0; i < count; ++i) {
        BsdfSample s;
        const double w = b.sample(wo, rng, mode, s) ? double(s.weight.x) : 0.0;
        sum += w;
        sum2 += w * w;
      }
      const double mean = sum / count;
      return std::pair(mean, std::sqrt(std::max(0.0, sum2 / count - mean * mean) / count));
    };
    const auto [w_mean, w_se] = albedo(white, Transport::Radiance);
    EXPECT_NEAR(w_mean, 1.0, 4.0 * w_se + 1e-6) << mu;
    const auto [b_mean, b_se] = albedo(black, Transport::Radiance);
    EXPECT_NEAR(b_mean, coat_k(0.9, wo, n), 4.0 * b_se + 1e-6) << mu;
    const double k = coat_k(0.9, wo, n);
    const double quad_r = k * quad::albedo(dv, wo).x;
    const auto [r_mean, r_se] = albedo(rough, Transport::Radiance);
    const double quad_i = quad::albedo_of(ggx_alpha(0.3f), wo, [&](const vec3& o, const vec3& i) {
                            return float(coat_k(0.9, i, n)) * dv.eval(o, i);
                          }).x;
    const auto [i_mean, i_se] = albedo(rough, Transport::Importance);
    std::printf(
        "mu %.2f: white %.5f +- %.5f, black %.5f (k %.5f), rough coat %.5f +- %.5f "
        "(quadrature %.5f), photons %.5f +- %.5f (quadrature %.5f)\n",
        mu, w_mean, w_se, b_mean, k, r_mean, r_se, quad_r, i_mean, i_se, quad_i);
    EXPECT_NEAR(r_mean, quad_r, 4.0 * r_se + 2e-4) << mu;
    EXPECT_NEAR(i_mean, quad_i, 4.0 * i_se + 2e-4) << mu;
  }
}

TEST(Clearcoat, ZeroCoatIsTheUncoatedMaterialBitForBit) {
  // clearcoatFactor 0 disables the layer: eval, pdf, max_f and draws are the uncoated ones.
  Rng rng(407, 0, 0, Stream::Test);
  for (int k = 0; k < 2000; ++k) {
    const vec3 n = random_unit(rng), wo = random_unit(rng), wi = random_unit(rng);
    BsdfParams p = coated(vec3(rng.next_float()), rng.next_float(), rng.next_float(), 0.0f, 0.3f);
    const Bsdf a(p, n, n);
    p.clearcoat_roughness = 0.0f;
    p.coat_normal = glm::normalize(n + vec3(0.1f));
    const Bsdf b(p, n, n);
    EXPECT_EQ(a.eval(wo, wi), b.eval(wo, wi));
    EXPECT_EQ(a.pdf(wo, wi), b.pdf(wo, wi));
    EXPECT_EQ(a.max_f(wo), b.max_f(wo));
    Rng r1(408, 0, uint64_t(k), Stream::Test), r2(408, 0, uint64_t(k), Stream::Test);
    BsdfSample s1, s2;
    ASSERT_EQ(a.sample(wo, r1, Transport::Importance, s1),
              b.sample(wo, r2, Transport::Importance, s2));
    EXPECT_EQ(s1.wi, s2.wi);
  }
}

TEST(Clearcoat, RestrictedKeepsItsTermsAndTheTermsSumToTheWhole) {
  // Bsdf::restricted, the general operation SPPM's split is made of: every term kept is the
  // Bsdf itself (bit for bit, delta branches and all); a restricted Bsdf has only the terms it
  // keeps (terms() within kept()), restricting twice keeps the intersection, and the four
  // terms of a rough coat over a rough dielectric with a sheen, each alone, sum to eval()
  // (relative 1e-5).
  BsdfParams p = coated(vec3(0.6f, 0.5f, 0.4f), 0.3f, 0.4f, 0.8f, 0.3f);
  p.sheen_color = vec3(0.5f);
  p.sheen_roughness = 0.5f;
  const vec3 n(0, 0, 1);
  const Bsdf bsdf(p, n, n);
  EXPECT_FALSE(bsdf.is_restricted());
  const TermSet has = bsdf.terms();
  for (Term t : {Term::Diffuse, Term::Lobe, Term::Coat, Term::Sheen}) EXPECT_TRUE(has.has(t));
  EXPECT_FALSE(has.has(Term::Glass));
  EXPECT_FALSE(has.has(Term::Transmission));
  const Bsdf same = bsdf.restricted(TermSet::all());
  EXPECT_FALSE(same.is_restricted());
  const TermSet diffuse_lobe = TermSet{}.with(Term::Diffuse).with(Term::Lobe);
  const Bsdf twice = bsdf.restricted(diffuse_lobe).restricted(TermSet{}.with(Term::Lobe));
  EXPECT_TRUE(twice.is_restricted());
  EXPECT_EQ(twice.kept(), TermSet{}.with(Term::Lobe));
  EXPECT_EQ(twice.terms(), TermSet{}.with(Term::Lobe));
  const Bsdf single[4] = {
      bsdf.restricted(TermSet{}.with(Term::Diffuse)), bsdf.restricted(TermSet{}.with(Term::Lobe)),
      bsdf.restricted(TermSet{}.with(Term::Coat)), bsdf.restricted(TermSet{}.with(Term::Sheen))};
  Rng rng(411, 0, 0, Stream::Test);
  for (int k = 0; k < 2000; ++k) {
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    if (glm::dot(wo, n) < 0.02f) continue;
    EXPECT_EQ(same.eval(wo, wi), bsdf.eval(wo, wi));
    EXPECT_EQ(same.pdf(wo, wi), bsdf.pdf(wo, wi));
    EXPECT_EQ(same.max_f(wo), bsdf.max_f(wo));
    vec3 sum(0.0f);
    for (const Bsdf& b : single) {
      EXPECT_FALSE(b.has_rough_glass());
      sum += b.eval(wo, wi);
    }
    const vec3 whole = bsdf.eval(wo, wi);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sum[ch], whole[ch], 1e-5f * whole[ch] + 1e-9f);
  }
}

}  // namespace
}  // namespace pb
