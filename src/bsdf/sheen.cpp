#include "bsdf/sheen.h"

#include <boost/math/quadrature/gauss.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace pb {

float sheen_alpha(float roughness) {
  const float r = std::clamp(roughness, kMinSheenRoughness, 1.0f);
  return r * r;
}

float charlie_d(float cos_h, float alpha) {
  const float sin2 = std::max(0.0f, 1.0f - cos_h * cos_h);
  const float inv = 1.0f / alpha;
  return (2.0f + inv) * std::pow(sin2, 0.5f * inv) / (2.0f * kPi);
}

namespace {

// The extension's fit of the Charlie Lambda (its "Sheen visibility", from Conty Estevez and
// Kulla's table): l(x) = a / (1 + b x^c) + d x + e, coefficients mixed by (1 - alpha)^2.
float lambda_fit(float x, float alpha) {
  const float t = (1.0f - alpha) * (1.0f - alpha);
  auto mix = [t](float u, float v) { return u + (v - u) * t; };
  const float a = mix(21.5473f, 25.3245f), b = mix(3.82987f, 3.32435f), c = mix(0.19823f, 0.16801f),
              d = mix(-1.97760f, -1.27393f), e = mix(-4.32054f, -4.85967f);
  return a / (1.0f + b * std::pow(x, c)) + d * x + e;
}

float charlie_lambda(float cos_theta, float alpha) {
  const float c = std::fabs(cos_theta);
  return c < 0.5f ? std::exp(lambda_fit(c, alpha))
                  : std::exp(2.0f * lambda_fit(0.5f, alpha) - lambda_fit(1.0f - c, alpha));
}

}  // namespace

float charlie_visibility(float cos_o, float cos_i, float alpha) {
  if (!(cos_o > 0.0f) || !(cos_i > 0.0f)) return 0.0f;
  const float den =
      (1.0f + charlie_lambda(cos_o, alpha) + charlie_lambda(cos_i, alpha)) * 4.0f * cos_o * cos_i;
  return std::clamp(1.0f / den, 0.0f, 1.0f);
}

float sheen_dv(const vec3& wo, const vec3& wi, float alpha) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return 0.0f;
  const vec3 h = glm::normalize(wo + wi);
  return charlie_d(h.z, alpha) * charlie_visibility(wo.z, wi.z, alpha);
}

namespace {

constexpr int kTable = 32;  // intervals in sqrt(cos_o) and in roughness (0.07 .. 1)

// E over the half vector h (wi = reflect(wo, h), d omega_i = 4 (wo.h) d omega_h), where the
// integrand is smooth but for D's peak along the horizon, about sqrt(alpha) wide in theta_h:
// 10-point Gauss-Legendre on panels of theta_h, narrowing toward pi/2, the midpoint rule in phi_h
// over [0, pi] (the integrand is even in phi_h), in double.
double albedo_quadrature(double cos_o, float alpha) {
  using GL = boost::math::quadrature::gauss<double, 10>;
  const double h = kPiD / 2, w = std::sqrt(double(alpha));
  // Sixteen equal panels (the horizon of wi cuts the integrand inside some), and three more
  // edges that narrow toward the peak.
  std::vector<double> edges;
  for (int k = 0; k <= 16; ++k) edges.push_back(h * k / 16);
  for (double f : {1.5, 0.5, 0.1})
    if (h - f * w > 0.0) edges.push_back(h - f * w);
  std::sort(edges.begin(), edges.end());
  const double so = std::sqrt(std::max(0.0, 1.0 - cos_o * cos_o));
  const dvec3 wo(so, 0.0, cos_o);
  constexpr int kPhi = 64;
  double sum = 0.0;
  for (size_t p = 0; p + 1 < edges.size(); ++p) {
    const double lo = edges[p], hi = edges[p + 1];
    if (!(hi > lo)) continue;
    const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    for (size_t i = 0; i < GL::abscissa().size(); ++i)
      for (int sign : {1, -1}) {
        const double x = GL::abscissa()[i];
        if (sign < 0 && x == 0.0) continue;
        const double th = mid + sign * half * x, wt = GL::weights()[i] * half;
        const double d = charlie_d(float(std::cos(th)), alpha);
        if (!(d > 0.0)) continue;
        double ring = 0.0;
        for (int j = 0; j < kPhi; ++j) {
          const double phi = kPiD * (j + 0.5) / kPhi;
          const dvec3 m(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
          const double o_h = glm::dot(wo, m);
          if (o_h <= 0.0) continue;
          const dvec3 wi = 2.0 * o_h * m - wo;
          if (wi.z <= 0.0) continue;
          ring += charlie_visibility(float(cos_o), float(wi.z), alpha) * wi.z * 4.0 * o_h;
        }
        sum += wt * std::sin(th) * d * ring * (2.0 * kPiD / kPhi);
      }
  }
  return sum;
}

struct AlbedoTable {
  std::array<float, (kTable + 1) * (kTable + 1)> e{};
  AlbedoTable() {
    for (int r = 0; r <= kTable; ++r) {
      const float rough = kMinSheenRoughness + (1.0f - kMinSheenRoughness) * float(r) / kTable;
      for (int c = 0; c <= kTable; ++c) {
        const double t = double(c) / kTable, mu = std::max(1e-4, t * t);
        e[size_t(r * (kTable + 1) + c)] = float(albedo_quadrature(mu, sheen_alpha(rough)));
      }
    }
  }
};

}  // namespace

float sheen_albedo(float cos_o, float roughness) {
  static const AlbedoTable table;  // made once, on first use (thread-safe)
  const float r = (std::clamp(roughness, kMinSheenRoughness, 1.0f) - kMinSheenRoughness) /
                  (1.0f - kMinSheenRoughness) * kTable;
  // Nodes at cos_o = (k / 32)^2: E changes fastest toward the horizon.
  const float c = std::sqrt(std::clamp(cos_o, 0.0f, 1.0f)) * kTable;
  const int r0 = std::min(int(r), kTable - 1), c0 = std::min(int(c), kTable - 1);
  const float fr = r - float(r0), fc = c - float(c0);
  auto at = [&](int i, int j) { return table.e[size_t(i * (kTable + 1) + j)]; };
  return (1.0f - fr) * ((1.0f - fc) * at(r0, c0) + fc * at(r0, c0 + 1)) +
         fr * ((1.0f - fc) * at(r0 + 1, c0) + fc * at(r0 + 1, c0 + 1));
}

}  // namespace pb
