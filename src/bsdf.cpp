#include "photonbound/bsdf.h"

#include <algorithm>

namespace pb {

float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  // Snell: sin_t = sin_i / eta.
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_parl * r_parl + r_perp * r_perp);
}

bool refract(const vec3& w, const vec3& n, float eta, vec3& wt) {
  const float cos_i = glm::dot(w, n);
  const float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return false;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  wt = glm::normalize(-w / eta + (cos_i / eta - cos_t) * n);
  return true;
}

vec3 sample_cosine_hemisphere(const vec3& n, float u1, float u2) {
  // Malley's method: uniform disk point lifted to the hemisphere.
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  const float z = std::sqrt(std::max(0.0f, 1.0f - u1));
  vec3 t, b;
  orthonormal_basis(n, t, b);
  return glm::normalize(x * t + y * b + z * n);
}

vec3 sample_uniform_sphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u2;
  return vec3(r * std::cos(phi), r * std::sin(phi), z);
}

vec3 sample_uniform_cone(const vec3& axis, float cos_max, float u1, float u2) {
  const float z = 1.0f - u1 * (1.0f - cos_max);
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u2;
  vec3 t, b;
  orthonormal_basis(axis, t, b);
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + z * axis);
}

float adjoint_shading_factor(const vec3& wo, const vec3& wi, const vec3& ng, const vec3& ns) {
  const float den = std::fabs(glm::dot(wo, ng)) * std::fabs(glm::dot(wi, ns));
  if (den <= 0.0f) return 0.0f;
  return std::fabs(glm::dot(wo, ns)) * std::fabs(glm::dot(wi, ng)) / den;
}

namespace {

// Shading normals make tessellated spheres look smooth, but a direction computed from ns can
// end up on the wrong side of the true surface; then the geometric normal is used instead.
vec3 reflect_checked(const vec3& wo, const vec3& ns, const vec3& ng) {
  const vec3 r = reflect(wo, ns);
  return glm::dot(r, ng) > 0.0f ? r : reflect(wo, ng);
}

}  // namespace

BsdfParams BsdfParams::of(const Material& m) {
  BsdfParams p;
  p.base_color = m.base_color;
  p.metallic = m.metallic;
  p.roughness = m.roughness;
  p.ior = m.ior;
  p.specular = m.specular;
  p.specular_color = m.specular_color;
  p.transmission = m.transmission;
  p.thin = m.thin;
  return p;
}

Bsdf::Bsdf(const BsdfParams& p, const vec3& ng, const vec3& ns, float mirror_roughness)
    : thin_(p.thin), ng_(ng), ns_(ns) {
  brdf_.base_color = p.base_color;
  brdf_.roughness = p.roughness;
  brdf_.ior = p.ior;
  brdf_.specular = p.specular;
  brdf_.specular_color = p.specular_color;
  const float m = std::clamp(p.metallic, 0.0f, 1.0f), t = std::clamp(p.transmission, 0.0f, 1.0f);
  if (m == 0.0f && t == 0.0f && p.specular == 0.0f) {  // KHR_materials_specular: no layer
    brdf_.metallic = 0.0f;
    reflect_ = 1.0f;
    return;  // kind_ Lambertian
  }
  // KHR_materials_transmission: dielectric = fresnel_mix(mix(diffuse, btdf, t), specular) is
  // (1 - t) fresnel_mix(diffuse, specular) + t fresnel_mix(btdf, specular): the parts split.
  glass_ = (1.0f - m) * t;
  reflect_ = m + (1.0f - m) * (1.0f - t);
  brdf_.metallic = reflect_ > 0.0f ? m / reflect_ : 0.0f;
  smooth_ = p.roughness < mirror_roughness;
  const float opaque = (1.0f - m) * (1.0f - t);
  const bool non_delta = reflect_ > 0.0f && (!smooth_ || opaque > 0.0f);
  const bool delta = glass_ > 0.0f || (smooth_ && reflect_ > 0.0f);
  kind_ = non_delta ? Kind::Layered : Kind::Delta;
  has_delta_ = non_delta && delta;
}

namespace {

// Directions in the shading frame (t, b, n) and back.
struct Frame {
  vec3 t, b, n;
  explicit Frame(const vec3& normal) : n(normal) { orthonormal_basis(n, t, b); }
  vec3 local(const vec3& w) const { return vec3(glm::dot(w, t), glm::dot(w, b), glm::dot(w, n)); }
  vec3 world(const vec3& w) const { return glm::normalize(w.x * t + w.y * b + w.z * n); }
};

}  // namespace

vec3 Bsdf::eval_local(const vec3& wo, const vec3& wi, float* pdf) const {
  if (pdf) *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
  if (!smooth_ && part_ == Part::All) {
    if (pdf) *pdf = brdf_.pdf(wo, wi);
    return reflect_ * brdf_.eval(wo, wi);
  }
  if (part_ == Part::Lobe) {
    if (pdf) *pdf = ggx_reflection_pdf(wo, wi, ggx_alpha(brdf_.roughness));
    return reflect_ * brdf_.eval_specular(wo, wi);
  }
  // The mirror limit of appendix B's dielectric: the GGX layer is a delta branch, the diffuse
  // base keeps its weight 1 - max F(v.h) at this pair's half vector (v.h averaged over both
  // directions, so that f stays reciprocal bit for bit). base_part() is the same term of a
  // rough lobe (MetalRoughBrdf::eval_diffuse computes it the same way).
  const vec3 h = glm::normalize(wo + wi);
  const float v_h = 0.5f * (glm::dot(wo, h) + glm::dot(wi, h));
  const vec3 f0 = brdf_.dielectric_f0();
  const vec3 fr = f0 + (vec3(brdf_.dielectric_f90()) - f0) * schlick_weight(v_h);
  if (pdf) *pdf = wi.z / kPi;
  const float opaque = reflect_ * (1.0f - brdf_.metallic);
  return (opaque * (1.0f - max_component(fr)) / kPi) * brdf_.base_color;
}

vec3 Bsdf::eval(const vec3& wo, const vec3& wi) const {
  if (kind_ == Kind::Delta) return vec3(0.0f);
  // Both directions on one side of the true surface: reflection only.
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return vec3(0.0f);
  if (kind_ == Kind::Lambertian) return diffuse_f();
  const Frame f(glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_);
  return eval_local(f.local(wo), f.local(wi), nullptr);
}

namespace {

// An upper bound of F(v.h) D(h) V(zo, zi) over every wi, for wo at cosine zo, with fresnel(c)
// a bound of F where v.h >= c. With zi the cosine of wi: V(zo, zi) = 1 / (2 (zi so + zo si))
// falls with zi (microfacet.h); h.n = (zo + zi) / |wo + wi| <= c_max = (zo + zi) /
// sqrt((zo + zi)^2 + (sin_o - sin_i)^2) (|wo + wi| is smallest at opposite azimuths), which is 1
// only at zi = zo, and D rises with h.n; v.h = sqrt((1 + wo.wi) / 2) >= sqrt((1 + zo zi - sin_o
// sin_i) / 2), which rises with zi, and Schlick's F falls with v.h. So on each of 64 intervals
// [z0, z1] of zi the product is at most fresnel(v.h at z0) D(c_max at the end nearer zo, or 1 when
// the interval holds zo) V(zo, z0): within a few percent of the peak.
template <class Fresnel>
float ggx_term_bound(float zo, float alpha, Fresnel&& fresnel) {
  constexpr int kIntervals = 64;
  const float so = std::sqrt(std::max(0.0f, 1.0f - zo * zo));
  auto sin_of = [](float z) { return std::sqrt(std::max(0.0f, 1.0f - z * z)); };
  auto c_max = [&](float zi) {
    const float sum = zo + zi, d = so - sin_of(zi);
    return sum / std::sqrt(sum * sum + d * d);
  };
  float best = 0.0f;
  for (int k = 0; k < kIntervals; ++k) {
    const float z0 = float(k) / kIntervals, z1 = float(k + 1) / kIntervals;
    const float c = zo >= z0 && zo <= z1 ? 1.0f : c_max(zo < z0 ? z0 : z1);
    const vec3 h(sin_of(c), 0.0f, c);
    const float v_h = std::sqrt(std::max(0.0f, 0.5f * (1.0f + zo * z0 - so * sin_of(z0))));
    best = std::max(best, fresnel(v_h) * ggx_d(h, alpha) * ggx_visibility(zo, z0, alpha));
  }
  return best * (1.0f + 1e-4f);  // float rounding of the pieces
}

}  // namespace

vec3 Bsdf::max_f(const vec3& wo) const {
  if (kind_ == Kind::Lambertian) return diffuse_f();
  if (kind_ == Kind::Delta) return vec3(0.0f);
  const float mu = brdf_.metallic;
  const vec3 diffuse = (1.0f - mu) / kPi * brdf_.base_color;  // 1 - max F <= 1
  if (smooth_ || part_ == Part::Base) return reflect_ * diffuse;
  const float zo = std::max(std::fabs(glm::dot(wo, ns_)), kMinCosine);
  const vec3 f0 = brdf_.dielectric_f0();
  const float f90 = brdf_.dielectric_f90();
  const float spec = ggx_term_bound(zo, ggx_alpha(brdf_.roughness), [&](float v_h) {
    const float w = schlick_weight(v_h);
    return (1.0f - mu) * max_component(f0 + (vec3(f90) - f0) * w) +
           mu * max_component(schlick_fresnel(brdf_.base_color, v_h));
  });
  return reflect_ * ((part_ == Part::Lobe ? vec3(0.0f) : diffuse) + vec3(spec));
}

float Bsdf::pdf(const vec3& wo, const vec3& wi) const {
  if (kind_ == Kind::Delta) return 0.0f;
  const vec3 ns = glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_;
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return 0.0f;
  if (kind_ == Kind::Lambertian)
    return std::max(0.0f, glm::dot(wi, ns)) / kPi;  // cosine-weighted about the shading normal
  const Frame f(ns);
  float p = 0.0f;
  eval_local(f.local(wo), f.local(wi), &p);
  return has_delta_ && part_ == Part::All ? (1.0f - delta_probability(wo)) * p : p;
}

float Bsdf::non_delta_albedo(float cos_o) const {
  // Estimates only (they choose between the parts; the weights stay exact): the diffuse base's
  // (1 - f0) max(base) and, for glossy lobes, Schlick's Fresnel at the macro normal. The floor
  // keeps the part's probability above 0 wherever it may reflect.
  const float mu = brdf_.metallic, f0 = max_component(brdf_.dielectric_f0());
  const float diffuse = (1.0f - mu) * (1.0f - f0) * max_component(brdf_.base_color);
  float a = part_ == Part::Lobe ? 0.0f : diffuse;
  if (!smooth_ && part_ != Part::Base)
    a += (1.0f - mu) * (f0 + (brdf_.dielectric_f90() - f0) * schlick_weight(cos_o)) +
         mu * max_component(schlick_fresnel(brdf_.base_color, cos_o));
  return reflect_ * std::max(a, 0.01f);
}

float Bsdf::delta_probability(const vec3& wo) const {
  if (kind_ != Kind::Layered) return kind_ == Kind::Delta ? 1.0f : 0.0f;
  if (!has_delta_) return 0.0f;
  SpecularBranch b[2];
  const int n = delta_branches(wo, Transport::Importance, b);
  float wd = 0.0f;
  for (int k = 0; k < n; ++k) wd += average(b[k].weight);
  const float wn = non_delta_albedo(std::fabs(glm::dot(wo, ns_)));
  return wd > 0.0f ? wd / (wd + wn) : 0.0f;
}

bool Bsdf::sample(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const {
  if (kind_ == Kind::Lambertian) {
    const bool front = glm::dot(wo, ng_) > 0.0f;
    const vec3 ng = front ? ng_ : -ng_;
    const vec3 ns = front ? ns_ : -ns_;
    // Drawn in this order: the arguments of an earlier call, which GCC evaluated right to left
    // (images stay bit-identical; the order is now explicit for every compiler).
    const float u2 = rng.next_float(), u1 = rng.next_float();
    out.wi = sample_cosine_hemisphere(ns, u1, u2);
    if (glm::dot(out.wi, ng) <= 0.0f) return false;  // below the true surface: absorbed
    // Cosine sampling cancels f cos / pdf to rho.
    out.weight = brdf_.base_color;
    out.pdf = glm::dot(out.wi, ns) / kPi;
    out.delta = false;
    return true;
  }
  if (kind_ == Kind::Delta) return sample_delta(wo, rng, mode, out);
  if (part_ != Part::All) return sample_non_delta(wo, rng, out);  // one term, no delta part
  const float pd = delta_probability(wo);
  if (pd > 0.0f) {
    const float u = rng.next_float();  // which part, then that part's numbers
    if (u < pd) {
      if (!sample_delta(wo, rng, mode, out)) return false;
      out.weight /= pd;
      return true;
    }
  }
  if (!sample_non_delta(wo, rng, out)) return false;
  out.weight /= 1.0f - pd;
  out.pdf *= 1.0f - pd;
  return true;
}

bool Bsdf::sample_non_delta_part(const vec3& wo, Rng& rng, BsdfSample& out) const {
  if (kind_ == Kind::Lambertian) return sample(wo, rng, Transport::Radiance, out);
  if (kind_ == Kind::Delta) return false;
  return sample_non_delta(wo, rng, out);
}

bool Bsdf::sample_non_delta(const vec3& wo, Rng& rng, BsdfSample& out) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;
  const Frame f(front ? ns_ : -ns_);
  const vec3 wo_l = f.local(wo);
  if (wo_l.z <= 0.0f) return false;  // seen from below the shading hemisphere
  if (part_ == Part::Lobe) {
    const float u1 = rng.next_float(), u2 = rng.next_float();
    vec3 wi_l, w;
    float p = 0.0f;
    if (!brdf_.sample_specular(wo_l, u1, u2, wi_l, w, p)) return false;
    out.wi = f.world(wi_l);
    out.weight = reflect_ * w;
    out.pdf = p;
  } else if (!smooth_ && part_ == Part::All) {
    const float u_lobe = rng.next_float(), u1 = rng.next_float(), u2 = rng.next_float();
    vec3 wi_l, w;
    float p = 0.0f;
    if (!brdf_.sample(wo_l, u_lobe, u1, u2, wi_l, w, p)) return false;
    out.wi = f.world(wi_l);
    out.weight = reflect_ * w;
    out.pdf = p;
  } else {
    const float u2 = rng.next_float(), u1 = rng.next_float();
    out.wi = sample_cosine_hemisphere(f.n, u1, u2);
    const vec3 wi_l = f.local(out.wi);
    float p = 0.0f;
    const vec3 value = eval_local(wo_l, wi_l, &p);
    if (!(p > 0.0f)) return false;
    out.weight = value * (wi_l.z / p);
    out.pdf = p;
  }
  out.delta = false;
  return glm::dot(out.wi, ng) > 0.0f;  // below the true surface: absorbed
}

bool Bsdf::sample_delta(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const {
  SpecularBranch b[2];
  const int n = delta_branches(wo, mode, b);
  if (n == 0) return false;
  int pick = 0;
  float p = 1.0f;
  if (n == 2) {
    // Reflection or refraction in proportion to their throughput.
    const float a0 = average(b[0].weight), a1 = average(b[1].weight);
    p = a0 / (a0 + a1);
    if (rng.next_float() >= p) {
      pick = 1;
      p = 1.0f - p;
    }
  }
  if (!(p > 0.0f)) return false;
  out.wi = b[pick].dir;
  out.weight = b[pick].weight / p;
  out.pdf = 0.0f;
  out.delta = true;
  return true;
}

int Bsdf::delta_branches(const vec3& wo, Transport mode, SpecularBranch out[2]) const {
  if (kind_ == Kind::Lambertian) return 0;
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;  // normals on wo's side
  const vec3 ns = front ? ns_ : -ns_;
  const float cos_i = std::fabs(glm::dot(wo, ns));
  vec3 mirror(0.0f);
  if (smooth_ && reflect_ > 0.0f) {
    // The mirror limit of the GGX lobes (h = n): appendix B's Fresnel terms at cos_i.
    const float mu = brdf_.metallic;
    const vec3 f0 = brdf_.dielectric_f0();
    const vec3 fd = f0 + (vec3(brdf_.dielectric_f90()) - f0) * schlick_weight(cos_i);
    mirror = reflect_ * ((1.0f - mu) * fd + mu * schlick_fresnel(brdf_.base_color, cos_i));
  }
  if (glass_ <= 0.0f) {
    if (!(max_component(mirror) > 0.0f)) return 0;
    out[0] = {reflect_checked(wo, ns, ng), mirror};
    return 1;
  }
  if (thin_) {
    // Thin-walled (KHR_materials_transmission without a volume): no refraction; Schlick's
    // Fresnel of the layer reflects, the rest goes straight through, tinted by base colour.
    const vec3 f0 = brdf_.dielectric_f0();
    const vec3 fr = f0 + (vec3(brdf_.dielectric_f90()) - f0) * schlick_weight(cos_i);
    out[0] = {reflect_checked(wo, ns, ng), mirror + glass_ * fr};
    out[1] = {-wo, brdf_.base_color * (glass_ * (1.0f - max_component(fr)))};
    return 2;
  }
  // A volume boundary: the exact Fresnel equations with total internal reflection (Schlick's
  // term has none from the dense side; KHR_materials_volume, "Implementation").
  const float eta = front ? brdf_.ior : 1.0f / brdf_.ior;  // eta_t / eta_i
  const float f = fresnel_dielectric(cos_i, eta);
  out[0] = {reflect_checked(wo, ns, ng), mirror + glass_ * f};
  if (f >= 1.0f) return 1;
  vec3 wt;
  if (!refract(wo, ns, eta, wt) || glm::dot(wt, ng) >= 0.0f) {
    if (!refract(wo, ng, eta, wt)) {
      // No transmission about either normal: all of the energy is reflected.
      out[0].weight = mirror + vec3(glass_);
      return 1;
    }
  }
  const float scale = mode == Transport::Radiance ? 1.0f / (eta * eta) : 1.0f;
  out[1] = {wt, glass_ * brdf_.base_color * ((1.0f - f) * scale)};
  return 2;
}

bool Bsdf::has_lobe_below(float below) const {
  if (kind_ != Kind::Layered || smooth_ || part_ != Part::All || !(brdf_.roughness < below))
    return false;
  return brdf_.metallic > 0.0f || brdf_.specular > 0.0f;
}

float Bsdf::lobe_probability(const vec3& wo) const {
  // specular_probability reads only the cosine of wo with the shading normal.
  return brdf_.specular_probability(vec3(0.0f, 0.0f, std::fabs(glm::dot(wo, ns_))));
}

Bsdf Bsdf::base_part() const {
  Bsdf b = *this;
  b.part_ = Part::Base;
  return b;
}

Bsdf Bsdf::lobe_part() const {
  Bsdf b = *this;
  b.part_ = Part::Lobe;
  return b;
}

}  // namespace pb
