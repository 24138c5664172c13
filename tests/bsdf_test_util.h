// Helpers of the Bsdf tests (test_bsdf*.cpp): random directions, a frame of the test's own, the
// metal-rough parameters and MetalRoughBrdf of a BsdfParams, and the chi-square test of
// sample()'s directions.
#pragma once

#include "bsdf/bsdf.h"
#include "util/rng.h"

#include <gtest/gtest.h>
#include <boost/math/distributions/chi_squared.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace pb::test {

// Uniform on the unit sphere by rejection (the three numbers drawn in order).
inline vec3 random_unit(Rng& rng) {
  for (;;) {
    const float x = 2.0f * rng.next_float() - 1.0f, y = 2.0f * rng.next_float() - 1.0f,
                z = 2.0f * rng.next_float() - 1.0f;
    const vec3 v(x, y, z);
    const float l2 = glm::dot(v, v);
    if (l2 > 1e-4f && l2 <= 1.0f) return v / std::sqrt(l2);
  }
}

// A frame of its own (Gram-Schmidt from a fixed axis), not the Bsdf's.
struct Basis {
  vec3 t, b, n;
  explicit Basis(const vec3& normal) : n(normal) {
    const vec3 a = std::fabs(n.x) < 0.6f ? vec3(1, 0, 0) : vec3(0, 1, 0);
    t = glm::normalize(a - glm::dot(a, n) * n);
    b = glm::cross(n, t);
  }
  vec3 local(const vec3& w) const { return {glm::dot(w, t), glm::dot(w, b), glm::dot(w, n)}; }
  vec3 world(double theta, double phi) const {
    return glm::normalize(float(std::sin(theta) * std::cos(phi)) * t +
                          float(std::sin(theta) * std::sin(phi)) * b + float(std::cos(theta)) * n);
  }
};

// The parameters every test material starts from: glTF's metal-rough core, the rest as
// BsdfParams's defaults (each test file's builder sets its extension's).
inline BsdfParams metal_rough(vec3 base, float metallic, float roughness) {
  BsdfParams p;
  p.base_color = base;
  p.metallic = metallic;
  p.roughness = roughness;
  return p;
}

inline MetalRoughBrdf brdf_of(const BsdfParams& p) {
  MetalRoughBrdf m;
  m.base_color = p.base_color;
  m.metallic = p.metallic;
  m.roughness = p.roughness;
  m.ior = p.ior;
  m.specular = p.specular;
  m.specular_color = p.specular_color;
  return m;
}

// Chi-square of sample()'s directions against pdf() integrated over cells of the shading
// hemisphere of wo's side (cos theta in 16 equal bins, phi in 32), plus one cell for delta draws
// (expected: delta_probability) and one for absorbed draws (the rest). Cells expecting fewer
// than 5 are pooled.
struct ChiSquare {
  double statistic = 0.0, p_value = 1.0;
  int dof = 0;
};

inline ChiSquare chi_square(const Bsdf& bsdf, const vec3& wo, const vec3& ns_wo, int n, Rng& rng) {
  constexpr int kTheta = 16, kPhi = 32, kSub = 12;
  const Basis f(ns_wo);
  std::vector<double> observed(kTheta * kPhi + 2, 0.0), expected(kTheta * kPhi + 2, 0.0);
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    if (!bsdf.sample(wo, rng, Transport::Importance, s)) {
      observed[kTheta * kPhi + 1] += 1;
      continue;
    }
    if (s.delta) {
      observed[kTheta * kPhi] += 1;
      continue;
    }
    const vec3 l = f.local(s.wi);
    const double mu = std::clamp(double(l.z), 0.0, 1.0 - 1e-12);
    const double phi = std::atan2(double(l.y), double(l.x)) + kPiD;
    const int a = std::min(kTheta - 1, int((1.0 - mu) * kTheta));
    const int b = std::min(kPhi - 1, int(phi / (2 * kPiD) * kPhi));
    observed[a * kPhi + b] += 1;
  }
  double total = 0.0;
  for (int a = 0; a < kTheta; ++a) {
    for (int b = 0; b < kPhi; ++b) {
      // Midpoint rule on kSub^2 sub-cells in (mu, phi): d omega = d mu d phi.
      double sum = 0.0;
      for (int i = 0; i < kSub; ++i) {
        const double mu = 1.0 - (a + (i + 0.5) / kSub) / kTheta;
        for (int j = 0; j < kSub; ++j) {
          const double phi = (b + (j + 0.5) / kSub) / kPhi * 2 * kPiD - kPiD;
          sum += bsdf.pdf(wo, f.world(std::acos(mu), phi));
        }
      }
      const double cell = (1.0 / kTheta) * (2 * kPiD / kPhi) / (kSub * kSub);
      expected[a * kPhi + b] = n * sum * cell;
      total += sum * cell;
    }
  }
  const double pd = bsdf.delta_probability(wo);
  expected[kTheta * kPhi] = n * pd;
  expected[kTheta * kPhi + 1] = std::max(0.0, n * (1.0 - pd - total));
  ChiSquare r;
  double pooled_o = 0.0, pooled_e = 0.0;
  int cells = 0;
  for (size_t k = 0; k < expected.size(); ++k) {
    if (expected[k] < 5.0) {
      pooled_o += observed[k];
      pooled_e += expected[k];
      continue;
    }
    r.statistic += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++cells;
  }
  if (pooled_e >= 5.0) {
    r.statistic += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
    ++cells;
  } else if (pooled_o > 5.0 + 10.0 * pooled_e) {
    r.statistic += 1e9;  // draws where the density says there are none
  }
  r.dof = cells - 1;
  r.p_value = boost::math::cdf(boost::math::complement(
      boost::math::chi_squared_distribution<double>(std::max(1, r.dof)), r.statistic));
  return r;
}

// A continuous draw agrees with the density and value the Bsdf reports for the same direction:
// pdf = pdf(wo, wi) and weight = f |wi.ns| / pdf (pbrt-v4's sampling contract), f = f(wo, wi)
// for radiance and the adjoint f(wi, wo) for photons; relative 2e-3 (the sampled direction is
// rounded through the shading frame).
inline void expect_sample_matches_eval(const Bsdf& bsdf, const vec3& wo, const BsdfSample& s,
                                       const vec3& ns, const char* name,
                                       Transport mode = Transport::Radiance) {
  const float pdf = bsdf.pdf(wo, s.wi);
  const vec3 f = mode == Transport::Radiance ? bsdf.eval(wo, s.wi) : bsdf.eval(s.wi, wo);
  const float cos = std::fabs(glm::dot(s.wi, ns));
  EXPECT_NEAR(s.pdf, pdf, 2e-3f * pdf) << name;
  for (int ch = 0; ch < 3; ++ch)
    EXPECT_NEAR(s.weight[ch], f[ch] * cos / pdf, 2e-3f * s.weight[ch] + 1e-6f) << name;
}

// A delta draw leaves along one of the Bsdf's delta branches.
inline bool leaves_along_a_branch(const Bsdf& bsdf, const vec3& wo, Transport mode,
                                  const BsdfSample& s) {
  SpecularBranch b[kMaxDeltaBranches];
  const int nb = bsdf.delta_branches(wo, mode, b);
  bool found = false;
  for (int i = 0; i < nb; ++i) found |= glm::length(b[i].dir - s.wi) < 1e-6f;
  return found;
}

// chi_square at views theta (radians, azimuth 0.7 about ns), `draws` draws each (2e5 unless
// told), seeded by `seed` and theta: each p-value above `min_p` (1e-4 unless told; the callers'
// comments give the family-wise rates).
inline void expect_draws_follow_the_pdf(const Bsdf& bsdf, const vec3& ns,
                                        const std::vector<double>& thetas, uint64_t seed,
                                        const char* name, int draws = 200000, double min_p = 1e-4) {
  const Basis f(ns);
  for (double theta : thetas) {
    Rng rng(seed, uint64_t(theta * 10), 0, Stream::Test);
    const double pv = chi_square(bsdf, f.world(theta, 0.7), ns, draws, rng).p_value;
    std::printf("%-36s theta %.2f: p = %.3g\n", name, theta, pv);
    EXPECT_GT(pv, min_p) << name << " theta " << theta;
  }
}

// ng and a shading normal tilted from it by up to ~0.3 rad (the three numbers of two
// random_unit draws, in order).
inline void random_normals(Rng& rng, vec3& ng, vec3& ns) {
  ng = random_unit(rng);
  ns = glm::normalize(ng + 0.3f * random_unit(rng));
  if (glm::dot(ns, ng) < 0.2f) ns = ng;
}

// The same with a coat normal, tilted from ng by up to ~0.3 rad as well (drawn after ns).
inline void random_normals(Rng& rng, vec3& ng, vec3& ns, vec3& nc) {
  random_normals(rng, ng, ns);
  nc = glm::normalize(ng + 0.3f * random_unit(rng));
  if (glm::dot(nc, ng) < 0.2f) nc = ng;
}

// The draws of sample() for a Bsdf with normal +z, seen from wo, binned over the whole sphere
// in 12 x 8 bins of (cos theta, phi): each bin's mean weight (channel `channel`, absorbed draws
// 0) estimates the integral of f |cos| over the bin, which `f` (the definition, written out by
// the caller for n = +z) gives by a 24 x 24 midpoint rule per bin. Within 4.5 standard errors
// plus 1% of the bin (the quadrature near a lobe's peak) in every bin, so the draws are
// unbiased wherever they go: with 96 bins a false alarm has probability below 1e-3 per call.
template <class Definition>
void expect_draws_integrate_to(const Bsdf& b, const vec3& wo, Transport mode, int channel,
                               Definition&& f, Rng& rng, const std::string& name,
                               int draws = 300000) {
  constexpr int kCos = 12, kPhi = 8, kQ = 24;
  std::vector<double> sum(kCos * kPhi, 0.0), sum2(kCos * kPhi, 0.0);
  for (int i = 0; i < draws; ++i) {
    BsdfSample s;
    if (!b.sample(wo, rng, mode, s)) continue;
    ASSERT_FALSE(s.delta) << name;
    const int ci = std::clamp(int((s.wi.z + 1.0f) / 2.0f * kCos), 0, kCos - 1);
    const float phi = std::atan2(s.wi.y, s.wi.x) + float(M_PI);
    const int pi = std::clamp(int(phi / float(2.0 * M_PI) * kPhi), 0, kPhi - 1);
    const double w = s.weight[channel];
    sum[size_t(ci * kPhi + pi)] += w;
    sum2[size_t(ci * kPhi + pi)] += w * w;
  }
  for (int ci = 0; ci < kCos; ++ci)
    for (int pi = 0; pi < kPhi; ++pi) {
      double want = 0.0;
      for (int a = 0; a < kQ; ++a)
        for (int c = 0; c < kQ; ++c) {
          const double z = -1.0 + (ci + (a + 0.5) / kQ) * 2.0 / kCos;
          const double phi = -M_PI + (pi + (c + 0.5) / kQ) * 2.0 * M_PI / kPhi;
          const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
          want += f(glm::dvec3(wo), glm::dvec3(r * std::cos(phi), r * std::sin(phi), z))[channel] *
                  std::fabs(z);
        }
      want *= (2.0 / kCos / kQ) * (2.0 * M_PI / kPhi / kQ);
      const size_t j = size_t(ci * kPhi + pi);
      const double mean = sum[j] / draws;
      const double se = std::sqrt(std::max(0.0, sum2[j] / draws - mean * mean) / draws);
      EXPECT_NEAR(mean, want, 4.5 * se + 0.01 * want + 1e-6) << name << " bin " << ci << "," << pi;
    }
}

}  // namespace pb::test
