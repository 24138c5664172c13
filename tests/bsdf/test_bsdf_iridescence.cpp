// KHR_materials_iridescence: the thin-film Fresnel term against the extension's GLSL written out
// here in double, its physical limits (no film, a film of the outside's index, a thick film
// losing its colour, total internal reflection into the film), and the Bsdf: eval against the
// extension's layering, iridescence 0 unchanged bit for bit, reciprocity, max_f, sample()
// against eval() and pdf(), the mirror and thin-glass branches.
#include "bsdf/bsdf.h"
#include "bsdf/microfacet.h"
#include "bsdf/thin_film.h"
#include "util/rng.h"

#include "bsdf_properties.h"
#include "bsdf_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace pb {
namespace {

using test::BsdfCase;
using test::cases_of;
using test::expect_sample_matches_eval;
using test::metal_rough;
using test::random_normals;
using test::random_unit;

// The extension's "Iridescence Fresnel" GLSL, line by line in double (its evalSensitivity with
// the XYZ_TO_REC709 matrix as GLSL's column-major mat3 reads it), before photonbound's clamp.
dvec3 spec_sensitivity(double opd, dvec3 shift) {
  const double phase = 2.0 * kPiD * opd * 1.0e-9;
  const dvec3 val(5.4856e-13, 4.4201e-13, 5.2481e-13), pos(1.6810e+06, 1.7953e+06, 2.2084e+06),
      var(4.3278e+09, 9.3046e+09, 6.6121e+09);
  dvec3 xyz = val * glm::sqrt(2.0 * kPiD * var) * glm::cos(pos * phase + shift) *
              glm::exp(-(phase * phase) * var);
  xyz.x += 9.7470e-14 * std::sqrt(2.0 * kPiD * 4.5282e+09) *
           std::cos(2.2399e+06 * phase + shift[0]) * std::exp(-4.5282e+09 * phase * phase);
  xyz /= 1.0685e-7;
  const glm::dmat3 m(3.2404542, -0.9692660, 0.0556434, -1.5371385, 1.8760108, -0.2040259,
                     -0.4985314, 0.0415560, 1.0572252);
  return m * xyz;
}
dvec3 spec_iridescence(double outside, double film, dvec3 base_f0, double thickness, double c1) {
  auto ior_to_f0 = [](dvec3 t, double i) { return (t - i) / (t + i) * ((t - i) / (t + i)); };
  auto schlick = [](dvec3 f0, double c) { return f0 + (1.0 - f0) * std::pow(1.0 - c, 5.0); };
  const double sin2 = std::pow(outside / film, 2.0) * (1.0 - c1 * c1);
  if (1.0 - sin2 < 0.0) return dvec3(1.0);
  const double c2 = std::sqrt(1.0 - sin2);
  const double r0 = ior_to_f0(dvec3(film), outside).x;
  const double r12 = schlick(dvec3(r0), c1).x, t121 = 1.0 - r12;
  const dvec3 sq = glm::sqrt(base_f0 + 0.0001);
  const dvec3 base_ior = (1.0 + sq) / (1.0 - sq);
  const dvec3 r23 = schlick(ior_to_f0(base_ior, film), c2);
  const double phi12 = film < outside ? kPiD : 0.0, phi21 = kPiD - phi12;
  dvec3 phi23(0.0);
  for (int c = 0; c < 3; ++c)
    if (base_ior[c] < film) phi23[c] = kPiD;
  const dvec3 phi = dvec3(phi21) + phi23;
  const double opd = 2.0 * film * thickness * c2;
  const dvec3 r123 = glm::clamp(r12 * r23, 1e-5, 0.9999), root = glm::sqrt(r123);
  const dvec3 rs = t121 * t121 * r23 / (1.0 - r123);
  dvec3 i = r12 + rs, cm = rs - t121;
  for (int k = 1; k <= 2; ++k) {
    cm *= root;
    i += cm * 2.0 * spec_sensitivity(k * opd, double(k) * phi);
  }
  return glm::max(i, 0.0);
}

TEST(ThinFilm, IsTheExtensionsIridescentFresnel) {
  // Random films over dielectric and metallic bases, thicknesses 10-1200 nm, every view: the
  // float implementation against the double GLSL within 2e-4 (float cosines and Schlick terms;
  // a base index near 1e3, from f0 near 0.999, amplifies float rounding the most),
  // after clamping the GLSL's result at 1 (photonbound's one departure above 0 nm).
  Rng rng(701, 0, 0, Stream::Test);
  int above_one = 0;
  for (int k = 0; k < 20000; ++k) {
    const float film = 1.0f + 1.5f * rng.next_float(),
                thickness = 10.0f + 1190.0f * rng.next_float();
    // f0 up to 0.999: above 0.9999 the GLSL's guard f0 + 1e-4 passes 1 and its base index turns
    // negative; photonbound keeps f0 + 1e-4 at most 0.9999 (a base index of 4e4, a mirror).
    const float u = rng.next_float(), v = rng.next_float(), w = rng.next_float();
    const vec3 f0 = k % 2 ? vec3(0.02f + 0.1f * u) : 0.999f * vec3(u, v, w);
    const float c = 0.01f + 0.99f * rng.next_float();
    const vec3 got = iridescent_fresnel(1.0f, film, f0, thickness, c);
    const dvec3 want = spec_iridescence(1.0, film, dvec3(f0), thickness, c);
    for (int ch = 0; ch < 3; ++ch) {
      above_one += want[ch] > 1.0;
      EXPECT_NEAR(got[ch], std::min(want[ch], 1.0), 2e-4) << k << " " << ch;
    }
  }
  std::printf("GLSL results above 1: %d of 60000\n", above_one);
}

TEST(ThinFilm, PhysicalLimits) {
  // No film (0 nm): the base's Schlick reflectance. A film of the outside's own index (1) at
  // normal incidence: the first interface reflects nothing and the base alone is seen, up to
  // the extension's clamp of R12 R23 at 1e-5 (its interference terms scale with sqrt of it:
  // within 2e-2). A thick film (20 um): the interference terms vanish (the sensitivities'
  // Gaussian envelopes), so a grey base reflects grey, the incoherent sum R12 + T121^2 R23 /
  // (1 - R12 R23), within 1e-3. Total internal reflection into the film (from a denser
  // outside at grazing): 1.
  const vec3 f0(0.04f, 0.5f, 0.9f);
  for (float c : {1.0f, 0.6f, 0.2f}) {
    const vec3 none = iridescent_fresnel(1.0f, 1.3f, f0, 0.0f, c);
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(none[ch], schlick_fresnel(f0[ch], c));
  }
  const vec3 air = iridescent_fresnel(1.0f, 1.0f, f0, 300.0f, 1.0f);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(air[ch], f0[ch], 2e-2) << ch;
  for (float c : {1.0f, 0.7f, 0.3f}) {
    const float grey = 0.04f;
    const vec3 thick = iridescent_fresnel(1.0f, 1.3f, vec3(grey), 20000.0f, c);
    const double r0 = std::pow(0.3 / 2.3, 2.0), r12 = r0 + (1 - r0) * std::pow(1.0 - c, 5.0);
    const double c2 = std::sqrt(1.0 - (1.0 - c * c) / (1.3 * 1.3));
    const double sq = std::sqrt(grey + 1e-4), n = (1 + sq) / (1 - sq);
    const double rb = std::pow((n - 1.3) / (n + 1.3), 2.0),
                 r23 = rb + (1 - rb) * std::pow(1 - c2, 5.0);
    const double incoherent = r12 + (1 - r12) * (1 - r12) * r23 / (1 - r12 * r23);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(thick[ch], incoherent, 1e-3) << c << " " << ch;
  }
  EXPECT_EQ(iridescent_fresnel(2.0f, 1.3f, f0, 300.0f, 0.3f), vec3(1.0f));
}

BsdfParams film(vec3 base, float metallic, float roughness, float weight, float thickness) {
  BsdfParams p = metal_rough(base, metallic, roughness);
  p.iridescence = weight;
  p.iridescence_ior = 1.3f;
  p.iridescence_thickness = thickness;
  return p;
}

TEST(Iridescence, EvalIsTheExtensionsLayering) {
  // The dielectric: rgb_mix(base, V D, mix(F_schlick, F_film, s)) = (1 - max F) base / pi +
  // F V D; the metal: mix(F_schlick(base), F_film(base), s) V D; glTF's mix of the two by
  // metallic. F_film is iridescent_fresnel (tested above) at v.h. Relative 1e-5.
  Rng rng(702, 0, 0, Stream::Test);
  const vec3 n(0, 0, 1);
  for (int k = 0; k < 20000; ++k) {
    const BsdfParams p =
        film(vec3(rng.next_float(), rng.next_float(), rng.next_float()), rng.next_float(),
             0.1f + 0.9f * rng.next_float(), rng.next_float(), 100.0f + 700.0f * rng.next_float());
    const Bsdf bsdf(p, n, n);
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    if (wo.z < 0.05f || wi.z < 0.05f) continue;
    const vec3 h = glm::normalize(wo + wi);
    const float vh = glm::dot(wo, h), a = p.roughness * p.roughness;
    const float vd = ggx_visibility(wo.z, wi.z, a) * ggx_d(h, a);
    const float w = std::pow(1.0f - vh, 5.0f);
    const vec3 fd = glm::mix(
        vec3(0.04f + 0.96f * w),
        iridescent_fresnel(1.0f, 1.3f, vec3(0.04f), p.iridescence_thickness, vh), p.iridescence);
    const vec3 fm = glm::mix(
        p.base_color + (vec3(1.0f) - p.base_color) * w,
        iridescent_fresnel(1.0f, 1.3f, p.base_color, p.iridescence_thickness, vh), p.iridescence);
    const vec3 dielectric = (1.0f - max_component(fd)) * p.base_color / kPi + fd * vd;
    const vec3 want = glm::mix(dielectric, fm * vd, p.metallic);
    const vec3 got = bsdf.eval(wo, wi);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-5f * want[c] + 1e-7f) << k;
  }
}

TEST(Iridescence, NoFilmIsTheMaterialBitForBit) {
  // iridescenceFactor 0 (the default) leaves every value the Bsdf gives unchanged.
  Rng rng(703, 0, 0, Stream::Test);
  for (int k = 0; k < 2000; ++k) {
    const vec3 n = random_unit(rng);
    BsdfParams a = film(vec3(rng.next_float()), rng.next_float(), rng.next_float(), 0.0f, 300.0f);
    a.transmission = k % 3 == 0 ? 1.0f : 0.0f;
    BsdfParams b = a;
    b.iridescence_ior = 2.0f;  // read only with a film
    b.iridescence_thickness = 50.0f;
    const Bsdf x(a, n, n), y(b, n, n);
    const vec3 wo = random_unit(rng), wi = random_unit(rng);
    EXPECT_EQ(x.eval(wo, wi), y.eval(wo, wi));
    EXPECT_EQ(x.max_f(wo), y.max_f(wo));
    SpecularBranch bx[kMaxDeltaBranches], by[kMaxDeltaBranches];
    const int nx = x.delta_branches(wo, Transport::Radiance, bx);
    ASSERT_EQ(nx, y.delta_branches(wo, Transport::Radiance, by));
    for (int j = 0; j < nx; ++j) EXPECT_EQ(bx[j].weight, by[j].weight);
  }
}

TEST(Iridescence, ReciprocalBoundedByMaxFAndSampledByItsPdf) {
  // f(wo, wi) = f(wi, wo) (v.h is the same both ways); max_f bounds eval for random, drawn and
  // grazing wi; draws agree with eval and pdf (relative 2e-3); the suite's cases below test the
  // draws of two films by chi-square.
  Rng rng(704, 0, 0, Stream::Test);
  for (int k = 0; k < 3000; ++k) {
    vec3 ng, ns;
    random_normals(rng, ng, ns);
    const BsdfParams p =
        film(vec3(rng.next_float()), rng.next_float(), 0.05f + 0.95f * rng.next_float(),
             rng.next_float(), 100.0f + 700.0f * rng.next_float());
    const Bsdf bsdf(p, ng, ns);
    const vec3 wo = random_unit(rng);
    const vec3 cap = bsdf.max_f(wo);
    for (int i = 0; i < 60; ++i) {
      vec3 wi = random_unit(rng);
      if (i % 3 == 1) {
        BsdfSample s;
        if (!bsdf.sample(wo, rng, Transport::Radiance, s) || s.delta) continue;
        if (glm::dot(wo, glm::dot(wo, ng) > 0.0f ? ns : -ns) > 0.02f)
          expect_sample_matches_eval(bsdf, wo, s, ns, "film");
        wi = s.wi;
      } else if (i % 3 == 2) {
        wi = glm::normalize(vec3(wi.x, wi.y, 0.002f * wi.z));
      }
      const vec3 a = bsdf.eval(wo, wi), b = bsdf.eval(wi, wo);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a[c], b[c], 1e-5f * a[c] + 1e-9f) << k;
        ASSERT_LE(a[c], cap[c] * (1.0f + 1e-5f)) << k << " " << i;
      }
    }
  }
}

// The suite's cases (bsdf_properties.h): two films, each tested by chi-square at two views with
// a seed of its own (4 tests at p > 1e-4).
std::vector<BsdfCase> iridescence_cases() {
  std::vector<BsdfCase> c =
      cases_of({{"film over a dielectric", film(vec3(0.3f), 0.0f, 0.3f, 1.0f, 350.0f)},
                {"film over a metal", film(vec3(0.9f), 1.0f, 0.5f, 0.7f, 250.0f)}},
               707, 705);
  c[1].chi_seed = 706;
  return c;
}
PB_BSDF_PROPERTY_CASES(Iridescence, iridescence_cases());

TEST(Iridescence, MirrorsAndThinGlassReflectTheFilm) {
  // Below the mirror roughness the metal's branch is the film's Fresnel at the view's cosine,
  // mixed by the weight; a thin-walled glass reflects the dielectric's mixed F and transmits
  // (1 - max F) x base colour, so the two never exceed 1 in any channel.
  const vec3 n(0, 0, 1);
  for (float c : {0.9f, 0.5f, 0.15f}) {
    const vec3 wo(std::sqrt(1.0f - c * c), 0.0f, c);
    const Bsdf metal(film(vec3(0.95f, 0.6f, 0.3f), 1.0f, 0.0f, 0.8f, 300.0f), n, n);
    SpecularBranch b[kMaxDeltaBranches];
    ASSERT_EQ(metal.delta_branches(wo, Transport::Radiance, b), 1);
    const vec3 fm =
        glm::mix(schlick_fresnel(vec3(0.95f, 0.6f, 0.3f), c),
                 iridescent_fresnel(1.0f, 1.3f, vec3(0.95f, 0.6f, 0.3f), 300.0f, c), 0.8f);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(b[0].weight[ch], fm[ch], 1e-6f) << c;
    BsdfParams glass = film(vec3(1.0f), 0.0f, 0.0f, 1.0f, 450.0f);
    glass.transmission = 1.0f;
    const Bsdf bubble(glass, n, n);
    ASSERT_EQ(bubble.delta_branches(wo, Transport::Radiance, b), 2);
    const vec3 fr = iridescent_fresnel(1.0f, 1.3f, vec3(0.04f), 450.0f, c);
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_NEAR(b[0].weight[ch], fr[ch], 1e-6f) << c;
      EXPECT_NEAR(b[1].weight[ch], 1.0f - max_component(fr), 1e-6f) << c;
      EXPECT_LE(b[0].weight[ch] + b[1].weight[ch], 1.0f + 1e-6f);
    }
  }
}

}  // namespace
}  // namespace pb
