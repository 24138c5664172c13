// glTF's material at a surface point (docs/materials.md): the Bsdf every stage asks, of
// directions in world space (the pure functions it is made of are in bsdf/scattering.h).
// Directions point away from the surface; n is the side the incoming direction is on. Its
// definitions, by operation: bsdf.cpp (construction, lobe_roughness), bsdf_eval.cpp (eval, pdf,
// the layering, terms() and restricted()), bsdf_bounds.cpp (max_f), bsdf_sample.cpp (sampling,
// lobe_share), bsdf_delta.cpp (delta branches and dispersion) and bsdf_glass.cpp (rough glass,
// diffuse transmission). Its terms and restricted() are general; SPPM's lobe split, made of them,
// is render/lobe_split.h (ESTIMATOR.md section 10).
#pragma once

#include "bsdf/microfacet.h"
#include "bsdf/scattering.h"
#include "scene/scene.h"
#include "util/math.h"
#include "util/rng.h"

#include <algorithm>

namespace pb {

// KHR_materials_dispersion's index of refraction for RGB channel 0, 1 or 2 (dispersion = 20 /
// Abbe number; ior is n_d, the index at 587.6 nm). The channels stand for the three lines that
// define the Abbe number, C (656.3 nm), d and F (486.1 nm): green keeps the material's ior and
// blue - red = (ior - 1) / V_d, the extension's implementation note's spread.
float dispersed_ior(float ior, float dispersion, int channel);

// How a transport quantity is carried: radiance (camera paths) picks up the (eta_i/eta_t)^2
// factor at refraction; photons carry flux and do not (Veach thesis section 5.2).
enum class Transport : uint8_t { Radiance, Importance };

// At most: the mirror of smooth lobes (with a thin wall's or a volume's Fresnel reflection), a
// transmission (three, one per RGB channel, through a dispersive volume), and a smooth clear
// coat's mirror about its own normal.
inline constexpr int kMaxDeltaBranches = 5;

// Rough glass at least this rough takes next-event light (Bsdf::glass_lit_directly).
inline constexpr float kGlassDirectRoughness = 0.4f;

struct SpecularBranch {
  vec3 dir{0.0f};
  vec3 weight{0.0f};  // throughput factor of the branch (Fresnel term included)
};

struct BsdfSample {
  vec3 wi{0.0f};      // the new direction, unit
  vec3 weight{0.0f};  // f |cos| / pdf; for a delta lobe, the branch weight over its probability
  float pdf = 0.0f;   // solid-angle pdf; 0 for a delta lobe
  bool delta = false;
  bool glass = false;  // drawn from rough glass (Bsdf::sample)
};

// The material's parameters at one surface point: the factors times the textures there.
struct BsdfParams {
  vec3 base_color{1.0f};
  float metallic = 1.0f, roughness = 1.0f, ior = 1.5f;
  float specular = 1.0f;
  vec3 specular_color{1.0f};
  float transmission = 0.0f;
  bool thin = true;
  float clearcoat = 0.0f, clearcoat_roughness = 0.0f;  // KHR_materials_clearcoat
  vec3 coat_normal{0.0f};  // the coat's shading normal; zero: ns (no clearcoatNormalTexture)
  vec3 sheen_color{0.0f};  // KHR_materials_sheen (black: no sheen)
  float sheen_roughness = 0.0f;
  // KHR_materials_anisotropy: the strength in [0, 1] and the direction of increased roughness
  // (world space; projected into ns's tangent plane). 0 or a direction along ns: isotropic.
  float anisotropy = 0.0f;
  vec3 anisotropy_direction{0.0f};
  // KHR_materials_iridescence: the film's weight (0: none), index and thickness in nm.
  float iridescence = 0.0f, iridescence_ior = 1.3f, iridescence_thickness = 400.0f;
  float dispersion = 0.0f;  // KHR_materials_dispersion: 20 / Abbe number (0: none)
  // KHR_materials_diffuse_transmission: the share of the diffuse base transmitted to the other
  // side (a Lambertian BTDF), and its colour.
  float diffuse_transmission = 0.0f;
  vec3 diffuse_transmission_color{1.0f};
  // A transmitting part of roughness at or above the mirror roughness is rough glass (a GGX
  // component, bsdf_glass.cpp) and diffuse transmission a Lambertian BTDF, both followed by
  // SPPM's camera paths; or, false, smooth glass and no diffuse transmission (its share
  // reflected), as PPM renders them (its fixed points cannot follow a path through a surface).
  bool follows_transmission = true;
  static BsdfParams of(const Material& m);  // the factors alone (no textures)
};

// The terms of a Bsdf's non-delta part (Bsdf::terms), and a set of them (Bsdf::restricted): the
// diffuse base, the base's GGX lobe, the clear coat's GGX lobe, the sheen, rough glass and
// diffuse transmission.
enum class Term : uint8_t { Diffuse, Lobe, Coat, Sheen, Glass, Transmission };

class TermSet {
 public:
  constexpr TermSet() = default;
  static constexpr TermSet all() { return TermSet(uint8_t((1u << 6) - 1u)); }
  constexpr bool has(Term t) const { return (bits_ >> unsigned(t)) & 1u; }
  constexpr TermSet with(Term t, bool add = true) const {
    return add ? TermSet(uint8_t(bits_ | (1u << unsigned(t)))) : *this;
  }
  constexpr TermSet operator&(TermSet o) const { return TermSet(uint8_t(bits_ & o.bits_)); }
  constexpr bool operator==(const TermSet&) const = default;

 private:
  explicit constexpr TermSet(uint8_t bits) : bits_(bits) {}
  uint8_t bits_ = 0;
};

// A material's scattering at one surface point, as World::surface() makes it: the one thing
// the camera pass, the photon pass, next-event estimation and the gather ask about a surface.
// Directions point away from the surface; either side may be hit (the normals are flipped to
// the side of wo where that matters).
//
// glTF's material (appendix B with KHR_materials_specular and KHR_materials_transmission) is
// linear in its parts, so it is kept as three weighted parts: metal m, opaque dielectric
// (1 - m)(1 - t) and transmitting dielectric (1 - m) t. The first two are MetalRoughBrdf (GGX
// and Lambertian, glossy); below the mirror roughness their GGX lobe becomes a perfect mirror
// (a delta branch) and the opaque part keeps its diffuse base (1 - max F(v.h)) base / pi. The
// transmitting part is always smooth: reflection and refraction (KHR_materials_volume) or
// straight transmission (thin-walled), both delta branches. eval() and pdf() are the non-delta
// parts; delta_branches() the delta ones.
//
// KHR_materials_clearcoat lays a GGX layer (ior 1.5, its own roughness and normal) over all of
// it: f = (1 - k) f_material + k D V (alpha = clearcoatRoughness^2, about the coat normal), k =
// clearcoat (0.04 + 0.96 (1 - |v.n_c|)^5) with v the view (the extension's fresnel_coat). The
// weight reads only the view, so f is not reciprocal: radiance transport takes v = wo, photons
// (Transport::Importance) the direction they leave in (the adjoint f*(wo, wi) = f(wi, wo), Veach
// thesis 3.7.6). A coat below the mirror roughness is a delta branch (the mirror limit of D V is
// a mirror of weight 1: k reflects).
//
// KHR_materials_anisotropy stretches the base's GGX lobe (metal and dielectric layer) along a
// direction in the tangent plane: the shading frame's x is that direction, and MetalRoughBrdf
// takes alpha mix(alpha, 1, strength^2) along it (microfacet.h).
//
// KHR_materials_sheen lies between the material and the coat: f_sheen + s f_material, f_sheen =
// sheen colour x D V (sheen.h), s = min(1 - max(sheen) E(wo), 1 - max(sheen) E(wi)) (its
// albedo scaling, in the reciprocal form it gives); delta branches are scaled by s as well.
class Bsdf {
 public:
  Bsdf() = default;
  Bsdf(const BsdfParams& p, const vec3& ng, const vec3& ns,
       float mirror_roughness = float(kDefaultMirrorRoughness));
  Bsdf(const Material& m, const vec3& ng, const vec3& ns,
       float mirror_roughness = float(kDefaultMirrorRoughness))
      : Bsdf(BsdfParams::of(m), ng, ns, mirror_roughness) {}
  // Whether a Bsdf of these parameters depends on its surface frame through ng and ns alone
  // (no anisotropy direction, no clear coat normal): then one built at any frame and moved to
  // another by move_to_frame is the one built there, bit for bit (World keeps one per untextured
  // material: the construction was 3% of a render's instructions).
  static bool frame_free(const BsdfParams& p) {
    return !(p.anisotropy > 0.0f) && !(std::clamp(p.clearcoat, 0.0f, 1.0f) > 0.0f);
  }
  // In place, on a copy assigned where it is kept: a copy returned by value and then read back
  // in 16-byte pieces across the normals just written stalled store forwarding (a quarter of
  // World::surface's time).
  void move_to_frame(const vec3& ng, const vec3& ns) {
    ng_ = ng;
    ns_ = ns;
  }

  // Only delta branches (smooth metal, smooth glass): no eval, no visible point.
  bool is_delta() const { return kind_ == Kind::Delta; }
  // Delta branches beside a non-delta part (a smooth dielectric coat over its diffuse base).
  bool has_delta() const { return kind_ == Kind::Delta || has_delta_; }
  // The Lambertian fast path (metallic 0, no transmission, specular 0): f is the constant
  // diffuse_f() for every pair of directions on the same side, so a gather may sum photon powers
  // first and multiply once (bit for bit what PPM did before this interface).
  bool is_lambertian() const { return kind_ == Kind::Lambertian; }
  vec3 diffuse_f() const { return lambertian(brdf_.base_color); }

  // f(wo, wi) of the non-delta part, without the cosine; 0 for wi on the other side of ng.
  vec3 eval(const vec3& wo, const vec3& wi) const;
  // What reaches wi on the other side of ng through the surface, f(wo, wi) for radiance (view
  // wo): diffuse transmission and, with `glass`, rough glass's; 0 on wo's side. Next-event light
  // through the surface (camera paths).
  vec3 eval_transmission(const vec3& wo, const vec3& wi, bool glass = true) const;
  bool has_rough_glass() const { return glass_in_part(); }
  // A part that transmits (rough glass, diffuse transmission): followed by SPPM's paths.
  bool transmits() const { return glass_in_part() || dt_in_part(); }
  bool transmits_diffusely() const { return dt_in_part(); }
  // Rough glass broad enough for next-event light (roughness at least kGlassDirectRoughness):
  // camera paths sample lights for it (through the surface too). A sharper one is lit only by
  // what the paths that follow it hit, since a light sample would land in its narrow lobe
  // rarely and then weigh its peak (glass seen at a roughness near the mirror's, under an
  // environment: single samples of 5e5 on a pixel of radiance 0.5).
  bool glass_lit_directly() const;
  Bsdf without_glass() const;  // this Bsdf less rough glass (next-event light for a sharp one)
  // An upper bound of eval(wo, wi) over every wi: what one photon can bring at a glossy point
  // (the sparse-photon bound, ESTIMATOR.md section 12).
  vec3 max_f(const vec3& wo) const;
  // Solid-angle pdf of sample()'s non-delta draws (times the probability of drawing that part).
  float pdf(const vec3& wo, const vec3& wi) const;
  // Draws wi (random numbers from rng, as many as the lobes need, in a fixed order); false when
  // the sample is absorbed (below the true surface) or carries nothing. With both parts the
  // delta part is drawn with delta_probability(wo); delta branches are chosen in proportion to
  // their average throughput. `tint` is what the path carries so far (any positive scale): a
  // dispersive volume's branches are chosen by their average throughput times it, so that a
  // path left with one channel does not pick another channel's refraction (the others ignore
  // it).
  // Rough glass (KHR_materials_transmission at a roughness above the mirror's) is a component
  // of its own, drawn with its albedo estimate's share: its reflection and its transmission
  // through the surface, which eval() never returns (a gather and next-event see only what
  // reaches their side).
  bool sample(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out,
              const vec3& tint = vec3(1.0f)) const;
  // Probability that sample() takes the delta part: 0 without one, 1 without a non-delta part,
  // otherwise in proportion to estimates of the two parts' albedos (photon weights: the same
  // for either transport direction).
  float delta_probability(const vec3& wo) const;
  // A direction from the non-delta part alone, the part a visible point here gathers with
  // (weight f |cos| / pdf of that part, radiance transport); false for a delta-only Bsdf. A
  // camera path that cannot gather here continues with it (camera_paths.h).
  bool sample_non_delta_part(const vec3& wo, Rng& rng, BsdfSample& out) const;
  // One delta branch, chosen in proportion to the branches' average weights (weight divided by
  // that probability; through a dispersive volume their average weights times `tint`); draws
  // one number when there are two branches or more.
  bool sample_delta(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out,
                    const vec3& tint = vec3(1.0f)) const;
  // The deterministic delta branches: the mirror reflection (smooth lobes and the transmitting
  // part's Fresnel reflection) and the transmission, refracted (KHR_materials_volume; closed
  // meshes in vacuum: the side of ng tells whether the path enters, eta = ior, or leaves,
  // eta = 1/ior) or straight through (thin-walled). Returns the count (0, 1 or 2; through a
  // dispersive volume 1 to 4: the reflection and one refraction per RGB channel, each carrying
  // its own channel alone).
  // With a smooth clear coat, its mirror about the coat normal is one more (merged with the
  // mirror when the directions agree); the others are weighted by 1 - k.
  int delta_branches(const vec3& wo, Transport mode, SpecularBranch out[kMaxDeltaBranches]) const;

  // The non-delta part's terms and their estimates, for an integrator that treats them apart
  // (SPPM's lobe split, render/lobe_split.h). terms() are those this Bsdf has (and keeps): the
  // diffuse base and the base's GGX lobe (not a mirror), the clear coat's GGX lobe (not a
  // mirror), the sheen, rough glass and diffuse transmission (a Lambertian Bsdf: its diffuse
  // base, whatever it keeps; a delta-only one: none).
  TermSet terms() const;
  // A clear coat or a sheen lies over the material: the non-delta part is the mixture of its
  // first four terms (term_albedos picks among them); without one the diffuse base and the lobe
  // are MetalRoughBrdf's two parts (unlayered_albedo, lobe_share).
  bool layered() const { return coat_ > 0.0f || sheen_max() > 0.0f; }
  // Estimates of the albedos of the kept terms Term::Diffuse, Lobe, Coat and Sheen, in that
  // order (0 for absent terms), as the layered non-delta part's sampling picks among them.
  static constexpr int kLayerTerms = 4;
  void term_albedos(const vec3& wo, float a[kLayerTerms]) const;
  // Estimates of rough glass's and diffuse transmission's albedos (bsdf_glass.cpp), kept or not;
  // meaningful only where the Bsdf has that term.
  float glass_albedo(const vec3& wo) const;
  float dt_albedo(const vec3& wo) const;
  // Without layers: the estimate of the kept diffuse base's and lobe's albedo seen from wo, and the
  // lobe's share of the two (MetalRoughBrdf:: specular_probability; 1 where the base is black).
  float unlayered_albedo(const vec3& wo) const {
    return non_delta_albedo(std::fabs(glm::dot(wo, ns_)));
  }
  float lobe_share(const vec3& wo) const;
  // The base lobe's roughness (an anisotropic lobe as the isotropic one of the same peak D),
  // and the clear coat's; whether the base lobe can reflect anything (metal, or a dielectric
  // layer with specular > 0).
  float lobe_roughness() const;
  float coat_roughness() const { return coat_roughness_; }
  bool lobe_reflects() const { return brdf_.metallic > 0.0f || brdf_.specular > 0.0f; }
  // This Bsdf with its non-delta part restricted to the terms in `keep` (and in its own kept
  // set): eval, max_f and pdf of those terms alone, and sample() draws from them alone, never a
  // delta branch (delta_branches() is unchanged). kept() is the set a Bsdf keeps (every term
  // unless restricted).
  Bsdf restricted(TermSet keep) const;
  TermSet kept() const { return keep_; }
  bool is_restricted() const { return !(keep_ == TermSet::all()); }

 private:
  enum class Kind : uint8_t { Lambertian, Layered, Delta };
  // eval and pdf of the non-delta part in the shading frame of wo's side (both above it).
  vec3 eval_local(const vec3& wo, const vec3& wi, float* pdf) const;
  float non_delta_albedo(float cos_o) const;
  bool sample_non_delta(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const;
  bool sample_base(const vec3& wo, Rng& rng, BsdfSample& out) const;  // the uncoated part
  int base_branches(const vec3& wo, Transport mode, SpecularBranch out[4]) const;
  vec3 smooth_mirror(float cos_i) const;  // the reflecting parts' mirror weight (0 unless smooth)
  int dispersive_branches(const vec3& wo, Transport mode, SpecularBranch out[4]) const;
  // The clear coat (no coat: k = 0). k at the view v; the coat lobe's D V about n_c on wo's side
  // and its sampling density; the non-delta f with the view v and its mixture density.
  float coat_weight(const vec3& v) const;
  bool coat_lobe() const { return coat_ > 0.0f && !coat_smooth_; }
  float coat_dv(const vec3& wo, const vec3& wi, float* pdf) const;
  vec3 eval_with_view(const vec3& wo, const vec3& wi, const vec3& v, float* pdf) const;
  // Under a coat or a sheen the non-delta part is up to four terms: the diffuse base, the
  // base's GGX lobe, the coat's and the sheen; a restricted Bsdf keeps some.
  static constexpr int kTerms = kLayerTerms;  // diffuse, the base's lobe, the coat's lobe, sheen
  struct Terms {
    bool diffuse, lobe, coat, sheen;
  };
  float sheen_max() const { return max_component(sheen_); }
  Terms term_flags() const;  // the first four of terms()
  bool keeps(Term t) const { return keep_.has(t); }
  float sheen_scaling(float cos_o, float cos_i) const;      // 1 without a sheen
  vec3 diffuse_term(const vec3& wo, const vec3& wi) const;  // local frame, both above
  float lobe_bound(const vec3& wo) const;                   // of F D V of the base's lobe (max_f)
  // The part sample() draws from apart from rough glass.
  bool sample_rest(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out,
                   const vec3& tint) const;
  // Rough glass (bsdf_glass.cpp), if kept: its f in world directions
  // on either side, times the layering above it (the sheen's scaling, 1 - k at the view v),
  // and the density of sample_glass; its draw; the estimate of its albedo that picks it; that
  // of the rest of this part; and a bound of its reflection's F D V (max_f).
  bool glass_in_part() const { return rough_glass_ && keeps(Term::Glass); }
  // Diffuse transmission (bsdf_glass.cpp), if kept: its f through the surface (local
  // directions, unlayered), its draw (cosine-weighted on the other side) and albedo estimate.
  bool dt_in_part() const { return dt_ > 0.0f && keeps(Term::Transmission); }
  vec3 dt_f(const vec3& lo, const vec3& li) const;
  bool sample_dt(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const;
  vec3 glass_fresnel(float cos_h, bool front) const;
  vec3 glass_f(const vec3& lo, const vec3& li, bool front, Transport mode, float* pdf) const;
  vec3 eval_glass(const vec3& wo, const vec3& wi, const vec3& v, Transport mode, float* pdf) const;
  bool sample_glass(const vec3& wo, Rng& rng, Transport mode, BsdfSample& out) const;
  // What the sheen and the coat above leave of a through (or glass) term: exactly, for
  // directions at cosines cos_o, cos_i with the coat read at the view v, and as an estimate of
  // albedo seen from wo.
  float under_layers(float cos_o, float cos_i, const vec3& v) const;
  float layers_albedo(const vec3& wo, float cos_o) const;
  float rest_albedo(const vec3& wo) const;
  float glass_reflection_bound(const vec3& wo) const;

  Kind kind_ = Kind::Lambertian;
  bool smooth_ = false;     // GGX lobes below the mirror roughness: delta branches
  bool has_delta_ = false;  // Layered with a delta part too
  bool thin_ = true;
  bool rough_glass_ = false;       // the transmitting part is a GGX component (bsdf_glass.cpp)
  float dt_ = 0.0f;                // KHR_materials_diffuse_transmission's share (0: none)
  vec3 dt_color_{1.0f};            // its colour
  float dispersion_ = 0.0f;        // KHR_materials_dispersion, of a volume (0: none)
  TermSet keep_ = TermSet::all();  // the terms restricted() keeps
  bool base_non_delta_ = false;    // the uncoated material has a non-delta part
  bool coat_smooth_ = false;       // the clear coat is a mirror
  // The reflecting parts as one MetalRoughBrdf whose metallic is m / (m + o), scaled by
  // reflect_ = m + o; the Lambertian kind keeps its reflectance in brdf_.base_color.
  MetalRoughBrdf brdf_;
  float reflect_ = 0.0f;
  float glass_ = 0.0f;            // (1 - m) t
  float coat_ = 0.0f;             // clearcoat (0: none)
  float coat_roughness_ = 0.0f;   // clearcoatRoughness (alpha: ggx_alpha of it)
  vec3 sheen_{0.0f};              // sheen colour (black: none)
  float sheen_roughness_ = 0.0f;  // sheenRoughness (alpha: sheen_alpha of it)
  vec3 ng_{0.0f}, ns_{0.0f};
  vec3 nc_{0.0f};       // the coat's normal, on ng's side
  vec3 tangent_{0.0f};  // KHR_materials_anisotropy's direction (unit, _|_ ns); 0: isotropic
};

}  // namespace pb
