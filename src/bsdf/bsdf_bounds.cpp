// The Bsdf's max_f: upper bounds of eval over every incoming direction (ESTIMATOR.md section
// 12).
#include "bsdf/bsdf.h"

#include "bsdf/sheen.h"

#include <algorithm>

namespace pb {

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
    const Terms t = term_flags();
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
  const vec3 kept_diffuse = keeps(Term::Diffuse) ? diffuse : vec3(0.0f);
  if (smooth_ || !keeps(Term::Lobe) || !base_non_delta_) return reflect_ * kept_diffuse + glass;
  return reflect_ * (kept_diffuse + vec3(lobe_bound(wo))) + glass;
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

}  // namespace pb
