// The Bsdf's sampling: the choice among its parts and the non-delta part's draws (bsdf.h).
#include "bsdf/bsdf.h"

#include "bsdf/bsdf_frame.h"

#include <algorithm>

namespace pb {

using bsdf_detail::Frame;

float Bsdf::non_delta_albedo(float cos_o) const {
  // Estimates only (they choose between the parts; the weights stay exact): the diffuse base's
  // (1 - f0) max(base) and, for glossy lobes, Schlick's Fresnel at the macro normal. The floor
  // keeps the part's probability above 0 wherever it may reflect.
  const float mu = brdf_.metallic, f0 = max_component(brdf_.dielectric_f0());
  const float diffuse =
      (1.0f - mu) * (1.0f - f0) * brdf_.diffuse_weight * max_component(brdf_.base_color);
  float a = keeps(Term::Diffuse) ? diffuse : 0.0f;
  if (!smooth_ && keeps(Term::Lobe))
    a += (1.0f - mu) * (f0 + (brdf_.dielectric_f90() - f0) * schlick_weight(cos_o)) +
         mu * max_component(schlick_fresnel(brdf_.base_color, cos_o));
  return reflect_ * std::max(a, 0.01f);
}

float Bsdf::lobe_share(const vec3& wo) const {
  // specular_probability reads only the cosine of wo with the shading normal.
  return brdf_.specular_probability(vec3(0.0f, 0.0f, std::fabs(glm::dot(wo, ns_))));
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
  // This part's estimate without rough glass and diffuse transmission: its delta branches
  // (unless restricted) and its non-delta terms.
  float a = 0.0f;
  if (!is_restricted() && has_delta()) {
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
  if (base_non_delta_ && reflects && (keeps(Term::Diffuse) || (keeps(Term::Lobe) && !smooth_)))
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
  if (is_restricted()) return sample_non_delta(wo, rng, mode, out);  // kept terms, no delta
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
  if (!keeps(Term::Diffuse)) {       // the lobe alone
    if (!keeps(Term::Lobe) || smooth_) return false;
    const float u1 = rng.next_float(), u2 = rng.next_float();
    vec3 wi_l, w;
    float p = 0.0f;
    if (!brdf_.sample_specular(wo_l, u1, u2, wi_l, w, p)) return false;
    out.wi = f.world(wi_l);
    out.weight = reflect_ * w;
    out.pdf = p;
  } else if (!smooth_ && keeps(Term::Lobe)) {
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

}  // namespace pb
