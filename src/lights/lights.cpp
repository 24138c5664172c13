#include "lights/lights.h"

#include "bsdf/microfacet.h"

#include "bsdf/bsdf.h"
#include "util/ray_offset.h"

#include <algorithm>
#include <stdexcept>

namespace pb {

namespace {

// KHR_lights_punctual recommended spot attenuation: a linear ramp in cos between the cones,
// squared.
float spot_attenuation(const PunctualLight& l, float cos_angle) {
  if (l.kind == PunctualKind::Point) return 1.0f;
  const float span = std::max(l.cos_inner - l.cos_outer, 1e-4f);
  const float t = std::clamp((cos_angle - l.cos_outer) / span, 0.0f, 1.0f);
  return t * t;
}

}  // namespace

// How far from the emitter triangle t's plane, along its normal, rounding may put a point that
// is on it, seen from `receiver`: the sample's own error (t.error) plus Embree's, whose distance
// to the plane is computed from v0 - origin and so grows with the receiver's coordinates too
// (ray_offset.h). A receiver closer than this lies in the plane (a point beside the emitter on
// the same wall, lifted off it by World::spawn): it sees none of it, not a hemisphere.
float Lights::plane_tolerance(const Triangle& t, const vec3& receiver) {
  return t.error + gamma_bound(7) * glm::dot(glm::abs(t.normal), glm::abs(receiver));
}

// That distance along a shadow ray at cosine cos_light to t's normal: where the ray must stop.
float Lights::shadow_margin(const Triangle& t, const vec3& receiver, float cos_light) {
  return cos_light > 0.0f ? plane_tolerance(t, receiver) / cos_light : INFINITY;
}

Lights::Lights(const Scene& scene, double piece_budget)
    : punctual_(scene.lights),
      images_(scene.images),
      centre_(0.5f * (scene.bounds.lo + scene.bounds.hi)),
      radius_(emission_radius(scene.bounds)) {
  if (scene.bounds.empty()) centre_ = vec3(0.0f);
  if (scene.environment) environment_.emplace(*scene.environment);
  double pieces = 0.0;  // what the textured triangles ask for
  for (const Mesh& mesh : scene.meshes) {
    const Material& mat = scene.materials[mesh.material];
    if (!mat.emits() || !(mat.emissive_texture.present() || mat.masked() || mat.blended()))
      continue;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      const double n = textured_split(mesh, mat, uint32_t(t / 3), nullptr);
      pieces += n * n;
    }
  }
  if (pieces > piece_budget) split_scale_ = float(std::sqrt(piece_budget / pieces));
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
      tri.error = surface_error(tri.p0, tri.p0 + tri.e1, tri.p0 + tri.e2, tri.normal);
      tri.radiance = mat.emission;
      tri.select = average(tri.radiance);
      tri.two_sided = mat.double_sided;
      tri.coat = mat.clearcoat;
      if (mat.emissive_texture.present() || mat.masked() || mat.blended())
        add_textured(mesh, mat, uint32_t(t / 3), tri);
      else
        triangles_.push_back(tri);
    }
  }
  std::vector<double> weights;
  auto add = [&](const vec3& power, double weight) {
    total_power_ += power;
    weights.push_back(weight);
  };
  for (const PunctualLight& l : punctual_) {
    const vec3 p = punctual_power(l, radius_);
    add(p, double(p.x) + p.y + p.z);
  }
  for (const Triangle& t : triangles_) {
    const float sides = t.two_sided ? 2.0f : 1.0f;
    const vec3 p = lambertian_emitter_power(t.area * sides, t.radiance);
    // Chosen by power; a textured piece by its select radiance, which is never 0 where it emits.
    add(p, t.source < 0 ? double(p.x) + p.y + p.z
                        : 3.0 * double(lambertian_emitter_power(t.area * sides, t.select)));
  }
  if (environment_) {
    const vec3 p = environment_power(*environment_, radius_);
    add(p, double(p.x) + p.y + p.z);
  }

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
  // Per emitter: flux per photon = power / probability (sample_photon); a spot's photons carry
  // up to its intensity times the cone's solid angle, a directional light's pi r^2 E, an
  // environment map's pi r^2 times its largest radiance over its sampling density.
  for (size_t k = 0; k < weights.size(); ++k) {
    if (!(probability_[k] > 0.0f)) continue;
    vec3 peak(0.0f);
    if (k == punctual_.size() + triangles_.size()) {
      peak = vec3(kPi * radius_ * radius_ * environment_->max_radiance_over_pdf());
    } else if (k < punctual_.size()) {
      const PunctualLight& l = punctual_[k];
      peak = l.kind == PunctualKind::Point ? 4.0f * kPi * l.intensity
             : l.kind == PunctualKind::Directional
                 ? punctual_power(l, radius_)
                 : l.intensity * (2.0f * kPi * (1.0f - l.cos_outer));
    } else {
      const Triangle& t = triangles_[k - punctual_.size()];
      // A textured piece's photons carry the radiance where they start: at most its peak.
      const vec3 le = t.source < 0 ? t.radiance : vec3(t.peak);
      peak = lambertian_emitter_power(t.area * (t.two_sided ? 2.0f : 1.0f), le);
    }
    max_photon_flux_ = std::max(max_photon_flux_, max_component(peak) / probability_[k]);
  }
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

EmittedPhoton Lights::sample_photon(Rng& rng) const { return sample_photon_from(rng); }

EmittedPhoton Lights::sample_photon(PrimarySample& u) const { return sample_photon_from(u); }

int Lights::direction_pair(float u0) const {
  const size_t k = pick(u0);
  return k < punctual_.size() || k == punctual_.size() + triangles_.size() ? 1 : 3;
}

template <class Random>
EmittedPhoton Lights::sample_photon_from(Random& rng) const {
  const size_t k = pick(rng.next_float());
  const float p_pick = probability_[k];
  EmittedPhoton ph;
  const float u1 = rng.next_float(), u2 = rng.next_float();
  if (k < punctual_.size()) {
    const PunctualLight& l = punctual_[k];
    if (l.kind == PunctualKind::Directional) {
      ph = from_disc(l.direction, u1, u2);
      ph.flux = l.intensity * (kPi * radius_ * radius_) / p_pick;
      return ph;
    }
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
  if (k == punctual_.size() + triangles_.size()) {
    // The environment: a direction toward it by the map, entering through the disc facing it
    // (pbrt-v4 ImageInfiniteLight::SampleLe): flux = Le pi r^2 / pdf.
    float pdf = 0.0f;
    const float v0 = rng.next_float(), v1 = rng.next_float();
    const vec3 w = environment_->sample(u1, u2, v0, v1, pdf);
    const float d0 = rng.next_float(), d1 = rng.next_float();
    ph = from_disc(-w, d0, d1);
    ph.flux = pdf > 0.0f ? environment_->radiance(w) * (kPi * radius_ * radius_) / (pdf * p_pick)
                         : vec3(0.0f);
    return ph;
  }
  const Triangle& t = triangles_[k - punctual_.size()];
  // Uniform point on the triangle (pbrt-v4 SampleUniformTriangle, square-root mapping).
  const float s = std::sqrt(u1);
  const float b1 = 1.0f - s, b2 = u2 * s;
  ph.origin = t.p0 + b1 * t.e1 + b2 * t.e2;
  ph.normal = t.normal;
  ph.error = t.error;
  // Drawn in this order: the arguments of an earlier call, which GCC evaluated right to left
  // (images stay bit-identical; the order is now explicit for every compiler).
  const float v2 = rng.next_float(), v1 = rng.next_float();
  float sides = 1.0f;
  if (t.two_sided) {  // either side with probability 1/2
    sides = 2.0f;
    if (rng.next_float() < 0.5f) ph.normal = -ph.normal;
  }
  ph.dir = sample_cosine_hemisphere(ph.normal, v1, v2);
  // Cosine-weighted direction and uniform area: flux = Le cos / (pdf_A pdf_w) = pi A Le.
  const vec3 le = t.source < 0 ? t.radiance : radiance_at(t, b1, b2);
  ph.flux = le * (kPi * t.area * sides) / p_pick;
  if (t.coat > 0.0f) ph.flux *= 1.0f - clearcoat_fresnel(t.coat, glm::dot(ph.dir, ph.normal));
  return ph;
}

EmittedPhoton Lights::from_disc(const vec3& travel, float u0, float u1) const {
  // Uniform by area (radius r sqrt(u0), angle 2 pi u1) on the disc of radius r facing the light,
  // r before the scene's centre: outside the bounding sphere, covering all of it.
  vec3 t, b;
  orthonormal_basis(travel, t, b);
  const float rho = radius_ * std::sqrt(u0), phi = 2.0f * kPi * u1;
  EmittedPhoton ph;
  ph.origin = centre_ - radius_ * travel + rho * (std::cos(phi) * t + std::sin(phi) * b);
  ph.dir = travel;
  return ph;
}

}  // namespace pb
