// World::surface(): a hit's geometry, texture coordinates and Bsdf (glTF's factors times its
// textures, and the normal texture), and the note about lobes rendered as mirrors.
#include "world/world.h"

#include <algorithm>
#include <cstdio>

namespace pb {

namespace {

// The tangent-space normal of a normal texture (glTF 2.0 "normalTexture": RGB in [0, 1] maps to
// [-1, 1], X and Y scaled by normal_scale) in the frame (tangent, bitangent, ns); ns when the
// frame or the result is degenerate or the result falls below the true surface.
vec3 mapped_normal(const vec3& ns, const vec3& ng, const glm::vec4& tangent, const vec3& tex,
                   float scale) {
  vec3 t = vec3(tangent) - glm::dot(vec3(tangent), ns) * ns;  // Gram-Schmidt against ns
  const float len = glm::length(t);
  if (!(len > 1e-6f)) return ns;
  t /= len;
  const vec3 b = glm::cross(ns, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
  const vec3 c = 2.0f * tex - 1.0f;
  const vec3 n = (c.x * scale) * t + (c.y * scale) * b + c.z * ns;
  const float nl = glm::length(n);
  if (!(nl > 0.0f)) return ns;
  const vec3 unit = n / nl;
  return glm::dot(unit, ng) > 1e-3f ? unit : ns;
}

// KHR_materials_anisotropy's direction in world space, in the tangent frame (t, b, ns) of the
// interpolated normal (before normal mapping, as the extension's TBN): (1, 0), or the texture's
// RG mapped to [-1, 1] and normalised, rotated by anisotropyRotation toward b; the texture's B
// multiplies the strength. Zero (isotropic) where the frame or the texel's direction vanishes.
vec3 anisotropy_direction(const Material& m, const vec3& ns, const glm::vec4& tangent,
                          std::span<const Image> images, const vec2 uv[2], float& strength) {
  vec3 t = vec3(tangent) - glm::dot(vec3(tangent), ns) * ns;
  const float len = glm::length(t);
  if (!(len > 1e-6f)) return vec3(0.0f);
  t /= len;
  const vec3 b = glm::cross(ns, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
  vec2 d(1.0f, 0.0f);
  if (m.anisotropy_texture.present()) {
    const glm::vec4 tex = lookup(images, m.anisotropy_texture, uv, false);
    d = 2.0f * vec2(tex.x, tex.y) - 1.0f;
    const float dl = glm::length(d);
    if (!(dl > 1e-6f)) return vec3(0.0f);
    d /= dl;
    strength *= std::clamp(tex.z, 0.0f, 1.0f);
  }
  const float c = std::cos(m.anisotropy_rotation), sn = std::sin(m.anisotropy_rotation);
  const vec2 r(c * d.x - sn * d.y, sn * d.x + c * d.y);  // counter-clockwise, t toward b
  return r.x * t + r.y * b;
}

// The hit's triangle: its corners' vertex indices and barycentric weights (w, hit.u, hit.v).
struct Corners {
  const Hit& hit;
  uint32_t i0, i1, i2;
  float w;  // 1 - hit.u - hit.v
  // A vertex attribute at the hit: w a[i0] + u a[i1] + v a[i2].
  template <class T>
  T at(const T* a) const {
    return w * a[i0] + hit.u * a[i1] + hit.v * a[i2];
  }
};

// The hit's position, error bound (ray_offset.h), geometric and interpolated shading normals.
Surface geometry(const vec3* positions, const vec3* normals, const vec3& ng, const Corners& c) {
  Surface s;
  // Barycentric interpolation is more accurate than origin + t dir far from the origin.
  s.position = c.at(positions);
  s.ng = ng;
  s.error = surface_error(positions[c.i0], positions[c.i1], positions[c.i2], s.ng);
  s.ns = s.ng;
  if (normals) {
    const vec3 n = c.at(normals);
    const float len = glm::length(n);
    if (len > 0.0f) {
      s.ns = n / len;
      if (glm::dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
    }
  }
  return s;
}

// The base layer's factors times its textures (glTF 2.0 "Metallic-Roughness Material").
void base_textures(BsdfParams& p, const Material& m, std::span<const Image> images,
                   const vec2 uv[2], const glm::vec4* colors, const Corners& c) {
  // Each texture multiplies its factor; colour textures are sRGB, the others linear; metalness
  // in B, roughness in G.
  p.base_color *= vec3(lookup(images, m.base_color_texture, uv, true));
  if (colors)  // COLOR_0 multiplies the base colour (glTF 2.0 "Metallic-Roughness Material")
    p.base_color *= vec3(c.at(colors));
  const glm::vec4 mr = lookup(images, m.metallic_roughness_texture, uv, false);
  p.metallic *= mr.z;   // B: metalness
  p.roughness *= mr.y;  // G: roughness
  if (m.specular_glossiness_texture.present()) {
    // KHR_materials_pbrSpecularGlossiness (gltf_material.cpp): specular = factor x RGB (sRGB),
    // glossiness = factor x A; c_diff = diffuse (1 - max specular), f0 = specular.
    const glm::vec4 sg = lookup(images, m.specular_glossiness_texture, uv, true);
    const vec3 specular = m.sg_specular * vec3(sg);
    p.base_color *= 1.0f - max_component(specular);
    p.specular_color = specular / 0.04f;
    p.roughness = 1.0f - m.sg_glossiness * sg.w;
  }
}

// The KHR_materials_* layers' factors times their textures (each extension cited at its layer).
void extension_textures(BsdfParams& p, const Material& m, std::span<const Image> images,
                        const vec2 uv[2]) {
  p.transmission *= lookup(images, m.transmission_texture, uv, false).x;
  if (p.diffuse_transmission > 0.0f) {  // KHR_materials_diffuse_transmission: A; colour sRGB
    p.diffuse_transmission *= lookup(images, m.diffuse_transmission_texture, uv, false).w;
    p.diffuse_transmission_color *=
        vec3(lookup(images, m.diffuse_transmission_color_texture, uv, true));
  }
  p.specular *= lookup(images, m.specular_texture, uv, false).w;
  p.specular_color *= vec3(lookup(images, m.specular_color_texture, uv, true));
  if (p.clearcoat > 0.0f) {  // KHR_materials_clearcoat: clearcoat x R, roughness x G
    p.clearcoat *= lookup(images, m.clearcoat_texture, uv, false).x;
    p.clearcoat_roughness *= lookup(images, m.clearcoat_roughness_texture, uv, false).y;
  }
  if (max_component(p.sheen_color) > 0.0f) {  // KHR_materials_sheen: colour sRGB, roughness A
    p.sheen_color *= vec3(lookup(images, m.sheen_color_texture, uv, true));
    p.sheen_roughness *= lookup(images, m.sheen_roughness_texture, uv, false).w;
  }
  if (p.iridescence > 0.0f) {  // KHR_materials_iridescence: factor x R; thickness mixed by G
    p.iridescence *= lookup(images, m.iridescence_texture, uv, false).x;
    if (m.iridescence_thickness_texture.present())
      p.iridescence_thickness =
          glm::mix(m.iridescence_thickness_minimum, m.iridescence_thickness_maximum,
                   lookup(images, m.iridescence_thickness_texture, uv, false).y);
  }
}

// Anisotropy direction, coat normal and mapped ns in the tangent frame (glTF 2.0 "normalTexture").
void tangent_frame(BsdfParams& p, vec3& ns, const vec3& ng, const Material& m,
                   std::span<const Image> images, const vec2 uv[2], const glm::vec4* tangents,
                   const Corners& c) {
  const glm::vec4 t = c.at(tangents);
  if (p.anisotropy > 0.0f)
    p.anisotropy_direction = anisotropy_direction(m, ns, t, images, uv, p.anisotropy);
  // The coat's normal: its own texture, or the interpolated normal ("no normal mapping is
  // applied to the clear coat layer, even if normal mapping is applied to the base").
  if (p.clearcoat > 0.0f && m.clearcoat_normal_texture.present())
    p.coat_normal =
        mapped_normal(ns, ng, t, vec3(lookup(images, m.clearcoat_normal_texture, uv, false)),
                      m.clearcoat_normal_scale);
  else
    p.coat_normal = ns;
  if (m.normal_texture.present()) {
    const vec3 tex = vec3(lookup(images, m.normal_texture, uv, false));
    ns = mapped_normal(ns, ng, t, tex, m.normal_scale);
  }
}

}  // namespace

// The hit's Surface by phases: geometry; if textured, uv, textured factors, tangent frame; Bsdf.
Surface World::surface(const Hit& hit) const {
  const MeshView& mesh = meshes_[hit.mesh];
  const uint32_t* tri = mesh.indices + 3 * size_t(hit.prim);
  const Corners c{hit, tri[0], tri[1], tri[2], 1.0f - hit.u - hit.v};
  Surface s = geometry(mesh.positions, mesh.normals, mesh.face_normals[hit.prim], c);
  const Material& m = *mesh.material;
  s.material = &m;
  if (m.unlit) {  // painted, black to light (docs/materials.md "Unlit")
    for (int set = 0; set < 2; ++set)
      if (mesh.texcoords[set]) s.uv[set] = c.at(mesh.texcoords[set]);
    s.painted = m.base_color * vec3(lookup(scene_.images, m.base_color_texture, s.uv, true));
    if (mesh.colors) s.painted *= vec3(c.at(mesh.colors));
    s.bsdf = Bsdf(BsdfParams::of(Material::lambertian(vec3(0.0f))), s.ng, s.ns, mirror_roughness_);
    return s;
  }
  if (mesh.plain) {
    s.bsdf = *mesh.plain;
    s.bsdf.move_to_frame(s.ng, s.ns);
    return s;
  }
  if (!mesh.textured) {
    BsdfParams p = BsdfParams::of(m);
    p.follows_transmission = follows_transmission_;
    s.bsdf = Bsdf(p, s.ng, s.ns, mirror_roughness_);
    return s;
  }
  for (int set = 0; set < 2; ++set) {
    const vec2* uv = mesh.texcoords[set];
    if (uv) s.uv[set] = c.at(uv);
  }
  const std::span<const Image> images = scene_.images;
  BsdfParams p = BsdfParams::of(m);
  p.follows_transmission = follows_transmission_;
  base_textures(p, m, images, s.uv, mesh.colors, c);
  extension_textures(p, m, images, s.uv);
  if (mesh.tangents &&
      (m.normal_texture.present() || m.clearcoat_normal_texture.present() || p.anisotropy > 0.0f))
    tangent_frame(p, s.ns, s.ng, m, images, s.uv, mesh.tangents, c);
  s.bsdf = Bsdf(p, s.ng, s.ns, mirror_roughness_);
  return s;
}

bool World::may_hold_points(const Material& m) const {
  if (m.metallic_roughness_texture.present() || m.transmission_texture.present() ||
      m.specular_glossiness_texture.present())
    return true;
  if (m.anisotropy > 0.0f) return true;  // a mirror's roughness with anisotropy is a lobe
  const vec3 n(0.0f, 0.0f, 1.0f);
  BsdfParams p = BsdfParams::of(m);
  p.follows_transmission = follows_transmission_;
  return !Bsdf(p, n, n, mirror_roughness_).is_delta();
}

std::string World::mirror_note() const {
  std::string names;
  size_t count = 0;
  for (const Material& m : scene_.materials) {
    float lowest = m.roughness;
    if (m.metallic_roughness_texture.present()) {
      // The smallest roughness the texture holds (G channel).
      const Image& im = scene_.images[size_t(m.metallic_roughness_texture.image)];
      float g = 1.0f;
      for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) g = std::min(g, texel(im, x, y, false).y);
      lowest *= g;
    }
    if (m.anisotropy > 0.0f && !m.anisotropy_texture.present()) {
      // KHR_materials_anisotropy: a mirror only when narrow along its direction too (Bsdf).
      MetalRoughBrdf b;
      b.roughness = lowest;
      b.anisotropy = m.anisotropy;
      lowest = std::sqrt(b.alpha_x());
    }
    // A GGX lobe that reflects: the metal, or the specular layer of the opaque dielectric
    // (glass transmits through smooth branches at any roughness; Lambertians have no layer).
    const bool textured = m.metallic_roughness_texture.present() ||
                          m.transmission_texture.present() || m.specular_texture.present();
    const bool lobe = m.metallic > 0.0f || (m.specular > 0.0f && m.transmission < 1.0f) || textured;
    if (!lobe || !(lowest < mirror_roughness_)) continue;
    if (++count <= 4) names += std::string(names.empty() ? "" : ", ") + "'" + m.name + "'";
  }
  if (count == 0) return "";
  if (count > 4) names += " and " + std::to_string(count - 4) + " more";
  char threshold[32];
  std::snprintf(threshold, sizeof threshold, "%g", double(mirror_roughness_));
  return std::string(count == 1 ? "material " : "materials ") + names + ": roughness below " +
         threshold + " (--mirror-roughness) is rendered as a perfect mirror";
}

std::string World::followed_transmission_names() const {
  std::string names;
  size_t count = 0;
  for (const Material& m : scene_.materials) {
    const bool transmits = m.transmission > 0.0f || m.transmission_texture.present();
    const bool rough = !(m.roughness < mirror_roughness_) ||
                       m.metallic_roughness_texture.present() ||
                       m.specular_glossiness_texture.present();
    const bool dielectric = m.metallic < 1.0f || m.metallic_roughness_texture.present();
    if (!((transmits && rough) || m.diffuse_transmission > 0.0f) || !dielectric) continue;
    if (++count <= 4) names += std::string(names.empty() ? "" : ", ") + "'" + m.name + "'";
  }
  if (count == 0) return "";
  if (count > 4) names += " and " + std::to_string(count - 4) + " more";
  return std::string(count == 1 ? "material " : "materials ") + names;
}

}  // namespace pb
