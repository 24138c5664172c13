// The glTF loader's materials, lights and cameras (see gltf_loader_impl.h and the material rules
// at the top of gltf_loader.cpp).
#include "gltf_loader_impl.h"

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
      Material def;
      def.name = "default";
      scene_.materials.push_back(def);  // Lambertian, base_color 0.8
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

Material Loader::convert_material(size_t index) {  // the rules are in the comment at the top
  const tinygltf::Material& gm = m_.materials[index];
  const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
  const std::string ml = label("material", gm.name, index);
  Material out;
  out.name = gm.name.empty() ? "material " + std::to_string(index) : gm.name;
  bool textured = pbr.baseColorTexture.index >= 0 || pbr.metallicRoughnessTexture.index >= 0 ||
                  gm.normalTexture.index >= 0 || gm.occlusionTexture.index >= 0 ||
                  gm.emissiveTexture.index >= 0;
  for (const auto& [name, value] : gm.extensions)  // e.g. transmissionTexture
    for (const std::string& key : value.Keys())
      textured |= key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0;
  if (textured) warn("textures are not read; factors are used");
  const std::vector<double>& bc = pbr.baseColorFactor;
  if (bc.size() < 3) fail(ml + ": baseColorFactor has fewer than 3 numbers");
  if (!std::all_of(bc.begin(), bc.begin() + 3, [](double v) { return v >= 0.0 && v <= 1.0; }))
    fail(ml + ": baseColorFactor (" + num(bc[0]) + ", " + num(bc[1]) + ", " + num(bc[2]) +
         ") is outside [0, 1] (a reflectance above 1 would create energy)");
  out.base_color = vec3(float(bc[0]), float(bc[1]), float(bc[2]));
  const tinygltf::ExtensionMap& ext = gm.extensions;
  const double transmission =
      ext_number(ext, ml, "KHR_materials_transmission", "transmissionFactor", 0.0);
  if (transmission > 0.0) {
    out.model = Reflection::Dielectric;
    const double ior = ext_number(ext, ml, "KHR_materials_ior", "ior", 1.5);
    if (!(ior >= 1.0 && fits_float(ior)))
      fail(ml + ": ior " + num(ior) + " must be finite and >= 1");
    out.ior = float(ior);
    if (transmission < 1.0)
      warn(ml + ": transmissionFactor " + num(transmission) + " treated as clear glass");
  } else if (pbr.metallicFactor >= 0.5) {
    out.model = Reflection::Mirror;
    if (pbr.roughnessFactor > 0.05)
      warn(ml + ": roughness " + num(pbr.roughnessFactor) + " treated as a smooth mirror");
  } else {
    out.model = Reflection::Lambertian;
  }
  const double strength =
      ext_number(ext, ml, "KHR_materials_emissive_strength", "emissiveStrength", 1.0);
  if (gm.emissiveFactor.size() != 3) fail(ml + ": emissiveFactor must have 3 numbers");
  for (int c = 0; c < 3; ++c) {
    const double e = gm.emissiveFactor[size_t(c)] * strength;
    if (!(e >= 0.0 && strength >= 0.0 && fits_float(e)))
      fail(ml + ": emission (emissiveFactor x emissiveStrength) must be finite and >= 0");
    out.emission[c] = float(e);
  }
  return out;
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
  return vec3(p);
}

}  // namespace pb::gltf
