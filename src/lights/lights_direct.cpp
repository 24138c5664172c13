// Next-event sampling (Lights::sample_direct, docs/error-bounds.md "Next-event estimation and
// honest bounds"): the choice of an emitter as seen from a receiver, a direction toward it, and
// the density with which the environment is drawn (for multiple importance sampling).
#include "lights/lights.h"

#include "bsdf/bsdf.h"
#include "bsdf/microfacet.h"
#include "bsdf/scattering.h"
#include "util/ray_offset.h"

#include <algorithm>
#include <cmath>

namespace pb {

namespace {

// Receivers closer to a triangle's centroid than this many times its longest edge from vertex 0
// (squared) sample it by solid angle.
constexpr float kNearFactor2 = 4.0f * 4.0f;

}  // namespace

// atan2(y, x) for y >= 0, in [0, pi], within 1e-5 absolute and 1.4e-4 relative: Abramowitz &
// Stegun 4.4.49's odd polynomial on [0, 1], carried over by atan t = pi/2 - atan(1/t) and
// atan2(y, -x) = pi - atan2(y, x). The choice weights need no more: sample_direct divides by
// the very weights it chose with, so their accuracy moves the samples' variance, never their
// mean; libm's atan2f was a tenth of next-event sampling.
float atan2_upper(float y, float x) {
  const float ax = std::fabs(x);
  if (!(y > 0.0f)) return x < 0.0f ? kPi : 0.0f;
  const bool steep = y > ax;
  const float t = steep ? ax / y : y / ax, t2 = t * t;
  float r = t * (0.9998660f +
                 t2 * (-0.3302995f + t2 * (0.1801410f + t2 * (-0.0851330f + t2 * 0.0208351f))));
  if (steep) r = 0.5f * kPi - r;
  return x < 0.0f ? kPi - r : r;
}

float Lights::local_weight(size_t k, const vec3& receiver) const {
  if (k == punctual_.size() + triangles_.size())       // the environment: pi x its mean radiance,
    return average(environment_->integral()) * 0.25f;  // the irradiance it gives a free surface
  if (k < punctual_.size()) {
    const PunctualLight& l = punctual_[k];
    if (l.kind == PunctualKind::Directional) return average(l.intensity);  // irradiance
    const vec3 d = l.position - receiver;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) return 0.0f;
    return average(spot_falloff(l, -d / std::sqrt(dist2))) / dist2;
  }
  const Triangle& t = triangles_[k - punctual_.size()];
  const vec3 a = t.p0 - receiver, b = a + t.e1, c = a + t.e2;
  // Receiver behind a one-sided emitter, or in its plane.
  const float side = -glm::dot(a, t.normal);
  if ((t.two_sided ? std::fabs(side) : side) <= plane_tolerance(t, receiver)) return 0.0f;
  // Solid angle (Van Oosterom & Strackee 1983): tan(omega / 2) = |a.(b x c)| / denominator.
  const float la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const float num = std::fabs(glm::dot(a, glm::cross(b, c)));
  const float den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  const float omega = 2.0f * atan2_upper(num, den);
  return t.select * std::max(omega, 0.0f);
}

bool Lights::sample_environment(const vec3& normal, float p_pick, Rng& rng,
                                DirectSample& out) const {
  const float u1 = rng.next_float(), u2 = rng.next_float();
  out.distance = INFINITY;
  out.margin = 0.0f;
  if (environment_->uniform()) {
    // A uniform environment by the cosine about the receiver's normal: Li cos / pdf = pi Le for
    // every sample the receiver's side sees (exact on a convex object).
    out.wi = sample_cosine_hemisphere(normal, u1, u2);
    const float cos = glm::dot(out.wi, normal);
    if (!(cos > 0.0f)) return false;
    out.li = environment_->radiance(out.wi) * (kPi / (cos * p_pick));
    out.environment_pdf = p_pick * cos / kPi;
  } else {
    float pdf = 0.0f;
    const float u3 = rng.next_float(), u4 = rng.next_float();
    out.wi = environment_->sample(u1, u2, u3, u4, pdf);
    if (!(pdf > 0.0f)) return false;
    out.li = environment_->radiance(out.wi) / (pdf * p_pick);
    out.environment_pdf = p_pick * pdf;
  }
  return max_component(out.li) > 0.0f && is_finite(out.li);
}

float Lights::local_weights(const vec3& receiver, float* weights) const {
  float sum = 0.0f;
  for (size_t j = 0; j < emitter_count(); ++j) sum += (weights[j] = local_weight(j, receiver));
  return sum;
}

float Lights::choice_probability(size_t k, const vec3& receiver) const {
  if (emitter_count() > kLocalSelectionMax) return probability_[k];
  float weights[kLocalSelectionMax];
  const float sum = local_weights(receiver, weights);
  if (!(sum > 0.0f) || !std::isfinite(sum)) return 0.0f;
  return weights[k] / sum;
}

float Lights::environment_pdf(const vec3& receiver, const vec3& normal, const vec3& wi) const {
  const size_t k = punctual_.size() + triangles_.size();
  if (!environment_ || k >= emitter_count()) return 0.0f;
  const float p_pick = choice_probability(k, receiver);
  if (!(p_pick > 0.0f)) return 0.0f;
  if (environment_->uniform()) {
    const float cos = glm::dot(wi, normal);
    return cos > 0.0f ? p_pick * cos / kPi : 0.0f;
  }
  return p_pick * environment_->pdf(wi);
}

bool Lights::sample_direct(const vec3& receiver, const vec3& normal, Rng& rng,
                           DirectSample& out) const {
  size_t k = 0;
  float p_pick = 0.0f;
  const float u0 = rng.next_float();
  const bool local = emitter_count() <= kLocalSelectionMax;
  if (local) {
    // Few emitters: choose in proportion to radiance x solid angle (or intensity / d^2) seen
    // from this receiver, so that an emitter close to the receiver is chosen as often as it
    // matters. With power-proportional choice its rare picks carry huge weights, and the
    // per-pass samples become heavy-tailed, which breaks the t-interval of the error bound.
    float weights[kLocalSelectionMax];
    const float sum = local_weights(receiver, weights);
    if (!(sum > 0.0f) || !std::isfinite(sum)) return false;
    float target = u0 * sum;
    k = emitter_count() - 1;
    for (size_t j = 0; j < emitter_count(); ++j) {
      if (target < weights[j]) {
        k = j;
        break;
      }
      target -= weights[j];
    }
    while (weights[k] == 0.0f && k > 0) --k;  // rounding at the end of the list
    p_pick = weights[k] / sum;
    if (!(p_pick > 0.0f)) return false;
  } else {
    k = pick(u0);
    p_pick = probability_[k];
  }
  if (k == punctual_.size() + triangles_.size())
    return sample_environment(normal, p_pick, rng, out);
  const float u1 = rng.next_float(), u2 = rng.next_float();
  if (k < punctual_.size()) {
    const PunctualLight& l = punctual_[k];
    if (l.kind == PunctualKind::Directional) {  // a delta direction, unoccluded to infinity
      out.wi = -l.direction;
      out.distance = INFINITY;
      out.margin = 0.0f;
      out.li = l.intensity / p_pick;
      return max_component(out.li) > 0.0f;
    }
    const vec3 d = l.position - receiver;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) return false;
    out.distance = std::sqrt(dist2);
    out.wi = d / out.distance;
    out.li = spot_falloff(l, -out.wi) / (dist2 * p_pick);
    out.margin = 0.0f;
    return max_component(out.li) > 0.0f;
  }
  const Triangle& t = triangles_[k - punctual_.size()];
  const vec3 p1 = t.p0 + t.e1, p2 = t.p0 + t.e2;
  // A receiver on a one-sided emitter's back side, or in its plane, sees no light from it
  // (already known when the local choice gave the emitter a weight: local_weight's own test).
  if (!local) {
    const float side = glm::dot(receiver - t.p0, t.normal);
    if ((t.two_sided ? std::fabs(side) : side) <= plane_tolerance(t, receiver)) return false;
  }
  vec3 dir;
  float solid_angle = 0.0f;
  // Solid-angle sampling only pays near the emitter: from farther than a few times its size,
  // area sampling is already close to uniform in solid angle, and much cheaper.
  const vec3 to_centroid = t.p0 + (t.e1 + t.e2) * (1.0f / 3.0f) - receiver;
  const float size2 = std::max(glm::dot(t.e1, t.e1), glm::dot(t.e2, t.e2));
  const bool near = glm::dot(to_centroid, to_centroid) < kNearFactor2 * size2;
  if (near && sample_spherical_triangle(t.p0, p1, p2, receiver, u1, u2, dir, solid_angle)) {
    // Uniform in solid angle: each sample carries Le times the solid angle, bounded even when
    // the emitter nearly touches the receiver (area sampling is heavy-tailed there).
    const float dist = glm::dot(t.p0 - receiver, t.normal) / glm::dot(dir, t.normal);
    if (!(dist > 0.0f) || !std::isfinite(dist)) return false;
    out.wi = dir;
    out.distance = dist;
    vec3 le = t.radiance;
    if (t.source >= 0) {  // the point's barycentrics in the piece
      const vec3 v = receiver + dist * dir - t.p0;
      const float d00 = glm::dot(t.e1, t.e1), d01 = glm::dot(t.e1, t.e2);
      const float d11 = glm::dot(t.e2, t.e2), d20 = glm::dot(v, t.e1), d21 = glm::dot(v, t.e2);
      const float den = d00 * d11 - d01 * d01;
      const float c1 = std::clamp((d11 * d20 - d01 * d21) / den, 0.0f, 1.0f);
      const float c2 = std::clamp((d00 * d21 - d01 * d20) / den, 0.0f, 1.0f - c1);
      le = radiance_at(t, c1, c2);
    }
    out.li = le * (solid_angle / p_pick);
    if (t.coat > 0.0f) out.li *= 1.0f - clearcoat_fresnel(t.coat, glm::dot(dir, t.normal));
    out.margin = shadow_margin(t, receiver, std::fabs(glm::dot(dir, t.normal)));
    return max_component(out.li) > 0.0f;
  }
  // Tiny or degenerate solid angle: uniform area sampling (pbrt-v4 does the same).
  const float s = std::sqrt(u1);
  const vec3 y = t.p0 + (1.0f - s) * t.e1 + (u2 * s) * t.e2;
  const vec3 d = y - receiver;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return false;
  out.distance = std::sqrt(dist2);
  out.wi = d / out.distance;
  float cos_light = -glm::dot(out.wi, t.normal);
  if (t.two_sided) cos_light = std::fabs(cos_light);
  if (cos_light <= 0.0f) return false;  // one-sided emitter seen from behind
  // Area sampling converted to solid angle: Le cos_l A / (d^2 p_pick).
  const vec3 le = t.source < 0 ? t.radiance : radiance_at(t, 1.0f - s, u2 * s);
  out.li = le * (cos_light * t.area / (dist2 * p_pick));
  if (t.coat > 0.0f) out.li *= 1.0f - clearcoat_fresnel(t.coat, cos_light);
  out.margin = shadow_margin(t, receiver, cos_light);
  return t.source < 0 || max_component(out.li) > 0.0f;
}

}  // namespace pb
