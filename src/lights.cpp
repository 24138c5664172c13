#include "photonbound/lights.h"

#include "photonbound/bsdf.h"

#include <algorithm>
#include <stdexcept>

namespace pb {

namespace {

// KHR_lights_punctual recommended spot attenuation: a linear ramp in cos between the cones, squared.
float spot_attenuation(const PunctualLight& l, float cos_angle) {
  if (l.kind == PunctualKind::Point) return 1.0f;
  const float span = std::max(l.cos_inner - l.cos_outer, 1e-4f);
  const float t = std::clamp((cos_angle - l.cos_outer) / span, 0.0f, 1.0f);
  return t * t;
}

// Power of a punctual light: integral of intensity times attenuation over the sphere.
// Spot: 2 pi I (integral over cos from cos_outer to 1 of the attenuation)
//     = 2 pi I ((cos_inner - cos_outer) / 3 + (1 - cos_inner)) for the squared linear ramp.
vec3 punctual_power(const PunctualLight& l) {
  if (l.kind == PunctualKind::Point) return 4.0f * kPi * l.intensity;
  const float span = std::max(l.cos_inner - l.cos_outer, 0.0f);
  return 2.0f * kPi * l.intensity * (span / 3.0f + (1.0f - l.cos_inner));
}

}  // namespace

Lights::Lights(const Scene& scene) : punctual_(scene.lights) {
  for (const Mesh& mesh : scene.meshes) {
    const Material& mat = scene.materials[mesh.material];
    if (!mat.emits()) continue;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      Triangle tri;
      tri.p0 = mesh.positions[mesh.indices[t]];
      tri.e1 = mesh.positions[mesh.indices[t + 1]] - tri.p0;
      tri.e2 = mesh.positions[mesh.indices[t + 2]] - tri.p0;
      const vec3 c = glm::cross(tri.e1, tri.e2);
      tri.area = 0.5f * glm::length(c);
      if (!(tri.area > 0.0f)) continue;
      tri.normal = c / (2.0f * tri.area);
      tri.radiance = mat.emission;
      triangles_.push_back(tri);
    }
  }
  std::vector<double> weights;
  auto add = [&](const vec3& power) {
    total_power_ += power;
    weights.push_back(double(power.x) + power.y + power.z);
  };
  for (const PunctualLight& l : punctual_) add(punctual_power(l));
  // A one-sided Lambertian emitter of radiance Le and area A emits pi A Le.
  for (const Triangle& t : triangles_) add(kPi * t.area * t.radiance);

  double sum = 0.0;
  for (double w : weights) sum += w;
  if (!(sum > 0.0) || !std::isfinite(sum))
    throw std::runtime_error("the scene's lights emit no finite positive power");
  cdf_.resize(weights.size());
  probability_.resize(weights.size());
  double acc = 0.0;
  for (size_t k = 0; k < weights.size(); ++k) {
    acc += weights[k];
    cdf_[k] = acc / sum;
    probability_[k] = float(weights[k] / sum);
  }
  cdf_.back() = 1.0;
}

size_t Lights::pick(float u) const {
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), double(u));
  size_t k = size_t(it - cdf_.begin());
  k = std::min(k, cdf_.size() - 1);
  // Skip zero-probability emitters that share a CDF value with their successor.
  while (probability_[k] == 0.0f && k + 1 < cdf_.size()) ++k;
  return k;
}

vec3 Lights::spot_falloff(const PunctualLight& l, const vec3& dir) const {
  return l.intensity * spot_attenuation(l, glm::dot(dir, l.direction));
}

EmittedPhoton Lights::sample_photon(Rng& rng) const {
  const size_t k = pick(rng.next_float());
  const float p_pick = probability_[k];
  EmittedPhoton ph;
  const float u1 = rng.next_float(), u2 = rng.next_float();
  if (k < punctual_.size()) {
    const PunctualLight& l = punctual_[k];
    ph.origin = l.position;
    if (l.kind == PunctualKind::Point) {
      ph.dir = sample_uniform_sphere(u1, u2);
      ph.flux = l.intensity * (4.0f * kPi) / p_pick;
    } else {
      ph.dir = sample_uniform_cone(l.direction, l.cos_outer, u1, u2);
      const float solid_angle = 2.0f * kPi * (1.0f - l.cos_outer);
      ph.flux = spot_falloff(l, ph.dir) * solid_angle / p_pick;
    }
    return ph;
  }
  const Triangle& t = triangles_[k - punctual_.size()];
  // Uniform point on the triangle (pbrt-v4 SampleUniformTriangle, square-root mapping).
  const float s = std::sqrt(u1);
  const float b1 = 1.0f - s, b2 = u2 * s;
  ph.origin = t.p0 + b1 * t.e1 + b2 * t.e2;
  ph.normal = t.normal;
  ph.dir = sample_cosine_hemisphere(t.normal, rng.next_float(), rng.next_float());
  // Cosine-weighted direction and uniform area: flux = Le cos / (pdf_A pdf_w) = pi A Le.
  ph.flux = t.radiance * (kPi * t.area) / p_pick;
  return ph;
}

bool Lights::sample_direct(const vec3& receiver, Rng& rng, DirectSample& out) const {
  const size_t k = pick(rng.next_float());
  const float p_pick = probability_[k];
  const float u1 = rng.next_float(), u2 = rng.next_float();
  if (k < punctual_.size()) {
    const PunctualLight& l = punctual_[k];
    const vec3 d = l.position - receiver;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) return false;
    out.distance = std::sqrt(dist2);
    out.wi = d / out.distance;
    out.li = spot_falloff(l, -out.wi) / (dist2 * p_pick);
    return max_component(out.li) > 0.0f;
  }
  const Triangle& t = triangles_[k - punctual_.size()];
  const float s = std::sqrt(u1);
  const vec3 y = t.p0 + (1.0f - s) * t.e1 + (u2 * s) * t.e2;
  const vec3 d = y - receiver;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return false;
  out.distance = std::sqrt(dist2);
  out.wi = d / out.distance;
  const float cos_light = -glm::dot(out.wi, t.normal);
  if (cos_light <= 0.0f) return false;  // one-sided emitter seen from behind
  // Area sampling converted to solid angle: Le cos_l A / (d^2 p_pick).
  out.li = t.radiance * (cos_light * t.area / (dist2 * p_pick));
  return true;
}

}  // namespace pb
