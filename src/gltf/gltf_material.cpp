// The glTF loader's materials, lights and cameras (see gltf_loader_impl.h and the material rules
// at the top of gltf_loader.cpp).
#include "gltf/gltf_loader_impl.h"

#include "bsdf/microfacet.h"

#include <algorithm>
#include <cmath>

namespace pb::gltf {

double Loader::ext_number(const tinygltf::ExtensionMap& ext, const std::string& owner,
                          const char* name, const char* key, double fallback) const {
  const auto it = ext.find(name);
  if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key)) return fallback;
  const tinygltf::Value& v = it->second.Get(key);
  if (!v.IsNumber()) fail(owner + ": " + name + "." + key + " is not a number");
  return v.GetNumberAsDouble();
}

uint32_t Loader::material(int index, const std::string& where) {
  if (index == -1) {
    if (default_material_ < 0) {
      warn("primitives without a material use a default grey Lambertian material (0.8)");
      default_material_ = int64_t(scene_.materials.size());
      Material def = Material::lambertian(vec3(0.8f));
      def.name = "default";
      scene_.materials.push_back(def);
    }
    return uint32_t(default_material_);
  }
  if (index < 0 || size_t(index) >= m_.materials.size())
    fail(where + " refers to " + absent("material", index, m_.materials.size()));
  int64_t& slot = material_slot_[size_t(index)];
  if (slot < 0) {
    Material converted = convert_material(size_t(index));
    slot = int64_t(scene_.materials.size());
    scene_.materials.push_back(std::move(converted));
  }
  return uint32_t(slot);
}

std::optional<vec3> Loader::ext_color(const tinygltf::ExtensionMap& ext, const std::string& owner,
                                      const char* name, const char* key, double hi) const {
  const auto it = ext.find(name);
  if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key)) return std::nullopt;
  const tinygltf::Value& v = it->second.Get(key);
  vec3 out(0.0f);
  bool ok = v.IsArray() && v.ArrayLen() == 3;
  for (int c = 0; ok && c < 3; ++c) {
    const double x = v.Get(c).IsNumber() ? v.Get(c).GetNumberAsDouble() : -1.0;
    ok = x >= 0.0 && x <= hi;
    out[c] = float(x);
  }
  if (!ok)
    fail(owner + ": " + name + "." + key + " must be 3 numbers in [0, " +
         (std::isinf(hi) ? std::string("inf)") : num(hi) + "]"));
  return out;
}

Material Loader::convert_material(size_t index) {  // the rules are in the comment at the top
  const tinygltf::Material& gm = m_.materials[index];
  const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
  const std::string ml = label("material", gm.name, index);
  const tinygltf::ExtensionMap& ext = gm.extensions;
  Material out;
  out.name = gm.name.empty() ? "material " + std::to_string(index) : gm.name;
  auto unit = [&](double v, const char* what) {
    if (!(v >= 0.0 && v <= 1.0)) fail(ml + ": " + what + " " + num(v) + " is outside [0, 1]");
    return float(v);
  };
  const std::vector<double>& bc = pbr.baseColorFactor;
  if (bc.size() < 3) fail(ml + ": baseColorFactor has fewer than 3 numbers");
  if (!std::all_of(bc.begin(), bc.begin() + 3, [](double v) { return v >= 0.0 && v <= 1.0; }))
    fail(ml + ": baseColorFactor (" + num(bc[0]) + ", " + num(bc[1]) + ", " + num(bc[2]) +
         ") is outside [0, 1] (a reflectance above 1 would create energy)");
  out.base_color = vec3(float(bc[0]), float(bc[1]), float(bc[2]));
  out.alpha = bc.size() > 3 ? unit(bc[3], "the alpha of baseColorFactor") : 1.0f;
  out.metallic = unit(pbr.metallicFactor, "metallicFactor");
  out.roughness = unit(pbr.roughnessFactor, "roughnessFactor");
  out.base_color_texture = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                   pbr.baseColorTexture.extensions, ml + " baseColorTexture");
  const tinygltf::TextureInfo& mr = pbr.metallicRoughnessTexture;
  out.metallic_roughness_texture =
      texture(mr.index, mr.texCoord, mr.extensions, ml + " metallicRoughnessTexture");
  out.normal_texture = texture(gm.normalTexture.index, gm.normalTexture.texCoord,
                               gm.normalTexture.extensions, ml + " normalTexture");
  if (!std::isfinite(gm.normalTexture.scale)) fail(ml + ": normalTexture.scale is not finite");
  out.normal_scale = float(gm.normalTexture.scale);
  out.emissive_texture = texture(gm.emissiveTexture.index, gm.emissiveTexture.texCoord,
                                 gm.emissiveTexture.extensions, ml + " emissiveTexture");
  // occlusionTexture is a rasteriser's stand-in for the shadowing a path tracer computes: unread.

  const double ior = ext_number(ext, ml, "KHR_materials_ior", "ior", 1.5);
  if (!((ior >= 1.0 || ior == 0.0) && fits_float(ior)))
    fail(ml + ": ior " + num(ior) + " must be 0 or finite and >= 1");
  out.ior = float(ior);
  out.specular =
      unit(ext_number(ext, ml, "KHR_materials_specular", "specularFactor", 1.0), "specularFactor");
  out.specular_color =
      ext_color(ext, ml, "KHR_materials_specular", "specularColorFactor", 1e30).value_or(vec3(1));
  out.specular_texture = ext_texture(ext, ml, "KHR_materials_specular", "specularTexture");
  out.specular_color_texture =
      ext_texture(ext, ml, "KHR_materials_specular", "specularColorTexture");
  out.transmission =
      unit(ext_number(ext, ml, "KHR_materials_transmission", "transmissionFactor", 0.0),
           "transmissionFactor");
  out.transmission_texture =
      ext_texture(ext, ml, "KHR_materials_transmission", "transmissionTexture");
  // KHR_materials_volume: a thickness above 0 makes the mesh a volume boundary; the thickness
  // itself (and thicknessTexture) is a rasteriser's estimate of the distance a path tracer
  // traces, so only its sign is read.
  const double thickness = ext_number(ext, ml, "KHR_materials_volume", "thicknessFactor", 0.0);
  if (!(thickness >= 0.0)) fail(ml + ": thicknessFactor " + num(thickness) + " is below 0");
  out.thin = !(thickness > 0.0);
  const double distance =
      ext_number(ext, ml, "KHR_materials_volume", "attenuationDistance", INFINITY);
  if (!(distance > 0.0)) fail(ml + ": attenuationDistance " + num(distance) + " must be > 0");
  const vec3 color =
      ext_color(ext, ml, "KHR_materials_volume", "attenuationColor", 1.0).value_or(vec3(1));
  for (int c = 0; c < 3; ++c)  // sigma = -ln(c) / d (KHR_materials_volume, "Attenuation")
    out.attenuation[c] =
        std::isinf(distance) ? 0.0f : float(-std::log(double(color[c])) / distance);
  if (out.transmission > 0.0f || out.transmission_texture.present()) {
    if (!out.thin && out.ior == 0.0f) fail(ml + ": a volume boundary cannot have ior 0");
    if (!out.thin && ext.count("KHR_materials_specular"))
      warn(ml + ": KHR_materials_specular does not change a volume boundary (exact Fresnel)");
  }

  // KHR_materials_clearcoat: a GGX layer (ior 1.5) over the whole material, weighted by
  // clearcoat x Schlick's Fresnel at the coat normal's cosine with the view (Bsdf).
  out.clearcoat = unit(ext_number(ext, ml, "KHR_materials_clearcoat", "clearcoatFactor", 0.0),
                       "clearcoatFactor");
  out.clearcoat_roughness =
      unit(ext_number(ext, ml, "KHR_materials_clearcoat", "clearcoatRoughnessFactor", 0.0),
           "clearcoatRoughnessFactor");
  out.clearcoat_texture = ext_texture(ext, ml, "KHR_materials_clearcoat", "clearcoatTexture");
  out.clearcoat_roughness_texture =
      ext_texture(ext, ml, "KHR_materials_clearcoat", "clearcoatRoughnessTexture");
  out.clearcoat_normal_texture =
      ext_texture(ext, ml, "KHR_materials_clearcoat", "clearcoatNormalTexture");
  if (out.clearcoat_normal_texture.present()) {
    const tinygltf::Value& info = ext.at("KHR_materials_clearcoat").Get("clearcoatNormalTexture");
    if (info.Has("scale")) {
      const tinygltf::Value& v = info.Get("scale");
      if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
        fail(ml + ": KHR_materials_clearcoat.clearcoatNormalTexture.scale is not a finite number");
      out.clearcoat_normal_scale = float(v.GetNumberAsDouble());
    }
  }
  // KHR_materials_sheen: a Charlie sheen between the material and the coat (Bsdf, sheen.h).
  out.sheen_color =
      ext_color(ext, ml, "KHR_materials_sheen", "sheenColorFactor", 1.0).value_or(vec3(0.0f));
  out.sheen_roughness =
      unit(ext_number(ext, ml, "KHR_materials_sheen", "sheenRoughnessFactor", 0.0),
           "sheenRoughnessFactor");
  out.sheen_color_texture = ext_texture(ext, ml, "KHR_materials_sheen", "sheenColorTexture");
  out.sheen_roughness_texture =
      ext_texture(ext, ml, "KHR_materials_sheen", "sheenRoughnessTexture");
  if (max_component(out.sheen_color) == 0.0f)  // "If sheenColorFactor is zero, the whole sheen
    out.sheen_color_texture = out.sheen_roughness_texture = TextureRef{};  // layer is disabled"
  // KHR_materials_anisotropy: the base lobe's alpha along a direction in the tangent frame
  // (the tangent rotated by anisotropyRotation, or the texture's RG so rotated) becomes
  // mix(alpha, 1, strength^2); the strength is anisotropyStrength x the texture's B (Bsdf).
  out.anisotropy = unit(ext_number(ext, ml, "KHR_materials_anisotropy", "anisotropyStrength", 0.0),
                        "anisotropyStrength");
  const double rotation =
      ext_number(ext, ml, "KHR_materials_anisotropy", "anisotropyRotation", 0.0);
  if (!fits_float(rotation))
    fail(ml + ": anisotropyRotation " + num(rotation) + " is not a finite angle");
  out.anisotropy_rotation = float(std::remainder(rotation, 2.0 * M_PI));
  out.anisotropy_texture = ext_texture(ext, ml, "KHR_materials_anisotropy", "anisotropyTexture");
  if (out.anisotropy == 0.0f) out.anisotropy_texture = TextureRef{};  // strength 0: isotropic
  // KHR_materials_dispersion: the volume's index varies with the wavelength (Bsdf); it only
  // changes refraction, so a thin-walled material ignores it (warned).
  const double dispersion = ext_number(ext, ml, "KHR_materials_dispersion", "dispersion", 0.0);
  if (!(dispersion >= 0.0 && fits_float(dispersion)))
    fail(ml + ": dispersion " + num(dispersion) + " must be finite and at least 0");
  out.dispersion = float(dispersion);
  if (out.dispersion > 0.0f && out.thin)
    warn(ml + ": dispersion without KHR_materials_volume (thin-walled) has no effect");
  // KHR_materials_diffuse_transmission: the opaque dielectric's diffuse base transmits the share
  // diffuseTransmissionFactor x the texture's A through the surface, as a Lambertian BTDF of
  // diffuseTransmissionColorFactor x the colour texture (sRGB) (Bsdf).
  const char* dtx = "KHR_materials_diffuse_transmission";
  out.diffuse_transmission =
      unit(ext_number(ext, ml, dtx, "diffuseTransmissionFactor", 0.0), "diffuseTransmissionFactor");
  out.diffuse_transmission_color =
      ext_color(ext, ml, dtx, "diffuseTransmissionColorFactor", 1.0).value_or(vec3(1.0f));
  out.diffuse_transmission_texture = ext_texture(ext, ml, dtx, "diffuseTransmissionTexture");
  out.diffuse_transmission_color_texture =
      ext_texture(ext, ml, dtx, "diffuseTransmissionColorTexture");
  if (out.diffuse_transmission == 0.0f)  // the factor multiplies the texture: 0 is none
    out.diffuse_transmission_texture = out.diffuse_transmission_color_texture = TextureRef{};
  // KHR_materials_iridescence: a thin film whose Fresnel term (thin_film.h) is mixed into the
  // layers' by iridescenceFactor x the texture's R, of thickness mix(minimum, maximum, the
  // thickness texture's G) nanometres (the maximum without the texture).
  const char* irid = "KHR_materials_iridescence";
  out.iridescence = unit(ext_number(ext, ml, irid, "iridescenceFactor", 0.0), "iridescenceFactor");
  const double film_ior = ext_number(ext, ml, irid, "iridescenceIor", 1.3);
  if (!(film_ior >= 1.0 && fits_float(film_ior)))
    fail(ml + ": iridescenceIor " + num(film_ior) + " must be finite and at least 1");
  out.iridescence_ior = float(film_ior);
  const double thin = ext_number(ext, ml, irid, "iridescenceThicknessMinimum", 100.0);
  const double thick = ext_number(ext, ml, irid, "iridescenceThicknessMaximum", 400.0);
  for (const auto& [v, what] : {std::pair(thin, "iridescenceThicknessMinimum"),
                                std::pair(thick, "iridescenceThicknessMaximum")})
    if (!(v >= 0.0 && fits_float(v)))
      fail(ml + ": " + what + " " + num(v) + " must be finite and at least 0 (nanometres)");
  out.iridescence_thickness_minimum = float(thin);
  out.iridescence_thickness_maximum = float(thick);
  out.iridescence_texture = ext_texture(ext, ml, irid, "iridescenceTexture");
  out.iridescence_thickness_texture = ext_texture(ext, ml, irid, "iridescenceThicknessTexture");
  if (out.iridescence == 0.0f)  // "If iridescenceFactor is zero, the extension has no effect"
    out.iridescence_texture = out.iridescence_thickness_texture = TextureRef{};
  if (out.clearcoat == 0.0f) {  // the extension: clearcoatFactor 0 disables the whole layer
    out.clearcoat_texture = out.clearcoat_roughness_texture = out.clearcoat_normal_texture =
        TextureRef{};
  }

  specular_glossiness(ext, ml, out);
  const double strength =
      ext_number(ext, ml, "KHR_materials_emissive_strength", "emissiveStrength", 1.0);
  if (gm.emissiveFactor.size() != 3) fail(ml + ": emissiveFactor must have 3 numbers");
  for (int c = 0; c < 3; ++c) {
    const double e = gm.emissiveFactor[size_t(c)] * strength;
    if (!(e >= 0.0 && strength >= 0.0 && fits_float(e)))
      fail(ml + ": emission (emissiveFactor x emissiveStrength) must be finite and >= 0");
    out.emission[c] = float(e);
  }
  out.double_sided = gm.doubleSided;
  // KHR_materials_unlit: the base colour is painted (docs/materials.md "Unlit"); the other
  // properties, emission included, do not apply ("all other properties ... ignored").
  if (ext.count("KHR_materials_unlit")) {
    out.unlit = true;
    out.emission = vec3(0.0f);
  }
  if (gm.alphaMode == "MASK") {
    out.alpha_mode = AlphaMode::Mask;
    if (!(gm.alphaCutoff >= 0.0 && fits_float(gm.alphaCutoff)))
      fail(ml + ": alphaCutoff " + num(gm.alphaCutoff) + " must be finite and >= 0");
    out.alpha_cutoff = float(gm.alphaCutoff);
  } else if (gm.alphaMode == "BLEND") {
    out.alpha_mode = AlphaMode::Blend;  // alpha as coverage (docs/materials.md "Alpha")
  } else if (!gm.alphaMode.empty() && gm.alphaMode != "OPAQUE") {
    fail(ml + ": unknown alphaMode '" + one_line(gm.alphaMode) + "'");
  }
  return out;
}

// KHR_materials_pbrSpecularGlossiness (archived in 2021, and still in many files: Sketchfab's
// older downloads, Unity's and three.js's exporters; often without pbrMetallicRoughness, whose
// default would be a rough white metal). "Any client that supports the extension should always
// render the asset using the specular-glossiness material properties." Its BRDF inputs are
// c_diff = diffuse.rgb (1 - max(specular)), F0 = specular, alpha = (1 - glossiness)^2 with
// glTF's GGX, which is the dielectric of KHR_materials_specular with specularFactor 1 (F90 = 1)
// and f0 = min(0.04 x specularColor, 1) = specular for specularColor = specular / 0.04 at ior
// 1.5, over a base colour c_diff, roughness 1 - glossiness. The diffuse part is weighted by
// 1 - max F (the specular extension's rgb_mix) where the extension's appendix-B BRDF has 1 - F
// per channel: they differ only for a coloured specular.
void Loader::specular_glossiness(const tinygltf::ExtensionMap& ext, const std::string& ml,
                                 Material& out) {
  const char* name = "KHR_materials_pbrSpecularGlossiness";
  const auto it = ext.find(name);
  if (it == ext.end()) return;
  vec3 diffuse(1.0f);
  float alpha = 1.0f;
  if (it->second.IsObject() && it->second.Has("diffuseFactor")) {
    const tinygltf::Value& v = it->second.Get("diffuseFactor");
    bool ok = v.IsArray() && v.ArrayLen() == 4;
    for (int c = 0; ok && c < 4; ++c) {
      const double x = v.Get(c).IsNumber() ? v.Get(c).GetNumberAsDouble() : -1.0;
      ok = x >= 0.0 && x <= 1.0;
      (c < 3 ? diffuse[c] : alpha) = float(x);
    }
    if (!ok) fail(ml + ": " + name + ".diffuseFactor must be 4 numbers in [0, 1]");
  }
  const vec3 specular = ext_color(ext, ml, name, "specularFactor", 1.0).value_or(vec3(1.0f));
  const double gloss = ext_number(ext, ml, name, "glossinessFactor", 1.0);
  if (!(gloss >= 0.0 && gloss <= 1.0))
    fail(ml + ": glossinessFactor " + num(gloss) + " is outside [0, 1]");
  out.base_color = diffuse;
  out.alpha = alpha;
  out.base_color_texture = ext_texture(ext, ml, name, "diffuseTexture");
  out.metallic = 0.0f;
  out.metallic_roughness_texture = TextureRef{};
  out.roughness = 1.0f - float(gloss);
  out.ior = 1.5f;
  out.specular = 1.0f;
  out.specular_texture = out.specular_color_texture = TextureRef{};
  out.specular_color = specular / 0.04f;
  out.sg_specular = specular;
  out.sg_glossiness = float(gloss);
  out.specular_glossiness_texture = ext_texture(ext, ml, name, "specularGlossinessTexture");
  // With the texture, c_diff's factor (1 - max specular) varies per texel (World::surface).
  if (!out.specular_glossiness_texture.present()) out.base_color *= 1.0f - max_component(specular);
}

void Loader::add_light(const tinygltf::Node& n, const std::string& nl, const Xform& xf) {
  const tinygltf::Value& ext = n.extensions.at("KHR_lights_punctual");
  if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber())
    fail(nl + ": KHR_lights_punctual has no light index");
  const double li = ext.Get("light").GetNumberAsDouble();
  if (!(li >= 0.0 && li < double(m_.lights.size()) && li == std::floor(li)))
    fail(nl + " refers to " + absent("light", li, m_.lights.size()));
  const tinygltf::Light& gl = m_.lights[size_t(li)];
  const std::string ll = label("light", gl.name, size_t(li));
  PunctualLight out;
  out.name = gl.name.empty() ? "light " + num(li) : gl.name;
  if (gl.type != "point" && gl.type != "spot" && gl.type != "directional")
    fail(ll + " has unknown type '" + gl.type + "'");
  const std::vector<double> color = gl.color.empty() ? std::vector<double>(3, 1.0) : gl.color;
  if (color.size() != 3) fail(ll + ": color must have 3 numbers");
  // Radiant intensity per channel = color x intensity; for a directional light the irradiance on
  // a surface facing it (glTF's lux), in the image's radiance units times sr.
  for (int c = 0; c < 3; ++c) {
    const double v = color[size_t(c)] * gl.intensity;
    if (!(v >= 0.0 && gl.intensity >= 0.0 && color[size_t(c)] >= 0.0 && fits_float(v)))
      fail(ll + ": intensity and color must be finite and >= 0");
    out.intensity[c] = float(v);
  }
  if (gl.range > 0.0 && gl.type != "directional")
    warn(ll + ": range is ignored (inverse-square falloff)");
  if (gl.type == "directional") {  // light travels along the node's local -Z
    out.kind = PunctualKind::Directional;
    const dvec3 d = xf.direction(dvec3(0.0, 0.0, -1.0));
    if (!(glm::length(d) > 0.0))
      fail(ll + ": the light's direction is zero (" + nl + " is singular)");
    out.direction = vec3(glm::normalize(d));
    scene_.lights.push_back(std::move(out));
    return;
  }
  out.position = origin(xf, nl);
  if (gl.type == "spot") {
    out.kind = PunctualKind::Spot;
    const double inner = gl.spot.innerConeAngle, outer = gl.spot.outerConeAngle;
    if (!(inner >= 0.0 && inner < outer && outer <= kPiD / 2))
      fail(ll + ": spot cone angles inner " + num(inner) + ", outer " + num(outer) +
           " must satisfy 0 <= inner < outer <= pi/2");
    out.cos_inner = float(std::cos(inner));
    out.cos_outer = float(std::cos(outer));
    const dvec3 d = xf.direction(dvec3(0.0, 0.0, -1.0));
    if (!(glm::length(d) > 0.0)) fail(ll + ": the spot direction is zero (" + nl + " is singular)");
    out.direction = vec3(glm::normalize(d));
  }
  scene_.lights.push_back(std::move(out));
}

void Loader::add_camera(int index, const std::string& nl, const Xform& xf) {
  if (index < 0 || size_t(index) >= m_.cameras.size())
    fail(nl + " refers to " + absent("camera", index, m_.cameras.size()));
  const tinygltf::Camera& gc = m_.cameras[size_t(index)];
  const std::string cl = label("camera", gc.name, size_t(index));
  if (gc.type != "perspective") {
    warn(cl + " is " + gc.type + " and is skipped; only perspective cameras are supported");
    return;
  }
  Camera out;
  out.name = gc.name.empty() ? "camera " + std::to_string(index) : gc.name;
  const double yfov = gc.perspective.yfov;
  if (!(yfov > 0.0 && yfov < kPiD)) fail(cl + ": yfov " + num(yfov) + " must be in (0, pi)");
  out.yfov = float(yfov);
  if (gc.perspective.aspectRatio > 0.0 && fits_float(gc.perspective.aspectRatio))
    out.aspect = float(gc.perspective.aspectRatio);
  const dvec3 f = xf.direction(dvec3(0.0, 0.0, -1.0)), u = xf.direction(dvec3(0.0, 1.0, 0.0));
  const dvec3 fn = f / glm::length(f), uo = u - glm::dot(u, fn) * fn;  // Gram-Schmidt
  if (!(glm::length(f) > 0.0 && glm::length(uo) > 1e-9 * glm::length(u) && is_finite(vec3(uo))))
    fail(cl + ": " + nl + " has a degenerate transform (no forward or up direction)");
  out.position = origin(xf, nl);
  out.forward = vec3(fn);
  out.up = vec3(glm::normalize(uo));
  out.right = glm::normalize(glm::cross(out.forward, out.up));
  scene_.cameras.push_back(std::move(out));
}

vec3 Loader::origin(const Xform& xf, const std::string& nl) const {
  const dvec3 p = xf.point(dvec3(0.0));
  if (!(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) <= kMaxCoordinate))
    fail(nl + " is placed beyond the limit of 1e10 in world space");
  return vec3(p - scene_.origin);
}

}  // namespace pb::gltf
