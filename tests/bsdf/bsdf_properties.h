// The Bsdf property suite: one parameterised test per property every material should have,
// over a registry of named Bsdf constructions (BsdfCase). Each extension's test file
// (test_bsdf_gltf.cpp: Lambertian and glTF's metal-rough; _clearcoat, _sheen, _iridescence,
// _anisotropy, _rough_glass, _diffuse_transmission, _dispersion) builds its cases and registers
// them with PB_BSDF_PROPERTY_CASES(Extension, its_cases()); its own tests keep only what is
// particular to the extension. The properties (Property), each its own fixture:
//  - BsdfSampling.SampleWeightIsEvalCosOverPdf: pbrt-v4's sampling contract, per draw (both
//    transport directions; expect_sample_matches_eval), delta draws leave along a branch,
//    weights finite;
//  - BsdfChiSquare.SampledDirectionsFollowThePdf: the directions against pdf() (chi_square);
//  - BsdfReciprocity.EvalIsReciprocal: f(wo, wi) = f(wi, wo);
//  - BsdfEnergy.AlbedoAtMostOne: the mean weight of radiance draws from outside is at most 1.
// A property runs over the cases it applies to: a case excludes one with BsdfCase::exclude and
// a one-line reason, in the case's definition; nothing is instantiated to skip.
// Included by the extensions' test files alone (one executable each: the suite runs in each
// with that file's cases).
#pragma once

#include "bsdf/bsdf.h"
#include "util/rng.h"

#include "bsdf_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace pb::test {

// The properties of the suite, one fixture each (below).
enum class Property { Sampling, ChiSquare, Reciprocity, Energy };

// One named Bsdf construction and how the suite checks it.
struct BsdfCase {
  std::string name;
  BsdfParams params;
  // Every continuous draw is described by eval() and pdf() (the sampling contract and the
  // chi-square test). Not so for rough glass and diffuse transmission, whose draws through the
  // surface eval() and pdf() do not return (their files bin the draws against the definition:
  // expect_draws_integrate_to); for them the per-draw test checks weights and branches alone,
  // and the chi-square test is excluded.
  bool contract = true;
  // The properties that do not apply, each with its reason (exclude).
  std::vector<std::pair<Property, std::string>> excluded;
  // The coat normal: drawn beside ng for every draw of the per-draw tests (random_normals), and
  // chi_nc in the chi-square test (zero: ns).
  bool tilt_coat_normal = false;
  // Out of 20000 draws, more than this many continuous and delta draws (0: not checked).
  int min_continuous = 1000, min_delta = 0;
  // The per-draw tests' generator: Rng(seed, index, test) with index the case's place in its
  // extension's list (the first case's stream of the sampling contract is the one its file used
  // before the suite; the later ones then continued that one generator).
  uint64_t seed = 0, index = 0;
  // The chi-square test (no thetas: not run): views, seed, draws, the smallest p-value passed,
  // and the geometry.
  std::vector<double> chi_thetas;
  uint64_t chi_seed = 0;
  int chi_draws = 200000;
  double chi_min_p = 1e-4;
  vec3 chi_ng = glm::normalize(vec3(0.1f, -0.2f, 1.0f));
  vec3 chi_ns = glm::normalize(vec3(0.25f, -0.1f, 1.0f));
  vec3 chi_nc{0.0f};
  // The largest albedo allowed (AlbedoAtMostOne): 1 unless the case's comment justifies more.
  double albedo_max = 1.0;

  // Leaves property `p` out for this case: `why`, one line, says why it does not apply.
  BsdfCase& exclude(Property p, std::string why) {
    excluded.emplace_back(p, std::move(why));
    return *this;
  }
  bool applies(Property p) const {
    return std::none_of(excluded.begin(), excluded.end(),
                        [p](const auto& e) { return e.first == p; });
  }
};

// The cases property `p` applies to, in their order (seeds are the cases' own: index stays).
inline std::vector<BsdfCase> cases_for(const std::vector<BsdfCase>& cases, Property p) {
  std::vector<BsdfCase> out;
  for (const BsdfCase& c : cases)
    if (c.applies(p)) out.push_back(c);
  return out;
}

// gtest prints a case by its name.
inline void PrintTo(const BsdfCase& c, std::ostream* os) { *os << c.name; }

// Cases of one extension from (name, params) pairs: seed and index set, the chi-square test at
// `thetas` seeded by chi_seed; the rest as BsdfCase's defaults (the caller adjusts them).
inline std::vector<BsdfCase> cases_of(std::vector<std::pair<std::string, BsdfParams>> list,
                                      uint64_t seed, uint64_t chi_seed,
                                      std::vector<double> thetas = {0.4, 1.3}) {
  std::vector<BsdfCase> out;
  for (auto& [name, params] : list) {
    BsdfCase c;
    c.name = name;
    c.params = params;
    c.seed = seed;
    c.index = out.size();
    c.chi_seed = chi_seed;
    c.chi_thetas = thetas;
    out.push_back(c);
  }
  return out;
}

// gtest's name of a case: its name with every other character than a letter or digit as '_'.
inline std::string case_test_name(const testing::TestParamInfo<BsdfCase>& info) {
  std::string s = info.param.name;
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

// One fixture per property, so that each is instantiated over the cases it applies to alone.
class BsdfSampling : public testing::TestWithParam<BsdfCase> {};
class BsdfChiSquare : public testing::TestWithParam<BsdfCase> {};
class BsdfReciprocity : public testing::TestWithParam<BsdfCase> {};
class BsdfEnergy : public testing::TestWithParam<BsdfCase> {};

// An extension whose cases all exclude a property instantiates it over no case: allowed (the
// macro below instantiates every fixture, so an empty list is the only way to none).
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(BsdfSampling);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(BsdfChiSquare);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(BsdfReciprocity);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(BsdfEnergy);

TEST_P(BsdfSampling, SampleWeightIsEvalCosOverPdf) {
  // 20000 views from random normals (a shading normal tilted from ng), wo at least 0.02 above
  // the shading hemisphere, radiance and photons alternately. Continuous draws: pdf = pdf(wo, wi)
  // and weight = f |wi.ns| / pdf, f(wo, wi) for radiance and f(wi, wo) for photons, relative
  // 2e-3 (expect_sample_matches_eval); delta draws leave along a branch.
  const BsdfCase& c = GetParam();
  Rng rng(c.seed, c.index, 0, Stream::Test);
  int continuous = 0, delta = 0;
  for (int k = 0; k < 20000; ++k) {
    vec3 ng, ns, nc;
    BsdfParams p = c.params;
    if (c.tilt_coat_normal) {
      random_normals(rng, ng, ns, nc);
      p.coat_normal = nc;
    } else {
      random_normals(rng, ng, ns);
    }
    const Bsdf bsdf(p, ng, ns);
    const vec3 wo = random_unit(rng);
    if (glm::dot(wo, glm::dot(wo, ng) > 0.0f ? ns : -ns) < 0.02f) continue;
    const Transport mode = k % 2 ? Transport::Radiance : Transport::Importance;
    BsdfSample s;
    if (!bsdf.sample(wo, rng, mode, s)) continue;
    ASSERT_TRUE(is_finite(s.weight)) << c.name;
    if (s.delta) {
      EXPECT_TRUE(leaves_along_a_branch(bsdf, wo, mode, s)) << c.name;
      ++delta;
      continue;
    }
    if (c.contract) expect_sample_matches_eval(bsdf, wo, s, ns, c.name.c_str(), mode);
    ++continuous;
  }
  if (c.min_continuous > 0) EXPECT_GT(continuous, c.min_continuous) << c.name;
  if (c.min_delta > 0) EXPECT_GT(delta, c.min_delta) << c.name;
}

TEST_P(BsdfChiSquare, SampledDirectionsFollowThePdf) {
  // chi_square at each view (expect_draws_follow_the_pdf); each extension's registration says
  // the family-wise false-alarm rate of its cases.
  const BsdfCase& c = GetParam();
  ASSERT_TRUE(c.contract && !c.chi_thetas.empty())
      << c.name << ": no density of every draw, or no views: exclude Property::ChiSquare";
  BsdfParams p = c.params;
  if (c.chi_nc != vec3(0.0f)) p.coat_normal = c.chi_nc;
  const Bsdf bsdf(p, c.chi_ng, c.chi_ns);
  expect_draws_follow_the_pdf(bsdf, c.chi_ns, c.chi_thetas, c.chi_seed, c.name.c_str(), c.chi_draws,
                              c.chi_min_p);
}

TEST_P(BsdfReciprocity, EvalIsReciprocal) {
  // f(wo, wi) = f(wi, wo) for 5000 random pairs on random normals: relative 1e-5 (the two
  // orders round differently, as GltfBsdf.ReciprocalInWorldSpace allows) + 1e-9 absolute.
  const BsdfCase& c = GetParam();
  Rng rng(c.seed, c.index, 1, Stream::Test);
  for (int k = 0; k < 5000; ++k) {
    vec3 ng, ns;
    random_normals(rng, ng, ns);
    const Bsdf bsdf(c.params, ng, ns);
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    const vec3 a = bsdf.eval(wo, wi), b = bsdf.eval(wi, wo);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a[ch], b[ch], 1e-5f * a[ch] + 1e-9f) << c.name << k;
  }
}

TEST_P(BsdfEnergy, AlbedoAtMostOne) {
  // Energy: the mean radiance weight of 20000 draws (absorbed draws 0; both sides and delta
  // branches counted) estimates the albedo, which single scattering keeps at or below 1, per
  // channel, at views of cosine 0.9, 0.5 and 0.15 from outside (n = +z; through a volume from
  // outside the radiance factor 1/eta^2 is below 1). Tolerance: 4 standard errors (a one-sided
  // false alarm about 3e-5 per view where the albedo is 1, at a fixed seed) + 1e-4 for the
  // float weights of a white case (its weights round about 1).
  const BsdfCase& c = GetParam();
  const vec3 n(0, 0, 1);
  const Bsdf bsdf(c.params, n, n);
  Rng rng(c.seed, c.index, 2, Stream::Test);
  for (double mu : {0.9, 0.5, 0.15}) {
    const vec3 wo(float(std::sqrt(1.0 - mu * mu)), 0.0f, float(mu));
    const int count = 20000;
    glm::dvec3 sum(0.0), sum2(0.0);
    for (int i = 0; i < count; ++i) {
      BsdfSample s;
      if (!bsdf.sample(wo, rng, Transport::Radiance, s)) continue;
      const glm::dvec3 w(s.weight);
      sum += w;
      sum2 += w * w;
    }
    for (int ch = 0; ch < 3; ++ch) {
      const double mean = sum[ch] / count;
      const double se = std::sqrt(std::max(0.0, sum2[ch] / count - mean * mean) / count);
      EXPECT_LE(mean, c.albedo_max + 4.0 * se + 1e-4)
          << c.name << " mu " << mu << " channel " << ch;
    }
  }
}

}  // namespace pb::test

// Registers an extension's cases (a std::vector<BsdfCase>) with the suite: each property over
// the cases it applies to, as Extension/BsdfSampling.SampleWeightIsEvalCosOverPdf/case_name and
// likewise. Used at namespace scope (it declares the fixtures' names there).
#define PB_BSDF_PROPERTY_CASES(Extension, cases)                    \
  using ::pb::test::BsdfSampling;                                   \
  using ::pb::test::BsdfChiSquare;                                  \
  using ::pb::test::BsdfReciprocity;                                \
  using ::pb::test::BsdfEnergy;                                     \
  PB_BSDF_PROPERTY(Extension, BsdfSampling, cases, Sampling);       \
  PB_BSDF_PROPERTY(Extension, BsdfChiSquare, cases, ChiSquare);     \
  PB_BSDF_PROPERTY(Extension, BsdfReciprocity, cases, Reciprocity); \
  PB_BSDF_PROPERTY(Extension, BsdfEnergy, cases, Energy)

// One property's instantiation over the cases it applies to.
#define PB_BSDF_PROPERTY(Extension, Fixture, cases, property)                            \
  INSTANTIATE_TEST_SUITE_P(                                                              \
      Extension, Fixture,                                                                \
      ::testing::ValuesIn(::pb::test::cases_for(cases, ::pb::test::Property::property)), \
      ::pb::test::case_test_name)
