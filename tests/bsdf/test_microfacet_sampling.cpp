// MetalRoughBrdf::sample against pdf() and eval(): chi-square goodness of fit of the sampled
// directions against the density integrated over bins, the sample weights against
// eval cos / pdf (and, for a white metal, against G2 / G1), and the Monte Carlo
// albedo from the weights against the deterministic quadrature of microfacet_quadrature.h.
#include "bsdf/microfacet.h"
#include "util/rng.h"

#include "microfacet_quadrature.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace pb {
namespace {

using quad::at_cos;

// ---------------------------------------------------------------------------------------------
// Chi-square

// Bin edges on [lo, hi]: `uniform` equal bins, plus edges at centre +- width 2^k (k >= -2)
// so that a peak of that width at centre is split into bins of every scale around it.
std::vector<double> clustered_edges(double lo, double hi, double centre, double width,
                                    int uniform) {
  std::vector<double> e;
  for (int k = 0; k <= uniform; ++k) e.push_back(lo + (hi - lo) * k / uniform);
  for (double d = width / 4; d < hi - lo; d *= 2) {
    for (double x : {centre - d, centre + d}) {
      if (x > lo && x < hi) e.push_back(x);
    }
  }
  if (centre > lo && centre < hi) e.push_back(centre);
  std::sort(e.begin(), e.end());
  std::vector<double> out{e.front()};
  for (double x : e) {
    if (x - out.back() > 1e-9) out.push_back(x);
  }
  out.back() = hi;
  return out;
}

// Directions are binned by polar angle theta and by azimuth phi' measured from the mirror
// direction of wo (wo lies in the xz-plane, x >= 0, so the mirror azimuth is pi).
vec3 direction(double theta, double phi_rel) {
  return vec3(float(-std::sin(theta) * std::cos(phi_rel)),
              float(-std::sin(theta) * std::sin(phi_rel)), float(std::cos(theta)));
}

// Integral of pdf(wo, wi) sin(theta) over a (theta, phi') cell: 4x4 Gauss-Legendre, split into
// four until the split changes the result by less than 1e-8 (absolute probability) plus 1e-4
// relative. A bin of probability p has Poisson noise sqrt(p / n) relative to n, i.e. 5e-5 for
// p = 1e-3 and n = 4e5, so these errors add less than 1e-3 to its chi-square term. Tighter
// tolerances only chase the float rounding of pdf() near a narrow peak.
double cell_probability(const MetalRoughBrdf& m, const vec3& wo, double t0, double t1, double p0,
                        double p1, int depth = 0) {
  static constexpr double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                  0.8611363115940526};
  static constexpr double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                  0.3478548451374538};
  auto gl = [&](double a0, double a1, double b0, double b1) {
    double s = 0.0;
    for (int i = 0; i < 4; ++i) {
      const double t = 0.5 * (a0 + a1) + 0.5 * (a1 - a0) * x[i];
      for (int j = 0; j < 4; ++j) {
        const double p = 0.5 * (b0 + b1) + 0.5 * (b1 - b0) * x[j];
        s += w[i] * w[j] * m.pdf(wo, direction(t, p)) * std::sin(t);
      }
    }
    return s * 0.25 * (a1 - a0) * (b1 - b0);
  };
  const double tm = 0.5 * (t0 + t1), pm = 0.5 * (p0 + p1);
  const double whole = gl(t0, t1, p0, p1);
  const double split =
      gl(t0, tm, p0, pm) + gl(tm, t1, p0, pm) + gl(t0, tm, pm, p1) + gl(tm, t1, pm, p1);
  if (depth >= 6 || std::fabs(whole - split) <= 1e-8 + 1e-4 * split) return split;
  return cell_probability(m, wo, t0, tm, p0, pm, depth + 1) +
         cell_probability(m, wo, tm, t1, p0, pm, depth + 1) +
         cell_probability(m, wo, t0, tm, pm, p1, depth + 1) +
         cell_probability(m, wo, tm, t1, pm, p1, depth + 1);
}

struct ChiSquare {
  double statistic = 0.0;
  int dof = 0;
  double p_value = 0.0;
};

// Draws n samples from wo and compares the counts per bin with n times the probability of the
// bin, bins with expected count < 5 pooled into one (Cochran's rule), plus one bin for failed
// samples, expected n (1 - integral of pdf over the hemisphere).
ChiSquare chi_square(const MetalRoughBrdf& m, const vec3& wo, int n, uint64_t seed) {
  const double theta_o = std::acos(double(wo.z));
  // The reflected lobe's angular radius: 2 alpha in the plane of incidence (wi turns twice as
  // fast as h), 2 alpha (wo.h) ~ 2 alpha wo.z across it, which is alpha_out / sin(theta) in
  // azimuth.
  const double alpha = ggx_alpha(m.roughness);
  const double width = 2.0 * alpha, width_out = 2.0 * alpha * std::max(double(wo.z), alpha);
  const std::vector<double> te = clustered_edges(0.0, kPiD / 2, theta_o, width, 18);
  const double phi_width = std::min(kPiD, width_out / std::max(std::sin(theta_o), 1e-9));
  const std::vector<double> pe = clustered_edges(-kPiD, kPiD, 0.0, phi_width, 24);
  const size_t nt = te.size() - 1, np = pe.size() - 1;
  std::vector<double> observed(nt * np + 1, 0.0);  // last: failed samples
  Rng rng(seed, 0, 0, Stream::Test);
  for (int k = 0; k < n; ++k) {
    vec3 wi, weight;
    float pdf;
    const float ul = rng.next_float(), u1 = rng.next_float(), u2 = rng.next_float();
    if (!m.sample(wo, ul, u1, u2, wi, weight, pdf)) {
      observed.back() += 1;
      continue;
    }
    const double theta = std::atan2(std::hypot(double(wi.x), double(wi.y)), double(wi.z));
    const double phi = std::atan2(-double(wi.y), -double(wi.x));
    const size_t i =
        std::min<size_t>(std::upper_bound(te.begin(), te.end(), theta) - te.begin() - 1, nt - 1);
    const size_t j =
        std::min<size_t>(std::upper_bound(pe.begin(), pe.end(), phi) - pe.begin() - 1, np - 1);
    observed[i * np + j] += 1;
  }
  std::vector<double> expected(nt * np + 1, 0.0);
  double total = 0.0;
  for (size_t i = 0; i < nt; ++i) {
    for (size_t j = 0; j < np; ++j) {
      expected[i * np + j] = n * cell_probability(m, wo, te[i], te[i + 1], pe[j], pe[j + 1]);
      total += expected[i * np + j];
    }
  }
  expected.back() = std::max(0.0, n - total);
  ChiSquare out;
  double pooled_e = 0.0, pooled_o = 0.0;
  int bins = 0;
  for (size_t b = 0; b < expected.size(); ++b) {
    if (expected[b] < 5.0) {
      pooled_e += expected[b];
      pooled_o += observed[b];
      continue;
    }
    out.statistic += (observed[b] - expected[b]) * (observed[b] - expected[b]) / expected[b];
    ++bins;
  }
  if (pooled_e > 0.0) {
    out.statistic += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
    ++bins;
  } else if (pooled_o > 0.0) {
    out.statistic = INFINITY;  // samples where the density says there are none
  }
  out.dof = bins - 1;
  const boost::math::chi_squared dist(out.dof);
  out.p_value =
      std::isfinite(out.statistic) ? boost::math::cdf(complement(dist, out.statistic)) : 0.0;
  return out;
}

// The cases below: six materials x four views = 24 chi-square tests. Each is rejected at
// p < 1e-3 / 24 (Bonferroni), so a correct sampler fails any of them with probability < 1e-3;
// 400k samples resolve a 2% error in a lobe holding 5% of the samples at that level.
constexpr int kChiSquareTests = 24;
constexpr double kRejectP = 1e-3 / kChiSquareTests;
constexpr int kSamples = 400000;

// Views at 0, 45.6, 75 and 89.94 degrees.
void expect_fit(const MetalRoughBrdf& m, uint64_t seed,
                std::initializer_list<double> views = {1.0, 0.7, 0.26, 1e-3}) {
  for (double mu : views) {
    const vec3 wo = at_cos(mu);
    const ChiSquare c = chi_square(m, wo, kSamples, seed++);
    std::printf(
        "  roughness %.2f metallic %.1f base %.2f wo.z %.3f p_spec %.3f: chi2 %.1f, dof %d, p "
        "%.3g\n",
        m.roughness, m.metallic, m.base_color.x, mu, m.specular_probability(wo), c.statistic, c.dof,
        c.p_value);
    EXPECT_GT(c.p_value, kRejectP) << "chi2=" << c.statistic << " dof=" << c.dof << " wo.z=" << mu;
    EXPECT_GT(c.dof, 20);  // the bins resolve the distribution
  }
}

TEST(MetalRoughSampling, ChiSquareDiffuseDominated) {
  expect_fit(MetalRoughBrdf{vec3(0.8f, 0.7f, 0.6f), 0.0f, 0.5f}, 301);
}

TEST(MetalRoughSampling, ChiSquareSpecularDominatedDielectric) {
  expect_fit(MetalRoughBrdf{vec3(0.02f), 0.0f, 0.15f}, 311);
}

TEST(MetalRoughSampling, ChiSquareMetal) {
  expect_fit(MetalRoughBrdf{vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.3f}, 321);
}

TEST(MetalRoughSampling, ChiSquareRoughMixture) {
  expect_fit(MetalRoughBrdf{vec3(0.5f), 0.5f, 1.0f}, 331);
}

TEST(MetalRoughSampling, ChiSquareSmoothMetal) {
  expect_fit(MetalRoughBrdf{vec3(0.95f), 1.0f, 0.05f}, 341);
}

TEST(MetalRoughSampling, ChiSquareMinimumRoughnessMixture) {
  // Views down to wo.z = 0.01 only: alpha wo.z >= 1e-6 (microfacet.h, kMinGgxAlpha).
  expect_fit(MetalRoughBrdf{vec3(0.7f), 0.3f, 0.0f}, 351, {1.0, 0.7, 0.1, 0.01});
}

TEST(MetalRoughSampling, FloatDirectionsCannotResolveTheLobeBelowTheLimit) {
  // The limit documented at kMinGgxAlpha: at alpha = 1e-4 and wo.z = 1e-3 the reflected lobe is
  // 2 alpha wo.z = 2e-7 radians wide across the plane of incidence, three float spacings, and
  // the sampled directions no longer follow pdf() (measured p ~ 1e-200). Should this pass one
  // day, the documented limit can be relaxed.
  const MetalRoughBrdf m{vec3(0.7f), 0.3f, 0.0f};
  EXPECT_LT(chi_square(m, at_cos(1e-3), kSamples, 359).p_value, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// Weights

TEST(MetalRoughSampling, WeightIsEvalCosOverPdf) {
  // weight = eval cos / pdf and pdf = pdf(wo, wi), relative 1e-4 (float). For a white metal
  // (F = 1) a visible-normal sample weighs V D wi.z / (D / (2 (wo.z + s_o))) = G2(wo, wi) /
  // G1(wo), which the Smith functions give independently of D and of the mixture: 1e-4.
  Rng rng(361, 0, 0, Stream::Test);
  int checked = 0;
  for (int k = 0; k < 50000; ++k) {
    MetalRoughBrdf m;
    m.base_color = vec3(rng.next_float(), rng.next_float(), rng.next_float());
    m.metallic = rng.next_float();
    m.roughness = rng.next_float();
    const vec3 wo = at_cos(k % 10 == 0 ? 1e-3 : rng.next_double());
    vec3 wi, weight;
    float pdf;
    if (!m.sample(wo, rng.next_float(), rng.next_float(), rng.next_float(), wi, weight, pdf))
      continue;
    ++checked;
    const float p = m.pdf(wo, wi);
    ASSERT_NEAR(pdf, p, 1e-4f * p) << "k=" << k;
    const vec3 ref = m.eval(wo, wi) * wi.z / p;
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(weight[c], ref[c], 1e-4f * ref[c] + 1e-12f) << k;

    const MetalRoughBrdf white{vec3(1.0f), 1.0f, m.roughness};
    if (!white.sample(wo, 0.0f, rng.next_float(), rng.next_float(), wi, weight, pdf)) continue;
    const float a = ggx_alpha(m.roughness);
    const float g = smith_g2(wo, wi, a) / smith_g1(wo, a);
    ASSERT_NEAR(weight.x, g, 1e-4f * g) << "k=" << k;
    ASSERT_LE(weight.x, 1.0f + 1e-5f);
  }
  EXPECT_GT(checked, 45000);
}

TEST(MetalRoughSampling, MonteCarloAlbedoMatchesQuadrature) {
  // The mean sample weight (failed samples count 0) estimates the albedo. Tolerance: 5 standard
  // errors of that mean plus 2e-4 for the quadrature, or 1e-3 at the minimum roughness and
  // grazing, where float directions resolve the lobe only to ~1e-3 (test_microfacet.cpp).
  struct Case {
    MetalRoughBrdf m;
    double mu;
  };
  const std::vector<Case> cases = {
      {{vec3(1.0f), 1.0f, 1.0f}, 1.0},
      {{vec3(1.0f), 1.0f, 1.0f}, 1e-3},
      {{vec3(1.0f), 1.0f, 0.3f}, 0.5},
      {{vec3(1.0f), 1.0f, 0.05f}, 0.05},
      {{vec3(0.8f, 0.5f, 0.1f), 0.0f, 0.5f}, 0.8},
      {{vec3(0.8f, 0.5f, 0.1f), 0.0f, 0.5f}, 1e-3},
      {{vec3(1.0f), 0.0f, 0.05f}, 0.3},
      {{vec3(0.3f, 0.9f, 0.6f), 0.6f, 0.2f}, 0.6},
      {{vec3(0.7f), 0.3f, 0.0f}, 0.9},
      {{vec3(0.7f), 0.3f, 0.0f}, 0.02},
  };
  uint64_t seed = 371;
  const int n = 200000;
  for (const Case& c : cases) {
    const vec3 wo = at_cos(c.mu);
    const dvec3 exact = quad::albedo(c.m, wo);
    Rng rng(seed++, 0, 0, Stream::Test);
    dvec3 sum(0.0), sum2(0.0);
    for (int k = 0; k < n; ++k) {
      vec3 wi, weight;
      float pdf;
      if (!c.m.sample(wo, rng.next_float(), rng.next_float(), rng.next_float(), wi, weight, pdf))
        continue;
      sum += dvec3(weight);
      sum2 += dvec3(weight) * dvec3(weight);
    }
    const dvec3 mean = sum / double(n);
    const dvec3 se =
        glm::sqrt(glm::max(sum2 / double(n) - mean * mean, dvec3(0.0)) / double(n - 1));
    const double quad_tol = c.m.roughness < 0.03f && c.mu <= 0.02 ? 1e-3 : 2e-4;
    std::printf("  roughness %.2f metallic %.1f wo.z %.3f: MC %.5f +- %.5f, quadrature %.5f\n",
                c.m.roughness, c.m.metallic, c.mu, mean.x, se.x, exact.x);
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_NEAR(mean[ch], exact[ch], 5.0 * se[ch] + quad_tol)
          << "roughness=" << c.m.roughness << " metallic=" << c.m.metallic << " mu=" << c.mu;
    }
  }
}

}  // namespace
}  // namespace pb
