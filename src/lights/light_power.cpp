// The power formulas of every kind of light (lights.h): what the photon tracer divides among
// its photons, the loader's range check and the sparse-photon bound all use these.
#include "lights/lights.h"
#include "scene/texture.h"

#include <algorithm>

namespace pb {

float emission_radius(const Bounds& b) {
  // The bounding sphere of the box, 0.1% larger: the disc then lies outside every surface.
  return std::max(0.5f * b.diagonal(), 1e-30f) * 1.001f;
}

// Power of a punctual light: integral of intensity times attenuation over the sphere.
// Spot: 2 pi I (integral over cos from cos_outer to 1 of the attenuation)
//     = 2 pi I ((cos_inner - cos_outer) / 3 + (1 - cos_inner)) for the squared linear ramp.
// Directional: irradiance E through the emission disc, pi r^2 E.
vec3 punctual_power(const PunctualLight& l, float radius) {
  if (l.kind == PunctualKind::Point) return 4.0f * kPi * l.intensity;
  if (l.kind == PunctualKind::Directional) return kPi * radius * radius * l.intensity;
  const float span = std::max(l.cos_inner - l.cos_outer, 0.0f);
  return 2.0f * kPi * l.intensity * (span / 3.0f + (1.0f - l.cos_inner));
}

vec3 environment_power(const EnvironmentLight& env, float radius) {
  return kPi * radius * radius * env.integral();
}

double total_emitted_power(const Scene& scene) {
  double power = 0.0;
  auto add = [&](const dvec3& p) { power += p.x + p.y + p.z; };
  const double r = emission_radius(scene.bounds);
  for (const PunctualLight& l : scene.lights) {
    // In double: r^2 E may overflow float, which is what the loader's range check looks for.
    if (l.kind == PunctualKind::Directional)
      add(kPiD * r * r * dvec3(l.intensity));
    else
      add(dvec3(punctual_power(l, 0.0f)));
  }
  for (const Mesh& m : scene.meshes) {
    const Material& mat = scene.materials[m.material];
    if (!mat.emits()) continue;
    // Textures scale the emission by at most 1: the factor bounds the power.
    const dvec3 le = dvec3(mat.emission) * (mat.double_sided ? 2.0 : 1.0);
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      const dvec3 p0(m.positions[m.indices[t]]);
      const double area = 0.5 * glm::length(glm::cross(dvec3(m.positions[m.indices[t + 1]]) - p0,
                                                       dvec3(m.positions[m.indices[t + 2]]) - p0));
      add(lambertian_emitter_power(area, le));
    }
  }
  if (scene.environment) add(kPiD * r * r * dvec3(EnvironmentLight(*scene.environment).integral()));
  return power;
}

namespace {

// A material emits somewhere: a positive factor, and, with an emissive texture, one texel whose
// channel under a positive factor channel is positive (an exporter writes emissiveFactor 1 over
// an all-black texture for "no emission": such a file has no light, and gets the default sky).
bool emits_anywhere(const Scene& scene, const Material& m) {
  if (!m.emits()) return false;
  const TextureRef& t = m.emissive_texture;
  if (!t.present() || t.image < 0 || size_t(t.image) >= scene.images.size()) return true;
  const Image& im = scene.images[size_t(t.image)];
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const glm::vec4 c = texel(im, x, y, true);
      for (int k = 0; k < 3; ++k)
        if (c[k] * m.emission[k] > 0.0f) return true;
    }
  return false;
}

}  // namespace

bool has_light(const Scene& scene) {
  for (const PunctualLight& l : scene.lights)
    if (max_component(l.intensity) > 0.0f) return true;
  std::vector<char> checked(scene.materials.size(), 0);
  for (const Mesh& m : scene.meshes) {
    if (checked[m.material]) continue;
    checked[m.material] = 1;
    if (emits_anywhere(scene, scene.materials[m.material])) return true;
  }
  return scene.environment && max_component(EnvironmentLight(*scene.environment).integral()) > 0.0f;
}

}  // namespace pb
