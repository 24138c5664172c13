// The Bsdf's delta branches: the smooth mirror, the smooth transmitting part's reflection and
// transmission, the smooth coat's mirror, a dispersive volume's per-channel refractions and
// their draw (bsdf.h).
#include "bsdf/bsdf.h"

#include "bsdf/thin_film.h"

#include <algorithm>

namespace pb {

namespace {

// Shading normals make tessellated spheres look smooth, but a direction computed from ns can
// end up on the wrong side of the true surface; then the geometric normal is used instead.
vec3 reflect_checked(const vec3& wo, const vec3& ns, const vec3& ng) {
  const vec3 r = reflect(wo, ns);
  return glm::dot(r, ng) > 0.0f ? r : reflect(wo, ng);
}

}  // namespace

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

}  // namespace pb
