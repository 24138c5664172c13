#include "bsdf/thin_film.h"

#include "bsdf/microfacet.h"

#include <algorithm>
#include <cmath>

namespace pb {

namespace {

// ((n_t - n_i) / (n_t + n_i))^2 and its inverse for an air interface (the extension's
// IorToFresnel0 and Fresnel0ToIor).
float ior_to_f0(float transmitted, float incident) {
  const float r = (transmitted - incident) / (transmitted + incident);
  return r * r;
}
float f0_to_ior(float f0) {
  const float s = std::sqrt(std::clamp(f0, 0.0f, 0.9999f));
  return (1.0f + s) / (1.0f - s);
}

// The extension's evalSensitivity: the Fourier transform of the XYZ sensitivities (sums of
// Gaussians, Belcour and Barla's fit) at the optical path difference opd (nm) with phase shifts
// per channel, normalised by 1.0685e-7, in linear Rec. 709. Double: the phase is of order 1e-5
// and its square times the variances of order 1e9.
dvec3 sensitivity(double opd, const dvec3& shift) {
  const double phase = 2.0 * kPiD * opd * 1.0e-9;
  const dvec3 val(5.4856e-13, 4.4201e-13, 5.2481e-13);
  const dvec3 pos(1.6810e+06, 1.7953e+06, 2.2084e+06);
  const dvec3 var(4.3278e+09, 9.3046e+09, 6.6121e+09);
  dvec3 xyz;
  for (int c = 0; c < 3; ++c)
    xyz[c] = val[c] * std::sqrt(2.0 * kPiD * var[c]) * std::cos(pos[c] * phase + shift[c]) *
             std::exp(-phase * phase * var[c]);
  xyz.x += 9.7470e-14 * std::sqrt(2.0 * kPiD * 4.5282e+09) *
           std::cos(2.2399e+06 * phase + shift.x) * std::exp(-4.5282e+09 * phase * phase);
  xyz /= 1.0685e-7;
  // XYZ to linear Rec. 709 (sRGB primaries, D65).
  return dvec3(3.2404542 * xyz.x - 1.5371385 * xyz.y - 0.4985314 * xyz.z,
               -0.9692660 * xyz.x + 1.8760108 * xyz.y + 0.0415560 * xyz.z,
               0.0556434 * xyz.x - 0.2040259 * xyz.y + 1.0572252 * xyz.z);
}

}  // namespace

vec3 iridescent_fresnel(float outside_ior, float film_ior, const vec3& base_f0, float thickness_nm,
                        float cos_theta1) {
  const float c1 = std::clamp(std::fabs(cos_theta1), 0.0f, 1.0f);
  if (!(thickness_nm > 0.0f)) return schlick_fresnel(glm::clamp(base_f0, 0.0f, 1.0f), c1);
  // Snell into the film; total internal reflection reflects everything.
  const float ratio = outside_ior / film_ior;
  const float sin2 = ratio * ratio * (1.0f - c1 * c1);
  if (sin2 >= 1.0f) return vec3(1.0f);
  const float c2 = std::sqrt(1.0f - sin2);
  // First interface (outside to film) at theta1, second (film to base) at theta2, both by
  // Schlick; the base's index from its f0 as if seen from air (the extension's approximation,
  // exact for dielectrics, extinction taken as 0 for metals).
  const double r12 = schlick_fresnel(ior_to_f0(film_ior, outside_ior), c1);
  const double t121 = 1.0 - r12;
  const double phi12 = film_ior < outside_ior ? kPiD : 0.0, phi21 = kPiD - phi12;
  dvec3 r23, phi;
  for (int c = 0; c < 3; ++c) {
    const float base_ior = f0_to_ior(base_f0[c] + 1e-4f);  // the extension's guard against 1
    r23[c] = schlick_fresnel(ior_to_f0(base_ior, film_ior), c2);
    phi[c] = phi21 + (base_ior < film_ior ? kPiD : 0.0);
  }
  // First-order optical path difference (nm), and the series of the extension's "Analytic
  // Spectral Integration": the incoherent sum C0 plus the first two interference terms.
  const double opd = 2.0 * double(film_ior) * double(thickness_nm) * c2;
  const dvec3 s1 = sensitivity(opd, phi), s2 = sensitivity(2.0 * opd, 2.0 * phi);
  vec3 out;
  for (int c = 0; c < 3; ++c) {
    const double r123 = std::clamp(r12 * r23[c], 1e-5, 0.9999), root = std::sqrt(r123);
    const double rs = t121 * t121 * r23[c] / (1.0 - r123);
    const double c1m = (rs - t121) * root, c2m = c1m * root;  // C_m = (Rs - T121) r123^(m/2)
    const double i = r12 + rs + c1m * 2.0 * s1[c] + c2m * 2.0 * s2[c];
    out[c] = float(std::clamp(i, 0.0, 1.0));
  }
  return out;
}

}  // namespace pb
