// The GGX / Smith / Schlick pieces of microfacet.h against formulas written out independently
// here in double, their normalisations by deterministic quadrature (microfacet_quadrature.h),
// white-furnace albedos of the metal lobe (with an analytic value), what glTF's coupling of
// diffuse and specular does to energy, reciprocity, and inputs at the edges.
#include "bsdf/microfacet.h"
#include "util/rng.h"

#include "microfacet_quadrature.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace pb {
namespace {

using quad::at_cos;
using quad::at_theta;

// A direction on the upper hemisphere: cosine uniform, or (grazing) 10^-U(0, 8).
vec3 random_upper(Rng& rng, bool grazing = false) {
  const double z = grazing ? std::pow(10.0, -8.0 * rng.next_double()) : rng.next_double();
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2 * kPiD * rng.next_double();
  return vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(std::max(z, 1e-30)));
}

MetalRoughBrdf random_material(Rng& rng) {
  MetalRoughBrdf m;
  m.base_color = vec3(rng.next_float(), rng.next_float(), rng.next_float());
  m.metallic = rng.next_float() < 0.2f ? float(rng.next_u32() & 1) : rng.next_float();
  m.roughness = rng.next_float() < 0.1f ? 0.0f : rng.next_float();
  m.ior = 1.0f + 1.5f * rng.next_float();
  return m;
}

// ---------------------------------------------------------------------------------------------
// The pieces against their textbook forms

TEST(Microfacet, GgxDMatchesWalterFormInDouble) {
  // Walter et al. 2007, eq. 33: alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2), in double at the same
  // float h. The float form has a handful of roundings: relative 1e-5.
  Rng rng(201, 0, 0, Stream::Test);
  for (float alpha : {kMinGgxAlpha, 1e-3f, 0.01f, 0.1f, 0.5f, 1.0f}) {
    for (int k = 0; k < 2000; ++k) {
      // Half of the normals within a few alpha of the pole, where the peak is.
      vec3 h = random_upper(rng);
      if (k % 2) h = glm::normalize(vec3(h.x * 4 * alpha, h.y * 4 * alpha, 1.0f));
      const double c = h.z, t2 = (double(h.x) * h.x + double(h.y) * h.y) / (c * c);
      const double a2 = double(alpha) * alpha;
      const double ref = a2 / (kPiD * c * c * c * c * (a2 + t2) * (a2 + t2));
      EXPECT_NEAR(ggx_d(h, alpha), ref, 1e-5 * ref) << "alpha=" << alpha;
    }
  }
  EXPECT_EQ(ggx_d(vec3(1, 0, 0), 0.5f), 0.0f);
  EXPECT_EQ(ggx_d(vec3(0, 0.6f, -0.8f), 0.5f), 0.0f);
  EXPECT_EQ(ggx_d(vec3(0, 0, 1), 0.0f), ggx_d(vec3(0, 0, 1), kMinGgxAlpha));  // alpha raised
  EXPECT_TRUE(std::isfinite(ggx_d(vec3(0, 0, 1), 0.0f)));
}

TEST(Microfacet, SmithTermsMatchHeitzAndGltfForms) {
  // Lambda = (-1 + sqrt(1 + a^2 tan^2)) / 2 (Heitz 2014, eq. 72), in double via expm1/log1p so
  // that small Lambdas keep their digits; G1 = 1/(1+Lambda); G2 = 1/(1+Lo+Li); and glTF
  // appendix B's G and V written out verbatim. Relative 1e-5 (float).
  Rng rng(202, 0, 0, Stream::Test);
  auto lambda_ref = [](const vec3& w, double a) {
    const double c = w.z, t2 = (double(w.x) * w.x + double(w.y) * w.y) / (c * c);
    return 0.5 * std::expm1(0.5 * std::log1p(a * a * t2));
  };
  for (float alpha : {kMinGgxAlpha, 0.01f, 0.1f, 0.5f, 1.0f}) {
    for (int k = 0; k < 2000; ++k) {
      const vec3 wo = random_upper(rng, k % 4 == 0), wi = random_upper(rng, k % 3 == 0);
      const double lo = lambda_ref(wo, alpha), li = lambda_ref(wi, alpha);
      EXPECT_NEAR(smith_lambda(wo, alpha), lo, 1e-5 * lo + 1e-30);
      EXPECT_NEAR(smith_g1(wo, alpha), 1.0 / (1.0 + lo), 1e-5 / (1.0 + lo));
      const double g2 = 1.0 / (1.0 + lo + li);
      EXPECT_NEAR(smith_g2(wo, wi, alpha), g2, 1e-5 * g2);
      const double a2 = double(alpha) * alpha, nl = wi.z, nv = wo.z;
      const double sl = std::sqrt(a2 + (1 - a2) * nl * nl), sv = std::sqrt(a2 + (1 - a2) * nv * nv);
      const double g_gltf = 2 * nl * nv / (nv * sl + nl * sv);
      // The two forms are one function of unit vectors; these float vectors are unit to ~1e-7.
      EXPECT_NEAR(g2, g_gltf, 1e-6 * g2);
      const double v_gltf = 1.0 / (2.0 * (nv * sl + nl * sv));
      if (wo.z >= kMinCosine && wi.z >= kMinCosine) {
        EXPECT_NEAR(ggx_visibility(wo.z, wi.z, alpha), v_gltf, 1e-5 * v_gltf);
      }
      // Height correlation lies between independent masking and shadowing (the product) and
      // full correlation (the minimum): (1+Lo)(1+Li) >= 1+Lo+Li >= 1+max(Lo, Li).
      const float g1o = smith_g1(wo, alpha), g1i = smith_g1(wi, alpha);
      EXPECT_LE(smith_g2(wo, wi, alpha), std::min(g1o, g1i) * (1 + 1e-6f));
      EXPECT_GE(smith_g2(wo, wi, alpha), g1o * g1i * (1 - 1e-6f));
    }
  }
  const vec3 below(0.6f, 0.0f, -0.8f), up(0, 0, 1);
  EXPECT_EQ(smith_g1(below, 0.5f), 0.0f);
  EXPECT_EQ(smith_g2(below, up, 0.5f), 0.0f);
  EXPECT_EQ(smith_g1(up, 0.5f), 1.0f);  // no masking at normal incidence
  EXPECT_EQ(smith_lambda(up, 0.5f), 0.0f);
}

TEST(Microfacet, SchlickAndF0) {
  EXPECT_NEAR(dielectric_f0(1.5f), 0.04f, 1e-7f);
  EXPECT_NEAR(dielectric_f0(1.0f / 1.5f), 0.04f, 1e-7f);  // same from either side
  EXPECT_EQ(dielectric_f0(1.0f), 0.0f);
  EXPECT_EQ(schlick_weight(1.0f), 0.0f);
  EXPECT_EQ(schlick_weight(0.0f), 1.0f);
  EXPECT_EQ(schlick_weight(-1.0f), 0.0f);  // |cos|
  for (int k = 0; k <= 100; ++k) {
    const double c = k / 100.0;
    EXPECT_NEAR(schlick_fresnel(0.04f, float(c)), 0.04 + 0.96 * std::pow(1 - c, 5), 1e-6);
    const vec3 f = schlick_fresnel(vec3(0.9f, 0.5f, 0.0f), float(c));
    EXPECT_NEAR(f.y, 0.5 + 0.5 * std::pow(1 - c, 5), 1e-6);
    EXPECT_NEAR(f.z, std::pow(1 - c, 5), 1e-6);
  }
}

TEST(Microfacet, ReflectionPdfIsVndfOverJacobian) {
  // Heitz 2018, eq. 17: pdf(wi) = D_wo(h) / (4 wo.h) for wi = reflect(wo, h). Checked pointwise
  // against ggx_vndf (float: relative 1e-4, the reflected direction is rounded).
  Rng rng(203, 0, 0, Stream::Test);
  for (float alpha : {1e-3f, 0.05f, 0.3f, 1.0f}) {
    for (int k = 0; k < 3000; ++k) {
      const vec3 wo = random_upper(rng, k % 5 == 0);
      if (wo.z < 1e-6f) continue;
      const vec3 h = sample_ggx_vndf(wo, alpha, rng.next_float(), rng.next_float());
      const vec3 wi = glm::normalize(2.0f * glm::dot(wo, h) * h - wo);
      if (wi.z <= 1e-6f) continue;
      const vec3 hh = glm::normalize(wo + wi);  // the half vector as the pdf sees it
      const double ref = ggx_vndf(wo, hh, alpha) / (4.0 * glm::dot(wo, hh));
      EXPECT_NEAR(ggx_reflection_pdf(wo, wi, alpha), ref, 1e-4 * ref) << "alpha=" << alpha;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Normalisation by quadrature

TEST(Microfacet, GgxDIntegratesToOneOverProjectedArea) {
  // Integral of D(h) h.z over the hemisphere = 1 (Walter et al. 2007, eq. 4). The quadrature's
  // error is below 1e-7 here (its theta intervals scale with alpha); float D: 1e-5.
  for (float roughness : {0.0f, 0.01f, 0.05f, 0.1f, 0.3f, 0.5f, 0.8f, 1.0f}) {
    const float a = ggx_alpha(roughness);
    const double total =
        quad::integrate_hemisphere(a, 16, [&](const vec3& h) { return double(ggx_d(h, a)) * h.z; });
    EXPECT_NEAR(total, 1.0, 1e-5) << "roughness=" << roughness;
  }
}

TEST(Microfacet, VisibleNormalsIntegrateToOne) {
  // Integral of D_wo(h) over the hemisphere = 1 for every wo (Heitz 2018, eq. 3). max(0, wo.h)
  // puts a kink into the integrand, which the phi midpoints resolve to O(nphi^-2): measured
  // worst 2.5e-5 (roughness 1, wo.z = 1e-3) with nphi = 256; tolerance 1e-4.
  for (float roughness : {0.0f, 0.05f, 0.3f, 0.6f, 1.0f}) {
    const float a = ggx_alpha(roughness);
    for (double mu : {1.0, 0.9, 0.5, 0.17, 0.02, 1e-3}) {
      const vec3 wo = at_cos(mu);
      const double total = quad::integrate_hemisphere(
          a, 256, [&](const vec3& h) { return double(ggx_vndf(wo, h, a)); });
      EXPECT_NEAR(total, 1.0, 1e-4) << "roughness=" << roughness << " wo.z=" << mu;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Energy

double metal_albedo(float roughness, double mu) {
  return quad::albedo(MetalRoughBrdf{vec3(1.0f), 1.0f, roughness}, at_cos(mu)).x;
}

TEST(MetalRoughEnergy, WhiteMetalNeverReflectsMoreThanItReceives) {
  // Weak white furnace (base colour 1, metallic 1: F = 1, f = V D): E(wo) = integral of f cos
  // <= 1. Quadrature error (theta steps of 0.02, kinks where reflections cross the horizon):
  // 3e-5 measured; tolerance 2e-4. At the minimum alpha and wo.z <= 0.01 the float half vector
  // of a rounded wi moves by 6e-8 / (2 wo.h), several percent of the 1e-4 lobe, so the
  // integral over float directions is good to 1e-3 only there.
  for (float roughness : {0.0f, 0.05f, 0.1f, 0.2f, 0.3f, 0.5f, 0.7f, 0.9f, 1.0f}) {
    for (double mu : {1.0, 0.9, 0.7, 0.5, 0.3, 0.1, 0.03, 0.01, 1e-3}) {
      const double tol = roughness < 0.03f && mu <= 0.01 ? 1e-3 : 2e-4;
      EXPECT_LE(metal_albedo(roughness, mu), 1.0 + tol)
          << "roughness=" << roughness << " mu=" << mu;
    }
  }
}

TEST(MetalRoughEnergy, SmoothMetalConservesEnergyToOnePercent) {
  // Single-scattering GGX loses the light that would hit the microsurface twice; that loss is
  // below 1% only for smooth surfaces away from grazing. Measured E: roughness 0.1 >= 0.9941
  // for wo.z >= 0.1 (0.892 at wo.z = 0.01); roughness 0.2 >= 0.9954 for wo.z >= 0.5 (0.988 at
  // 0.3); roughness 0.3 is 0.9907 at normal incidence but 0.989 at wo.z = 0.9.
  for (float roughness : {0.0f, 0.02f, 0.05f, 0.1f}) {
    for (double mu : {1.0, 0.8, 0.6, 0.4, 0.2, 0.1}) {
      EXPECT_GE(metal_albedo(roughness, mu), 0.99) << "roughness=" << roughness << " mu=" << mu;
    }
  }
  for (double mu : {1.0, 0.8, 0.6, 0.5}) EXPECT_GE(metal_albedo(0.2f, mu), 0.99) << mu;
  EXPECT_LT(metal_albedo(0.2f, 0.3), 0.99);  // where the 1% region ends
  EXPECT_LT(metal_albedo(0.1f, 0.01), 0.95);
}

TEST(MetalRoughEnergy, RoughMetalMatchesAnalyticAndPublishedLoss) {
  // alpha = 1, normal incidence: D = 1/pi, the visible normals are cosine-distributed, wi is at
  // 2 theta_h and G2 / G1 = 2 cos(2 theta_h) / (1 + cos(2 theta_h)) up to theta_h = pi/4, so
  // E = integral_0^{pi/4} 2 cos(2t) tan(t) dt = 1 - ln 2 = 0.30685. Tolerance 2e-4 (quadrature
  // across the horizon kink; measured 1e-5).
  EXPECT_NEAR(metal_albedo(1.0f, 1.0), 1.0 - std::log(2.0), 2e-4);
  // Kulla & Conty 2017 (slide "energy loss"; also Filament, section 4.7.2) show single-
  // scattering GGX losing about 60% of the energy at roughness 1. The cosine-weighted average
  // loss 1 - 2 integral E(mu) mu dmu measured here is 59.1% (E = 0.307 at normal incidence,
  // rising to 0.99 at grazing, where the reflected directions leave steeply). Tolerance: the
  // published figure is read off a plot, so +-5 points.
  using GL = boost::math::quadrature::gauss<double, 15>;
  const double e_avg =
      GL::integrate([](double mu) { return 2.0 * mu * metal_albedo(1.0f, mu); }, 0.0, 1.0);
  EXPECT_NEAR(1.0 - e_avg, 0.60, 0.05) << "average albedo " << e_avg;
  // Loss grows with roughness at normal incidence.
  double previous = 1.0;
  for (float r : {0.1f, 0.3f, 0.5f, 0.7f, 0.9f, 1.0f}) {
    const double e = metal_albedo(r, 1.0);
    EXPECT_LT(e, previous) << "roughness=" << r;
    previous = e;
  }
}

TEST(MetalRoughEnergy, GltfMaterialConservesEnergyWhereTheSpecSays) {
  // The material is (1 - metallic) dielectric + metallic metal. The metal part conserves energy
  // (above); glTF's fresnel_mix does not: it weights the diffuse base by 1 - F(v.h) with v.h at
  // each pair's half vector, which for most pairs is far from grazing, while the specular layer
  // takes F(v.h) near 1 around the mirror direction at oblique wo. Appendix B "Coupling Diffuse
  // and Specular Reflection" says so: it "breaks ... energy conservation". The dielectric's
  // albedo is affine in the base colour, E0 + base (E1 - E0), so the brightest base colour that
  // stays <= 1 at every angle is min over wo of (1 - E0) / (E1 - E0); measured: 0.103
  // (roughness 0.05, at wo.z = 0.017), 0.180 (0.1), 0.596 (0.3), 0.831 (0.5), 0.930 (0.7),
  // 0.981 (1). So the whole material stays <= 1 on a grid of metallic and angles for base
  // colours up to those limits (channels below), and a white dielectric exceeds 1.
  struct Row {
    float roughness, safe_base;
  };
  for (const Row row : {Row{0.05f, 0.10f}, Row{0.1f, 0.17f}, Row{0.3f, 0.59f}, Row{0.5f, 0.82f},
                        Row{1.0f, 0.98f}}) {
    for (float metallic : {0.0f, 0.3f, 0.7f, 1.0f}) {
      for (double mu : {1.0, 0.7, 0.4, 0.2, 0.1, 0.05, 0.017, 0.005, 1e-3}) {
        // One channel black, one at the safe limit, one in between.
        const MetalRoughBrdf m{vec3(0.0f, row.safe_base, 0.5f * row.safe_base), metallic,
                               row.roughness};
        const dvec3 e = quad::albedo(m, at_cos(mu), 64);
        EXPECT_LE(max_component(e), 1.0 + 2e-4)
            << "roughness=" << row.roughness << " metallic=" << metallic << " mu=" << mu;
        EXPECT_GE(e.x, 0.0);
      }
    }
  }
  // White dielectric (base 1, metallic 0): 0.9996 at normal incidence, 1.0006 at wo.z = 0.7,
  // 1.151 at 0.3, 1.546 at 0.1 (roughness 0.05); its cosine-weighted average over incidence is
  // 1.042, so a closed box of it gains energy. Pinned here so that a change of the coupling
  // (say, to Kulla & Conty's energy-preserving one) has to update this test on purpose.
  const MetalRoughBrdf white{vec3(1.0f), 0.0f, 0.05f};
  EXPECT_NEAR(quad::albedo(white, at_cos(1.0)).x, 0.9996, 1e-3);
  EXPECT_NEAR(quad::albedo(white, at_cos(0.3)).x, 1.151, 1e-2);
  EXPECT_NEAR(quad::albedo(white, at_cos(0.1)).x, 1.546, 1e-2);
}

// ---------------------------------------------------------------------------------------------
// The material against glTF appendix B, written out in double

dvec3 gltf_reference(const MetalRoughBrdf& m, const vec3& v, const vec3& l) {
  // Appendix B "Metal BRDF and Dielectric BRDF", the full code, with D, G (height-correlated)
  // and V from "Specular BRDF" and f0 from "Fresnel".
  const dvec3 V(v), L(l), N(0, 0, 1), H = glm::normalize(V + L);
  const double a = std::max(double(m.roughness) * m.roughness, double(kMinGgxAlpha)), a2 = a * a;
  const double nh = glm::dot(N, H), nl = glm::dot(N, L), nv = glm::dot(N, V);
  const double D = a2 / (kPiD * std::pow(nh * nh * (a2 - 1) + 1, 2));
  const double G =
      2 * nl * nv /
      (nv * std::sqrt(a2 + (1 - a2) * nl * nl) + nl * std::sqrt(a2 + (1 - a2) * nv * nv));
  const double specular = D * G / (4 * nv * nl);
  const double fresnel_w = std::pow(1 - std::fabs(glm::dot(V, H)), 5);
  const double f0 = std::pow((1 - double(m.ior)) / (1 + double(m.ior)), 2);
  const dvec3 base(m.base_color);
  const dvec3 diffuse = base / kPiD;
  const double dielectric_fresnel = f0 + (1 - f0) * fresnel_w;
  const dvec3 dielectric = glm::mix(diffuse, dvec3(specular), dielectric_fresnel);
  const dvec3 metal = (base + (1.0 - base) * fresnel_w) * specular;
  return glm::mix(dielectric, metal, double(m.metallic));
}

TEST(MetalRough, EvalIsGltfAppendixB) {
  // Float against double: relative 1e-4 (near the peak of a narrow lobe the float half vector's
  // rounding moves D by up to ~1e-4 relative), plus 1e-6 absolute for values near 0.
  Rng rng(204, 0, 0, Stream::Test);
  for (int k = 0; k < 20000; ++k) {
    const MetalRoughBrdf m = random_material(rng);
    const vec3 wo = random_upper(rng);
    vec3 wi = random_upper(rng);
    if (k % 2) {  // half near the mirror direction, inside the specular peak
      const float a = ggx_alpha(m.roughness);
      wi = glm::normalize(vec3(-wo.x, -wo.y, wo.z) + 2.0f * a * vec3(random_upper(rng)));
    }
    if (wo.z < 1e-3f || wi.z < 1e-3f) continue;
    const vec3 f = m.eval(wo, wi);
    const dvec3 ref = gltf_reference(m, wo, wi);
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(f[c], ref[c], 1e-4 * ref[c] + 1e-6) << "k=" << k << " channel " << c;
    }
  }
}

TEST(MetalRough, Reciprocal) {
  // eval(wo, wi) = eval(wi, wo). The implementation is symmetric term by term, so the two agree
  // bit for bit in this build; the tolerance allows for a compiler contracting a*b + c*d into a
  // fused multiply-add, which would break that symmetry by one rounding.
  Rng rng(205, 0, 0, Stream::Test);
  for (int k = 0; k < 20000; ++k) {
    const MetalRoughBrdf m = random_material(rng);
    const vec3 wo = random_upper(rng, k % 4 == 0), wi = random_upper(rng, k % 7 == 0);
    const vec3 a = m.eval(wo, wi), b = m.eval(wi, wo);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(a[c], b[c], 1e-6f * a[c]) << "k=" << k;
  }
}

// ---------------------------------------------------------------------------------------------
// Edges

TEST(MetalRough, ZeroBelowTheSurfaceAndFiniteEverywhere) {
  const MetalRoughBrdf m{vec3(0.8f, 0.5f, 0.2f), 0.4f, 0.3f};
  const vec3 up(0, 0, 1), below(0.6f, 0.0f, -0.8f), horizon(1, 0, 0);
  for (const vec3& w : {below, horizon}) {
    EXPECT_EQ(m.eval(up, w), vec3(0.0f));
    EXPECT_EQ(m.eval(w, up), vec3(0.0f));
    EXPECT_EQ(m.pdf(up, w), 0.0f);
    EXPECT_EQ(m.pdf(w, up), 0.0f);
    vec3 wi, weight;
    float pdf;
    EXPECT_FALSE(m.sample(w, 0.5f, 0.5f, 0.5f, wi, weight, pdf));
  }
  // Roughness 0 is the minimum alpha, not a NaN.
  const MetalRoughBrdf zero{vec3(0.8f), 1.0f, 0.0f}, min{vec3(0.8f), 1.0f, 0.01f};
  EXPECT_EQ(ggx_alpha(0.0f), kMinGgxAlpha);
  EXPECT_EQ(zero.eval(up, up), min.eval(up, up));
  EXPECT_TRUE(is_finite(zero.eval(up, up)));
  EXPECT_GT(zero.eval(up, up).x, 1e6f);  // the peak: V D = 1/(4 pi alpha^2) at the pole

  // Random materials (roughness 0 among them) and directions, a quarter of them grazing down
  // to 1e-8 (and 1e-30): value, density, sample and weight always finite and non-negative.
  Rng rng(206, 0, 0, Stream::Test);
  int sampled = 0;
  for (int k = 0; k < 200000; ++k) {
    const MetalRoughBrdf mat = random_material(rng);
    const vec3 wo = random_upper(rng, k % 4 == 0), wi = random_upper(rng, k % 4 == 1);
    const vec3 f = mat.eval(wo, wi);
    const float p = mat.pdf(wo, wi);
    ASSERT_TRUE(is_finite(f) && f.x >= 0 && f.y >= 0 && f.z >= 0) << "k=" << k;
    ASSERT_TRUE(std::isfinite(p) && p >= 0) << "k=" << k;
    vec3 s, weight;
    float sp;
    if (mat.sample(wo, rng.next_float(), rng.next_float(), rng.next_float(), s, weight, sp)) {
      ++sampled;
      ASSERT_TRUE(is_finite(weight) && weight.x >= 0 && weight.y >= 0 && weight.z >= 0) << k;
      ASSERT_TRUE(std::isfinite(sp) && sp > 0) << "k=" << k;
      ASSERT_GT(s.z, 0.0f);
      ASSERT_NEAR(glm::length(s), 1.0f, 1e-5f);
    }
  }
  EXPECT_GT(sampled, 150000);
}

TEST(MetalRough, GrazingViewAtMinimumRoughness) {
  // wo.z = 1e-3 with the narrowest lobe: the peak value stays finite, the VNDF sampler returns
  // normals facing wo, and the specular probability stays in (0, 1].
  const vec3 wo = at_cos(1e-3);
  for (float roughness : {0.0f, 0.01f, 0.1f, 1.0f}) {
    const MetalRoughBrdf m{vec3(0.9f), 0.5f, roughness};
    const vec3 mirror(-wo.x, -wo.y, wo.z);
    EXPECT_TRUE(is_finite(m.eval(wo, mirror)));
    EXPECT_GT(m.eval(wo, mirror).x, 0.0f);
    const float ps = m.specular_probability(wo);
    EXPECT_GT(ps, 0.0f);
    EXPECT_LE(ps, 1.0f);
    Rng rng(207, 0, 0, Stream::Test);
    for (int k = 0; k < 10000; ++k) {
      const vec3 h = sample_ggx_vndf(wo, ggx_alpha(roughness), rng.next_float(), rng.next_float());
      ASSERT_GE(h.z, 0.0f);
      ASSERT_GE(glm::dot(wo, h), -1e-6f);
      ASSERT_NEAR(glm::length(h), 1.0f, 1e-5f);
    }
  }
}

}  // namespace
}  // namespace pb
