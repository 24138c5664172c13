// Deterministic quadrature over the hemisphere of microfacet normals, shared by the microfacet
// tests: integrals of D, of the visible normals, and directional albedos of the glTF BRDF.
#pragma once

#include "bsdf/microfacet.h"

#include <boost/math/quadrature/gauss.hpp>

#include <cmath>
#include <vector>

namespace pb::quad {

// Integral of fn(h) over the unit hemisphere h.z > 0 (solid angle measure), in double; fn
// returns double or dvec3.
// theta: 20-point Gauss-Legendre on intervals whose edges grow geometrically (ratio 1.5) from
// b / 64 to 0.8 pi/2, then steps of at most 0.02 to pi/2, so a lobe of width b (a GGX alpha)
// is resolved however narrow it is. phi: nphi midpoints, spectrally accurate for smooth
// periodic integrands and O(nphi^-2) where a horizon cut puts a kink into them.
template <class Fn>
auto integrate_hemisphere(double b, int nphi, Fn&& fn) {
  using T = decltype(fn(vec3(0.0f)));
  using GL = boost::math::quadrature::gauss<double, 20>;
  std::vector<double> edges{0.0};
  const double half_pi = kPiD / 2;
  for (double t = b / 64; t < 0.8 * half_pi; t *= 1.5) edges.push_back(t);
  const double last = edges.back();
  const int steps = std::max(4, int(std::ceil((half_pi - last) / 0.02)));
  for (int k = 1; k <= steps; ++k) edges.push_back(last + (half_pi - last) * k / steps);
  std::vector<double> cos_phi(nphi), sin_phi(nphi);
  for (int j = 0; j < nphi; ++j) {
    const double phi = 2 * kPiD * (j + 0.5) / nphi;
    cos_phi[j] = std::cos(phi);
    sin_phi[j] = std::sin(phi);
  }
  T sum(0.0);
  auto ring = [&](double theta, double weight) {
    const double st = std::sin(theta), ct = std::cos(theta);
    T s(0.0);
    for (int j = 0; j < nphi; ++j) {
      s += fn(vec3(float(st * cos_phi[j]), float(st * sin_phi[j]), float(ct)));
    }
    sum += weight * st * s * (2 * kPiD / nphi);
  };
  for (size_t e = 0; e + 1 < edges.size(); ++e) {
    const double mid = 0.5 * (edges[e] + edges[e + 1]), half = 0.5 * (edges[e + 1] - edges[e]);
    for (size_t i = 0; i < GL::abscissa().size(); ++i) {
      const double x = GL::abscissa()[i], w = GL::weights()[i] * half;
      ring(mid + half * x, w);
      if (x != 0.0) ring(mid - half * x, w);
    }
  }
  return sum;
}

// Directional albedo of the BRDF at wo: the integral over wi of f(wo, wi) wi.z, computed over
// the microfacet normals h (wi = reflect(wo, h), d omega_i = 4 (wo.h) d omega_h), so that the
// specular peak is resolved at any roughness.
// The same for any f(wo, wi) (returning vec3) whose peak is a GGX lobe of the given alpha.
template <class Eval>
dvec3 albedo_of(float alpha, const vec3& wo, Eval&& f, int nphi = 128) {
  const dvec3 o(wo);
  return integrate_hemisphere(alpha, nphi, [&](const vec3& h) {
    const double o_h = glm::dot(o, dvec3(h));
    if (o_h <= 0.0) return dvec3(0.0);
    const dvec3 wi = 2.0 * o_h * dvec3(h) - o;
    if (wi.z <= 0.0) return dvec3(0.0);
    return dvec3(f(wo, glm::normalize(vec3(wi)))) * (wi.z * 4.0 * o_h);
  });
}
inline dvec3 albedo(const MetalRoughBrdf& brdf, const vec3& wo, int nphi = 128) {
  return albedo_of(
      ggx_alpha(brdf.roughness), wo, [&](const vec3& o, const vec3& i) { return brdf.eval(o, i); },
      nphi);
}

// Unit direction at polar angle theta (radians) in the xz-plane, x >= 0.
inline vec3 at_theta(double theta) {
  return vec3(float(std::sin(theta)), 0.0f, float(std::cos(theta)));
}

// Unit direction with the given cosine, in the xz-plane.
inline vec3 at_cos(double mu) {
  return vec3(float(std::sqrt(std::max(0.0, 1.0 - mu * mu))), 0.0f, float(mu));
}

}  // namespace pb::quad
