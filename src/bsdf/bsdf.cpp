#include "bsdf/bsdf.h"

#include "bsdf/sheen.h"
#include "bsdf/thin_film.h"

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
  p.clearcoat = m.clearcoat;
  p.clearcoat_roughness = m.clearcoat_roughness;
  p.sheen_color = m.sheen_color;
  p.sheen_roughness = m.sheen_roughness;
  p.anisotropy = m.anisotropy;
  p.iridescence = m.iridescence;
  p.iridescence_ior = m.iridescence_ior;
  p.iridescence_thickness = m.iridescence_thickness_maximum;  // the texture's 1 (none: 1)
  p.dispersion = m.dispersion;
  p.diffuse_transmission = m.diffuse_transmission;
  p.diffuse_transmission_color = m.diffuse_transmission_color;
  return p;
}

Bsdf::Bsdf(const BsdfParams& p, const vec3& ng, const vec3& ns, float mirror_roughness)
    : thin_(p.thin), ng_(ng), ns_(ns) {
  brdf_.base_color = p.base_color;
  brdf_.roughness = p.roughness;
  brdf_.ior = p.ior;
  brdf_.specular = p.specular;
  brdf_.specular_color = p.specular_color;
  if (p.iridescence > 0.0f) {
    brdf_.iridescence = std::min(p.iridescence, 1.0f);
    brdf_.iridescence_ior = p.iridescence_ior;
    brdf_.iridescence_thickness = p.iridescence_thickness;
  }
  const float m = std::clamp(p.metallic, 0.0f, 1.0f), t = std::clamp(p.transmission, 0.0f, 1.0f);
  const float coat = std::clamp(p.clearcoat, 0.0f, 1.0f);
  const float sheen = max_component(p.sheen_color);
  const float dt = p.follows_transmission ? std::clamp(p.diffuse_transmission, 0.0f, 1.0f) : 0.0f;
  if (m == 0.0f && t == 0.0f && p.specular == 0.0f && coat == 0.0f && !(sheen > 0.0f) &&
      brdf_.iridescence == 0.0f && dt == 0.0f) {
    brdf_.metallic = 0.0f;
    reflect_ = 1.0f;
    return;  // kind_ Lambertian
  }
  // KHR_materials_transmission: dielectric = fresnel_mix(mix(diffuse, btdf, t), specular) is
  // (1 - t) fresnel_mix(diffuse, specular) + t fresnel_mix(btdf, specular): the parts split.
  glass_ = (1.0f - m) * t;
  // Rough glass (bsdf_glass.cpp) where the transmitting part's roughness is at or above the
  // mirror's, unless it is asked to be smooth (PPM). A volume of index 1 does not refract at any
  // microfacet: its transmission is straight through, a delta branch (Walter's half vector
  // eta wi + wo vanishes there).
  rough_glass_ = glass_ > 0.0f && p.follows_transmission && !(p.roughness < mirror_roughness) &&
                 (p.thin || std::fabs(p.ior - 1.0f) > 1e-4f);
  // KHR_materials_dispersion changes only a smooth volume's refraction.
  if (!p.thin && glass_ > 0.0f && p.dispersion > 0.0f && !rough_glass_) dispersion_ = p.dispersion;
  reflect_ = m + (1.0f - m) * (1.0f - t);
  brdf_.metallic = reflect_ > 0.0f ? m / reflect_ : 0.0f;
  // KHR_materials_diffuse_transmission: the opaque dielectric's diffuse base becomes
  // mix(diffuse_brdf(baseColor), diffuse_btdf(colour), dt); the BTDF is a component of its own
  // (bsdf_glass.cpp), the BRDF keeps 1 - dt.
  if (dt > 0.0f && reflect_ * (1.0f - brdf_.metallic) > 0.0f) {
    dt_ = dt;
    dt_color_ = glm::clamp(p.diffuse_transmission_color, vec3(0.0f), vec3(1.0f));
    brdf_.diffuse_weight = 1.0f - dt;
  }
  if (p.anisotropy > 0.0f) {  // KHR_materials_anisotropy: the direction in ns's tangent plane
    const vec3 d = p.anisotropy_direction - glm::dot(p.anisotropy_direction, ns) * ns;
    const float len = glm::length(d);
    if (len > 1e-6f && std::isfinite(len)) {
      tangent_ = d / len;
      brdf_.anisotropy = std::min(p.anisotropy, 1.0f);
    }
  }
  // A mirror only when the lobe is narrow in every direction (the anisotropic alpha_x).
  smooth_ = brdf_.anisotropy > 0.0f ? std::sqrt(brdf_.alpha_x()) < mirror_roughness
                                    : p.roughness < mirror_roughness;
  // A Lambertian under a coat or a sheen: its layer reflects nothing, so it has no mirror either.
  if ((coat > 0.0f || sheen > 0.0f) && m == 0.0f && p.specular == 0.0f) smooth_ = false;
  const float opaque = (1.0f - m) * (1.0f - t);
  base_non_delta_ = reflect_ > 0.0f && (!smooth_ || opaque > 0.0f);
  bool non_delta = base_non_delta_ || rough_glass_;
  bool delta = (glass_ > 0.0f && !rough_glass_) || (smooth_ && reflect_ > 0.0f);
  if (coat > 0.0f) {  // KHR_materials_clearcoat
    coat_ = coat;
    coat_smooth_ = p.clearcoat_roughness < mirror_roughness;
    coat_roughness_ = p.clearcoat_roughness;
    const float len = glm::length(p.coat_normal);
    nc_ = len > 0.0f ? p.coat_normal / len : ns;
    if (glm::dot(nc_, ng) < 0.0f) nc_ = -nc_;
    non_delta = non_delta || !coat_smooth_;
    delta = delta || coat_smooth_;
  }
  if (sheen > 0.0f) {  // KHR_materials_sheen: a broad lobe of its own, never a mirror
    sheen_ = glm::max(p.sheen_color, vec3(0.0f));
    sheen_roughness_ = p.sheen_roughness;
    non_delta = true;
  }
  kind_ = non_delta ? Kind::Layered : Kind::Delta;
  has_delta_ = non_delta && delta;
}

namespace {

// Directions in the shading frame (t, b, n) and back. With a tangent (unit, orthogonal to n:
// KHR_materials_anisotropy's direction) t is it; without, any basis (isotropic lobes).
struct Frame {
  vec3 t, b, n;
  explicit Frame(const vec3& normal) : n(normal) { orthonormal_basis(n, t, b); }
  Frame(const vec3& normal, const vec3& tangent) : n(normal) {
    if (tangent == vec3(0.0f)) {
      orthonormal_basis(n, t, b);
    } else {
      t = tangent;
      b = glm::cross(n, t);
    }
  }
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
    if (pdf) *pdf = brdf_.specular_pdf(wo, wi);
    return reflect_ * brdf_.eval_specular(wo, wi);
  }
  if (pdf) *pdf = wi.z / kPi;
  return diffuse_term(wo, wi);
}

vec3 Bsdf::diffuse_term(const vec3& wo, const vec3& wi) const {
  // The mirror limit of appendix B's dielectric: the GGX layer is a delta branch, the diffuse
  // base keeps its weight 1 - max F(v.h) at this pair's half vector (v.h averaged over both
  // directions, so that f stays reciprocal bit for bit). base_part() is the same term of a
  // rough lobe (MetalRoughBrdf::eval_diffuse computes it the same way).
  const vec3 h = glm::normalize(wo + wi);
  const float v_h = 0.5f * (glm::dot(wo, h) + glm::dot(wi, h));
  const vec3 fr = brdf_.layer_fresnel(v_h);
  const float opaque = reflect_ * (1.0f - brdf_.metallic);
  return (opaque * (1.0f - max_component(fr)) / kPi) * (brdf_.base_color * brdf_.diffuse_weight);
}

vec3 Bsdf::eval(const vec3& wo, const vec3& wi) const {
  if (kind_ == Kind::Delta) return vec3(0.0f);
  // Both directions on one side of the true surface: reflection only.
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return vec3(0.0f);
  if (kind_ == Kind::Lambertian) return diffuse_f();
  if (layered()) return eval_with_view(wo, wi, wo, nullptr);
  const Frame f(glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_, tangent_);
  const vec3 value = eval_local(f.local(wo), f.local(wi), nullptr);
  // Rough glass's reflection (its transmission reaches only the other side).
  return glass_in_part() ? value + eval_glass(wo, wi, wo, Transport::Radiance, nullptr) : value;
}

float Bsdf::coat_weight(const vec3& v) const {
  return clearcoat_fresnel(coat_, glm::dot(v, nc_));  // fresnel_coat at |v.n_c|
}

float Bsdf::coat_dv(const vec3& wo, const vec3& wi, float* pdf) const {
  if (pdf) *pdf = 0.0f;
  const Frame f(glm::dot(wo, ng_) > 0.0f ? nc_ : -nc_);
  const vec3 lo = f.local(wo), li = f.local(wi);
  if (lo.z <= 0.0f || li.z <= 0.0f) return 0.0f;
  const float alpha = ggx_alpha(coat_roughness_);
  if (pdf) *pdf = ggx_reflection_pdf(lo, li, alpha);
  // glTF's specular_brdf without its Fresnel (the coat's is in k): V D.
  return ggx_d(glm::normalize(lo + li), alpha) * ggx_visibility(lo.z, li.z, alpha);
}

Bsdf::Terms Bsdf::terms() const {
  const bool lobe = base_non_delta_ && !smooth_, coat = coat_lobe(), sheen = sheen_max() > 0.0f;
  switch (part_) {
    case Part::Lobe:
      return {false, lobe && follow_lobe_, coat && follow_coat_, false};
    case Part::Base:
      return {base_non_delta_, lobe && !follow_lobe_, coat && !follow_coat_, sheen};
    default:
      return {base_non_delta_, lobe, coat, sheen};
  }
}

float Bsdf::sheen_scaling(float cos_o, float cos_i) const {
  const float sm = sheen_max();
  if (!(sm > 0.0f)) return 1.0f;
  // KHR_materials_sheen's albedo scaling, in its reciprocal form: min over both directions of
  // 1 - max(sheen colour) E(cos), and not below 0 where E exceeds 1 (sheen.h).
  return std::max(0.0f, std::min(1.0f - sm * sheen_albedo(std::fabs(cos_o), sheen_roughness_),
                                 1.0f - sm * sheen_albedo(std::fabs(cos_i), sheen_roughness_)));
}

void Bsdf::term_albedos(const vec3& wo, float a[kTerms]) const {
  // Estimates only (they choose among the terms; the weights stay exact), as
  // non_delta_albedo's: the diffuse base's (1 - f0) max(base), Schlick's Fresnel at the macro
  // normal for the base's lobe, each x (1 - k) and under a sheen x (1 - max(sheen) E); k for
  // the coat's lobe (D V has albedo about 1) and (1 - k) max(sheen) E for the sheen. The floor
  // keeps each term's probability above 0.
  const Terms t = terms();
  const float k = coat_weight(wo), cos_o = std::fabs(glm::dot(wo, ns_));
  const float mu = brdf_.metallic, f0 = max_component(brdf_.dielectric_f0());
  const float sm = sheen_max();
  const float e = sm > 0.0f ? sm * sheen_albedo(cos_o, sheen_roughness_) : 0.0f;
  const float under = (1.0f - k) * std::max(0.0f, 1.0f - e) * reflect_;
  a[0] = t.diffuse ? std::max(under * (1.0f - mu) * (1.0f - f0) * brdf_.diffuse_weight *
                                  max_component(brdf_.base_color),
                              1e-3f)
                   : 0.0f;
  a[1] = t.lobe ? std::max(under * ((1.0f - mu) * (f0 + (brdf_.dielectric_f90() - f0) *
                                                            schlick_weight(cos_o)) +
                                    mu * max_component(schlick_fresnel(brdf_.base_color, cos_o))),
                           1e-3f)
                : 0.0f;
  a[2] = t.coat ? std::max(k, 1e-3f) : 0.0f;
  a[3] = t.sheen ? std::max((1.0f - k) * e, 1e-3f) : 0.0f;
}

vec3 Bsdf::eval_with_view(const vec3& wo, const vec3& wi, const vec3& v, float* pdf) const {
  const Frame f(glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_, tangent_);
  const vec3 lo = f.local(wo), li = f.local(wi);
  const Terms t = terms();
  vec3 under(0.0f);  // everything below the coat
  float p[kTerms] = {0.0f, 0.0f, 0.0f, 0.0f};
  if (lo.z > 0.0f && li.z > 0.0f) {
    vec3 base(0.0f);
    if (t.diffuse) {
      base += diffuse_term(lo, li);
      p[0] = li.z / kPi;
    }
    if (t.lobe) {
      base += reflect_ * brdf_.eval_specular(lo, li);
      p[1] = brdf_.specular_pdf(lo, li);
    }
    // Rough glass's reflection (drawn apart from these terms: sample()).
    if (glass_in_part())
      base += glass_f(lo, li, glm::dot(wo, ng_) > 0.0f, Transport::Radiance, nullptr);
    under = sheen_scaling(lo.z, li.z) * base;
    if (t.sheen) {  // f_sheen + scaling x f_material (KHR_materials_sheen, "albedo scaling")
      under += sheen_ * sheen_dv(lo, li, sheen_alpha(sheen_roughness_));
      p[3] = 1.0f / (2.0f * kPi);  // drawn uniformly over the hemisphere
    }
  }
  const float k = coat_weight(v);
  vec3 out = (1.0f - k) * under;
  if (t.coat) out += vec3(k * coat_dv(wo, wi, &p[2]));
  if (pdf) {  // the mixture sample_non_delta draws from (its choice reads wo alone)
    float a[kTerms];
    term_albedos(wo, a);
    float sum = 0.0f, mix = 0.0f;
    for (int j = 0; j < kTerms; ++j) {
      sum += a[j];
      mix += a[j] * p[j];
    }
    *pdf = sum > 0.0f ? mix / sum : 0.0f;
  }
  return out;
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
//
// For an anisotropic lobe (alpha_x >= alpha_y, microfacet.h) the same bound holds with D at
// alpha_x times alpha_x / alpha_y and V at alpha_y: hx^2/ax^2 + hy^2/ay^2 >= (hx^2 + hy^2)/ax^2
// gives D_aniso(h) <= (ax / ay) D(h; ax), equal at the peak h = n, and |(ax w.x, ay w.y, w.z)|
// >= smith_root(w; ay) gives V_aniso <= V(ay). alpha_v = alpha (scale 1) is the isotropic bound.
template <class Fresnel>
float ggx_term_bound(float zo, float alpha, Fresnel&& fresnel, float alpha_v = 0.0f,
                     float scale = 1.0f) {
  if (!(alpha_v > 0.0f)) alpha_v = alpha;
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
    best = std::max(best, fresnel(v_h) * ggx_d(h, alpha) * ggx_visibility(zo, z0, alpha_v));
  }
  return scale * best * (1.0f + 1e-4f);  // float rounding of the pieces
}

}  // namespace

float Bsdf::lobe_bound(const vec3& wo) const {
  const float mu = brdf_.metallic;
  const float zo = std::max(std::fabs(glm::dot(wo, ns_)), kMinCosine);
  const vec3 f0 = brdf_.dielectric_f0();
  const float f90 = brdf_.dielectric_f90();
  // Schlick's terms fall with v.h; the iridescent Fresnel does not, but it is at most 1.
  const float irid = brdf_.iridescence;
  const auto fresnel = [&](float v_h) {
    const float w = schlick_weight(v_h);
    const float schlick = (1.0f - mu) * max_component(f0 + (vec3(f90) - f0) * w) +
                          mu * max_component(schlick_fresnel(brdf_.base_color, v_h));
    return irid > 0.0f ? (1.0f - irid) * schlick + irid : schlick;
  };
  if (brdf_.anisotropy > 0.0f) {
    const float ax = brdf_.alpha_x(), ay = brdf_.alpha_y();
    return ggx_term_bound(zo, ax, fresnel, ay, ax / ay);
  }
  return ggx_term_bound(zo, ggx_alpha(brdf_.roughness), fresnel);
}

vec3 Bsdf::max_f(const vec3& wo) const {
  if (kind_ == Kind::Lambertian) return diffuse_f();
  if (kind_ == Kind::Delta) return vec3(0.0f);
  const float mu = brdf_.metallic;
  const vec3 diffuse = (1.0f - mu) / kPi * brdf_.base_color;  // 1 - max F <= 1
  if (layered()) {  // (1 - k) (f_sheen + s f_material) + k D V, k read at wo (the gather's view)
    const Terms t = terms();
    vec3 base(0.0f);
    if (t.diffuse) base += reflect_ * diffuse;
    if (t.lobe) base += vec3(reflect_ * lobe_bound(wo));
    if (glass_in_part()) base += vec3(glass_reflection_bound(wo));
    const float cos_o = std::fabs(glm::dot(wo, ns_));
    if (sheen_max() > 0.0f)  // s <= 1 - max(sheen) E(wo); D <= its horizon value, V <= 1
      base *= std::max(0.0f, 1.0f - sheen_max() * sheen_albedo(cos_o, sheen_roughness_));
    if (t.sheen) base += sheen_ * charlie_d_max(sheen_alpha(sheen_roughness_));
    const float k = coat_weight(wo);
    vec3 out = (1.0f - k) * base;
    if (t.coat) {
      const float zo = std::max(std::fabs(glm::dot(wo, nc_)), kMinCosine);
      out += vec3(k * ggx_term_bound(zo, ggx_alpha(coat_roughness_), [](float) { return 1.0f; }));
    }
    return out;
  }
  const vec3 glass(glass_in_part() ? glass_reflection_bound(wo) : 0.0f);
  if (smooth_ || part_ == Part::Base || !base_non_delta_) return reflect_ * diffuse + glass;
  return reflect_ * ((part_ == Part::Lobe ? vec3(0.0f) : diffuse) + vec3(lobe_bound(wo))) + glass;
}

float Bsdf::glass_reflection_bound(const vec3& wo) const {
  // Rough glass's reflection glass_ F D V: on a thin wall Schlick's layer term falls with v.h
  // (the film's is at most 1); a volume's exact term falls with v.h from outside, and from
  // inside total internal reflection makes it 1.
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const float zo = std::max(std::fabs(glm::dot(wo, ns_)), kMinCosine);
  const float irid = brdf_.iridescence;
  const auto fresnel = [&](float v_h) {
    float f = 1.0f;
    if (thin_) {
      const vec3 f0 = brdf_.dielectric_f0();
      f = max_component(f0 + (vec3(brdf_.dielectric_f90()) - f0) * schlick_weight(v_h));
    } else if (front) {
      f = fresnel_dielectric(v_h, brdf_.ior);
    }
    return irid > 0.0f ? (1.0f - irid) * f + irid : f;
  };
  return glass_ * ggx_term_bound(zo, ggx_alpha(brdf_.roughness), fresnel);
}

float Bsdf::pdf(const vec3& wo, const vec3& wi) const {
  if (kind_ == Kind::Delta) return 0.0f;
  const vec3 ns = glm::dot(wo, ng_) > 0.0f ? ns_ : -ns_;
  if (glm::dot(wo, ng_) * glm::dot(wi, ng_) <= 0.0f) return 0.0f;
  if (kind_ == Kind::Lambertian)
    return std::max(0.0f, glm::dot(wi, ns)) / kPi;  // cosine-weighted about the shading normal
  const Frame f(ns, tangent_);
  float p = 0.0f;
  if (layered())
    eval_with_view(wo, wi, wo, &p);
  else
    eval_local(f.local(wo), f.local(wi), &p);
  return has_delta_ && part_ == Part::All ? (1.0f - delta_probability(wo)) * p : p;
}

float Bsdf::non_delta_albedo(float cos_o) const {
  // Estimates only (they choose between the parts; the weights stay exact): the diffuse base's
  // (1 - f0) max(base) and, for glossy lobes, Schlick's Fresnel at the macro normal. The floor
  // keeps the part's probability above 0 wherever it may reflect.
  const float mu = brdf_.metallic, f0 = max_component(brdf_.dielectric_f0());
  const float diffuse =
      (1.0f - mu) * (1.0f - f0) * brdf_.diffuse_weight * max_component(brdf_.base_color);
  float a = part_ == Part::Lobe ? 0.0f : diffuse;
  if (!smooth_ && part_ != Part::Base)
    a += (1.0f - mu) * (f0 + (brdf_.dielectric_f90() - f0) * schlick_weight(cos_o)) +
         mu * max_component(schlick_fresnel(brdf_.base_color, cos_o));
  return reflect_ * std::max(a, 0.01f);
}

float Bsdf::delta_probability(const vec3& wo) const {
  if (kind_ != Kind::Layered) return kind_ == Kind::Delta ? 1.0f : 0.0f;
  if (!has_delta_) return 0.0f;
  SpecularBranch b[kMaxDeltaBranches];
  const int n = delta_branches(wo, Transport::Importance, b);
  float wd = 0.0f;
  for (int k = 0; k < n; ++k) wd += average(b[k].weight);
  float wn = base_non_delta_ ? non_delta_albedo(std::fabs(glm::dot(wo, ns_))) : 0.0f;
  if (layered()) {  // the coat's lobe (if rough), the sheen and the material under them
    float a[kTerms];
    term_albedos(wo, a);
    wn = a[0] + a[1] + a[2] + a[3];
  }
  if (glass_in_part()) wn += glass_albedo(wo);
  if (dt_in_part()) wn += dt_albedo(wo);
  return wd > 0.0f ? wd / (wd + wn) : 0.0f;
}

bool Bsdf::sample(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out,
                  const vec3& tint) const {
  if (transmits()) {
    // Rough glass, diffuse transmission or the rest of this part, by their albedo estimates,
    // each divided by its probability (an unbiased choice of one component of a sum).
    const float a[3] = {glass_in_part() ? glass_albedo(wo) : 0.0f,
                        dt_in_part() ? dt_albedo(wo) : 0.0f, rest_albedo(wo)};
    const float sum = a[0] + a[1] + a[2];
    int pick = a[0] > 0.0f ? 0 : 1;
    if (a[pick] < sum) {  // more than one: draw
      const float u = rng.next_float() * sum;
      pick = u < a[0] ? 0 : u < a[0] + a[1] ? 1 : 2;
      while (!(a[pick] > 0.0f)) --pick;  // rounding past the last one there is
    }
    const float p = a[pick] / sum;
    const bool drawn = pick == 0   ? sample_glass(wo, rng, mode, out)
                       : pick == 1 ? sample_dt(wo, rng, mode, out)
                                   : sample_rest(wo, rng, mode, out, tint);
    if (!drawn) return false;
    out.weight /= p;
    out.pdf *= p;
    return true;
  }
  return sample_rest(wo, rng, mode, out, tint);
}

float Bsdf::rest_albedo(const vec3& wo) const {
  // This part's estimate without rough glass and diffuse transmission: its delta branches (All)
  // and its non-delta terms.
  float a = 0.0f;
  if (part_ == Part::All && has_delta()) {
    SpecularBranch b[kMaxDeltaBranches];
    const int n = delta_branches(wo, Transport::Importance, b);
    for (int k = 0; k < n; ++k) a += average(b[k].weight);
  }
  if (layered()) {
    float t[kTerms];
    term_albedos(wo, t);
    return a + t[0] + t[1] + t[2] + t[3];
  }
  // (A diffuse base that transmits all, without a layer or metal, reflects nothing to draw.)
  const bool reflects =
      brdf_.diffuse_weight > 0.0f || brdf_.specular > 0.0f || brdf_.metallic > 0.0f;
  if (base_non_delta_ && reflects && (part_ == Part::All || follow_lobe_))
    a += non_delta_albedo(std::fabs(glm::dot(wo, ns_)));
  return a;
}

bool Bsdf::sample_rest(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out,
                       const vec3& tint) const {
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
  if (kind_ == Kind::Delta) return sample_delta(wo, rng, mode, out, tint);
  if (part_ != Part::All) return sample_non_delta(wo, rng, mode, out);  // one term, no delta
  const float pd = delta_probability(wo);
  if (pd > 0.0f) {
    const float u = rng.next_float();  // which part, then that part's numbers
    if (u < pd) {
      if (!sample_delta(wo, rng, mode, out, tint)) return false;
      out.weight /= pd;
      return true;
    }
  }
  if (!sample_non_delta(wo, rng, mode, out)) return false;
  out.weight /= 1.0f - pd;
  out.pdf *= 1.0f - pd;
  return true;
}

bool Bsdf::sample_non_delta_part(const vec3& wo, Rng& rng, BsdfSample& out) const {
  if (kind_ == Kind::Lambertian) return sample(wo, rng, Transport::Radiance, out);
  if (kind_ == Kind::Delta) return false;
  return sample_non_delta(wo, rng, Transport::Radiance, out);
}

bool Bsdf::sample_non_delta(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const {
  if (!layered()) return sample_base(wo, rng, out);
  // One of this part's terms by its albedo estimate, then the weight of the whole part over
  // the mixture density (one-sample, Veach thesis 9.2.4's balance heuristic), with the view
  // where the light leaves: wo for radiance, wi for photons.
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_, ns = front ? ns_ : -ns_;
  const Frame fs(ns);
  if (fs.local(wo).z <= 0.0f) return false;  // seen from below the shading hemisphere
  float a[kTerms];
  term_albedos(wo, a);
  float sum = 0.0f;
  int pick = 0, present = 0;
  for (int j = 0; j < kTerms; ++j) {
    sum += a[j];
    if (a[j] > 0.0f) {
      pick = j;  // the last term there is
      ++present;
    }
  }
  if (!(sum > 0.0f)) return false;
  if (present > 1) {
    const float u = rng.next_float() * sum;
    float acc = 0.0f;
    for (int j = 0; j < kTerms; ++j) {
      acc += a[j];
      if (a[j] > 0.0f && u < acc) {
        pick = j;
        break;
      }
    }
  }
  const float u1 = rng.next_float(), u2 = rng.next_float();
  vec3 wi;
  if (pick == 0) {
    wi = sample_cosine_hemisphere(ns, u1, u2);
  } else if (pick == 3) {  // uniform over the hemisphere: the sheen peaks toward its horizon
    const float z = u1, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * kPi * u2;
    vec3 t, b;
    orthonormal_basis(ns, t, b);
    wi = glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + z * ns);
  } else {
    const Frame f = pick == 1 ? Frame(ns, tangent_) : Frame(front ? nc_ : -nc_);
    const vec3 lo = f.local(wo);
    if (lo.z <= 0.0f) return false;
    const vec3 h = pick == 1 ? brdf_.sample_specular_normal(lo, u1, u2)
                             : sample_ggx_vndf(lo, ggx_alpha(coat_roughness_), u1, u2);
    const vec3 li = 2.0f * glm::dot(lo, h) * h - lo;
    if (li.z <= 0.0f) return false;
    wi = f.world(li);
  }
  if (glm::dot(wi, ng) <= 0.0f) return false;  // below the true surface: absorbed
  float p = 0.0f;
  const vec3 value = eval_with_view(wo, wi, mode == Transport::Radiance ? wo : wi, &p);
  const float cos_i = glm::dot(wi, ns);
  if (!(p > 0.0f) || !(cos_i > 0.0f)) return false;
  out.wi = wi;
  out.weight = value * (cos_i / p);
  out.pdf = p;
  out.delta = false;
  return true;
}

bool Bsdf::sample_base(const vec3& wo, Rng& rng, BsdfSample& out) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;
  const Frame f(front ? ns_ : -ns_, tangent_);
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

bool Bsdf::sample_delta(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out,
                        const vec3& tint) const {
  SpecularBranch b[kMaxDeltaBranches];
  const int n = delta_branches(wo, mode, b);
  if (n == 0) return false;
  int pick = 0;
  float p = 1.0f;
  if (dispersion_ > 0.0f) {
    // A dispersive volume: in proportion to what each branch would carry of this path. A
    // branch the path cannot use (another channel's refraction) is never drawn, and any it can
    // has a positive probability, so the weight w / p stays unbiased.
    float a[kMaxDeltaBranches], total = 0.0f;
    for (int k = 0; k < n; ++k) total += a[k] = average(glm::max(tint, vec3(0.0f)) * b[k].weight);
    if (!(total > 0.0f)) return false;
    const float u = rng.next_float() * total;
    float acc = 0.0f;
    pick = -1;
    for (int k = 0; k < n && pick < 0; ++k)
      if (a[k] > 0.0f && u < (acc += a[k])) pick = k;
    if (pick < 0)  // rounding past the end: the last branch that can be drawn
      for (int k = n - 1; k >= 0 && pick < 0; --k)
        if (a[k] > 0.0f) pick = k;
    p = a[pick] / total;
  } else if (n == 2) {
    // Reflection or refraction in proportion to their throughput.
    const float a0 = average(b[0].weight), a1 = average(b[1].weight);
    p = a0 / (a0 + a1);
    if (rng.next_float() >= p) {
      pick = 1;
      p = 1.0f - p;
    }
  } else if (n == 3) {
    const float a[3] = {average(b[0].weight), average(b[1].weight), average(b[2].weight)};
    const float total = a[0] + a[1] + a[2], u = rng.next_float() * total;
    pick = u < a[0] ? 0 : u < a[0] + a[1] ? 1 : 2;
    p = a[pick] / total;
  }
  if (!(p > 0.0f)) return false;
  out.wi = b[pick].dir;
  out.weight = b[pick].weight / p;
  out.pdf = 0.0f;
  out.delta = true;
  return true;
}

int Bsdf::delta_branches(const vec3& wo, Transport mode,
                         SpecularBranch out[kMaxDeltaBranches]) const {
  if (kind_ == Kind::Lambertian) return 0;
  const int n = base_branches(wo, mode, out);
  if (!layered()) return n;
  // Under a sheen each branch x its albedo scaling (wo and the branch's direction); under the
  // coat x (1 - k), k at the view (wo, or for photons the branch's own direction); a smooth
  // coat adds its mirror about n_c, of weight k.
  const float cos_o = glm::dot(wo, ns_);
  for (int j = 0; j < n; ++j)
    out[j].weight *= sheen_scaling(cos_o, glm::dot(out[j].dir, ns_)) *
                     (1.0f - coat_weight(mode == Transport::Radiance ? wo : out[j].dir));
  if (coat_ == 0.0f || !coat_smooth_) return n;
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 dir = reflect_checked(wo, front ? nc_ : -nc_, front ? ng_ : -ng_);
  const float k = coat_weight(mode == Transport::Radiance ? wo : dir);
  if (!(k > 0.0f)) return n;
  if (n > 0 && out[0].dir == dir) {
    out[0].weight += vec3(k);
    return n;
  }
  out[n] = {dir, vec3(k)};
  return n + 1;
}

vec3 Bsdf::smooth_mirror(float cos_i) const {
  if (!smooth_ || !(reflect_ > 0.0f)) return vec3(0.0f);
  // The mirror limit of the GGX lobes (h = n): appendix B's Fresnel terms at cos_i.
  const float mu = brdf_.metallic;
  return reflect_ * ((1.0f - mu) * brdf_.layer_fresnel(cos_i) + mu * brdf_.metal_fresnel(cos_i));
}

int Bsdf::base_branches(const vec3& wo, Transport mode, SpecularBranch out[4]) const {
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_;  // normals on wo's side
  const vec3 ns = front ? ns_ : -ns_;
  const float cos_i = std::fabs(glm::dot(wo, ns));
  const vec3 mirror = smooth_mirror(cos_i);
  if (glass_ <= 0.0f || rough_glass_) {  // rough glass is not a delta branch
    if (!(max_component(mirror) > 0.0f)) return 0;
    out[0] = {reflect_checked(wo, ns, ng), mirror};
    return 1;
  }
  if (thin_) {
    // Thin-walled (KHR_materials_transmission without a volume): no refraction; Schlick's
    // Fresnel of the layer reflects, the rest goes straight through, tinted by base colour.
    const vec3 fr = brdf_.layer_fresnel(cos_i);
    out[0] = {reflect_checked(wo, ns, ng), mirror + glass_ * fr};
    out[1] = {-wo, brdf_.base_color * (glass_ * (1.0f - max_component(fr)))};
    return 2;
  }
  if (dispersion_ > 0.0f) return dispersive_branches(wo, mode, out);
  // A volume boundary: the exact Fresnel equations with total internal reflection (Schlick's
  // term has none from the dense side; KHR_materials_volume, "Implementation").
  const float eta = front ? brdf_.ior : 1.0f / brdf_.ior;  // eta_t / eta_i
  const float f = fresnel_dielectric(cos_i, eta);
  // KHR_materials_iridescence on a volume: the film's Fresnel (of the volume's f0) mixed into
  // the exact one on the side the film faces, the outside; the refraction keeps 1 - its largest
  // channel (the extension's rgb_mix). From inside, the exact Fresnel alone.
  vec3 fr(f);
  if (brdf_.iridescence > 0.0f && front)
    fr = glm::mix(fr,
                  iridescent_fresnel(1.0f, brdf_.iridescence_ior, vec3(dielectric_f0(brdf_.ior)),
                                     brdf_.iridescence_thickness, cos_i),
                  brdf_.iridescence);
  out[0] = {reflect_checked(wo, ns, ng), mirror + glass_ * fr};
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
  out[1] = {wt, glass_ * brdf_.base_color * ((1.0f - max_component(fr)) * scale)};
  return 2;
}

float dispersed_ior(float ior, float dispersion, int channel) {
  // KHR_materials_dispersion: n(lambda) = max(n_d + (n_d - 1) / V_d (523655 / lambda^2 -
  // 1.5168), 1), V_d = 20 / dispersion, lambda in nm, at the C, d and F lines (bsdf.h).
  constexpr float kLambda[3] = {656.3f, 587.6f, 486.1f};
  const float l = kLambda[channel];
  return std::max(1.0f,
                  ior + (ior - 1.0f) * (dispersion / 20.0f) * (523655.0f / (l * l) - 1.5168f));
}

int Bsdf::dispersive_branches(const vec3& wo, Transport mode, SpecularBranch out[4]) const {
  // A dispersive volume boundary: each channel refracts by its own index, so the transmission
  // is up to three branches, channel c's carrying channel c alone (0 in the others), and the
  // reflection one branch whose exact Fresnel term differs per channel. A channel under total
  // internal reflection reflects whole. With a film (base_branches) the refractions keep 1 -
  // the largest mixed F, the extension's rgb_mix, so that dispersion 0+ meets dispersion 0.
  const bool front = glm::dot(wo, ng_) > 0.0f;
  const vec3 ng = front ? ng_ : -ng_, ns = front ? ns_ : -ns_;
  const float cos_i = std::fabs(glm::dot(wo, ns));
  const vec3 mirror = smooth_mirror(cos_i);
  const bool film = brdf_.iridescence > 0.0f && front;
  const vec3 film_f =
      film ? iridescent_fresnel(1.0f, brdf_.iridescence_ior, vec3(dielectric_f0(brdf_.ior)),
                                brdf_.iridescence_thickness, cos_i)
           : vec3(0.0f);
  vec3 fr(1.0f), dir[3];
  float eta[3];
  bool passes[3] = {false, false, false};
  for (int c = 0; c < 3; ++c) {
    eta[c] = front ? dispersed_ior(brdf_.ior, dispersion_, c)
                   : 1.0f / dispersed_ior(brdf_.ior, dispersion_, c);
    const float f = fresnel_dielectric(cos_i, eta[c]);
    if (f >= 1.0f || ((!refract(wo, ns, eta[c], dir[c]) || glm::dot(dir[c], ng) >= 0.0f) &&
                      !refract(wo, ng, eta[c], dir[c])))
      continue;  // no transmission about either normal: fr[c] stays 1
    fr[c] = film ? f + brdf_.iridescence * (film_f[c] - f) : f;
    passes[c] = true;
  }
  out[0] = {reflect_checked(wo, ns, ng), mirror + glass_ * fr};
  const float largest = max_component(fr);
  int n = 1;
  for (int c = 0; c < 3; ++c) {
    if (!passes[c]) continue;
    vec3 w(0.0f);
    w[c] = glass_ * brdf_.base_color[c] * (1.0f - (film ? largest : fr[c])) *
           (mode == Transport::Radiance ? 1.0f / (eta[c] * eta[c]) : 1.0f);
    out[n++] = {dir[c], w};
  }
  return n;
}

bool Bsdf::has_lobe_below(float below) const {
  if ((rough_glass_ || dt_ > 0.0f) && part_ == Part::All) return true;  // always followed
  if (layered())
    return kind_ == Kind::Layered && part_ == Part::All &&
           (follows_lobe(below) || follows_coat(below));
  if (kind_ != Kind::Layered || smooth_ || part_ != Part::All || !(lobe_roughness() < below))
    return false;
  return brdf_.metallic > 0.0f || brdf_.specular > 0.0f;
}

bool Bsdf::follows_lobe(float below) const {
  // With rough glass or diffuse transmission, followed anyway, the base's lobe is followed too:
  // a part then always splits as the lobes and the diffuse base.
  return base_non_delta_ && !smooth_ && (lobe_roughness() < below || rough_glass_ || dt_ > 0.0f) &&
         (brdf_.metallic > 0.0f || brdf_.specular > 0.0f);
}

float Bsdf::lobe_roughness() const {
  // An anisotropic lobe is followed or gathered as the isotropic one of the same peak D,
  // 1 / (pi ax ay): roughness (ax ay)^(1/4).
  if (!(brdf_.anisotropy > 0.0f)) return brdf_.roughness;
  return std::sqrt(std::sqrt(brdf_.alpha_x() * brdf_.alpha_y()));
}

bool Bsdf::follows_coat(float below) const { return coat_lobe() && coat_roughness_ < below; }

float Bsdf::lobe_probability(const vec3& wo, float below) const {
  // Rough glass and diffuse transmission are followed, always.
  const float glass =
      (rough_glass_ ? glass_albedo(wo) : 0.0f) + (dt_ > 0.0f ? dt_albedo(wo) : 0.0f);
  if (layered()) {  // the followed terms' share of the albedo estimates
    float all[kTerms], lobe[kTerms];
    term_albedos(wo, all);
    lobe_part(below).term_albedos(wo, lobe);
    float sum = glass, followed = glass;
    for (int j = 0; j < kTerms; ++j) {
      sum += all[j];
      followed += lobe[j];
    }
    return sum > 0.0f ? std::min(1.0f, followed / sum) : 0.0f;
  }
  // specular_probability reads only the cosine of wo with the shading normal.
  const float share = brdf_.specular_probability(vec3(0.0f, 0.0f, std::fabs(glm::dot(wo, ns_))));
  if (!rough_glass_ && !(dt_ > 0.0f)) return share;
  const float rest = base_non_delta_ ? non_delta_albedo(std::fabs(glm::dot(wo, ns_))) : 0.0f;
  const float lobe = follows_lobe(below) ? share * rest : 0.0f;
  return std::min(1.0f, (glass + lobe) / (glass + rest));
}

Bsdf Bsdf::base_part(float below) const {
  Bsdf b = *this;
  b.part_ = Part::Base;
  b.follow_lobe_ = follows_lobe(below);
  b.follow_coat_ = follows_coat(below);
  return b;
}

Bsdf Bsdf::lobe_part(float below) const {
  Bsdf b = *this;
  b.part_ = Part::Lobe;
  b.follow_lobe_ = follows_lobe(below);
  b.follow_coat_ = follows_coat(below);
  return b;
}

}  // namespace pb
