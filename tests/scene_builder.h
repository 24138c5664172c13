// Scenes built in memory as plain pb::Scene data (no glTF file): quads, boxes, flat-shaded
// spheres, lights and look-at cameras, for tests whose scenes are parametrised (ground sizes,
// light directions) or need an exact answer.
#pragma once

#include "scene/scene.h"

#include <cmath>
#include <string>

namespace pb::test {

struct SceneBuilder {
  Scene scene;

  SceneBuilder() { scene.source = "built.gltf"; }

  // A Lambertian of reflectance rho (glTF's metallic 0, specularFactor 0), emitting `emission`.
  uint32_t material(const vec3& rho, const vec3& emission = vec3(0.0f)) {
    Material m = Material::lambertian(rho);
    m.name = "material " + std::to_string(scene.materials.size());
    m.emission = emission;
    scene.materials.push_back(m);
    return uint32_t(scene.materials.size() - 1);
  }

  // Parallelogram c +- u +- v, front side u x v, flat (no shading normals).
  void quad(const vec3& c, const vec3& u, const vec3& v, uint32_t mat) {
    Mesh m;
    m.name = "quad";
    m.positions = {c - u - v, c + u - v, c + u + v, c - u + v};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = mat;
    add(std::move(m));
  }

  // Axis-aligned box [lo, hi], faces outward, flat.
  void box(const vec3& lo, const vec3& hi, uint32_t mat) {
    const vec3 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
    const vec3 x(h.x, 0, 0), y(0, h.y, 0), z(0, 0, h.z);
    quad(c + x, y, z, mat);
    quad(c - x, z, y, mat);
    quad(c + y, z, x, mat);
    quad(c - y, x, z, mat);
    quad(c + z, x, y, mat);
    quad(c - z, y, x, mat);
  }

  // UV sphere of `slices` x `stacks` with single pole vertices, outward winding, flat shaded
  // (no NORMAL): a convex polyhedron, so every facet sees its whole outer half-space.
  void sphere(const vec3& c, float r, int slices, int stacks, uint32_t mat) {
    Mesh m;
    m.name = "sphere";
    m.positions.push_back(c + vec3(0, r, 0));
    for (int i = 1; i < stacks; ++i) {
      const float th = kPi * float(i) / float(stacks);
      for (int j = 0; j < slices; ++j) {
        const float ph = 2.0f * kPi * float(j) / float(slices);
        m.positions.push_back(
            c + r * vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
      }
    }
    m.positions.push_back(c - vec3(0, r, 0));
    const uint32_t south = uint32_t(m.positions.size() - 1);
    auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * slices + j % slices); };
    for (int j = 0; j < slices; ++j) {
      m.indices.insert(m.indices.end(), {0, ring(1, j + 1), ring(1, j)});
      for (int i = 1; i < stacks - 1; ++i) {
        const uint32_t a = ring(i, j), b = ring(i, j + 1), d = ring(i + 1, j),
                       e = ring(i + 1, j + 1);
        m.indices.insert(m.indices.end(), {a, b, d, b, e, d});
      }
      m.indices.insert(m.indices.end(), {ring(stacks - 1, j), ring(stacks - 1, j + 1), south});
    }
    m.material = mat;
    add(std::move(m));
  }

  // Closed cylinder along y (centre c, radius r, length 2 h) of `slices` flat sides and two
  // flat caps, outward winding, flat shaded: a convex polyhedron, like sphere().
  void tube(const vec3& c, float r, float h, int slices, uint32_t mat) {
    Mesh m;
    m.name = "tube";
    for (int j = 0; j < slices; ++j) {
      const float ph = 2.0f * kPi * float(j) / float(slices);
      const vec3 rim = c + r * vec3(std::cos(ph), 0, std::sin(ph));
      m.positions.push_back(rim + vec3(0, h, 0));
      m.positions.push_back(rim - vec3(0, h, 0));
    }
    const uint32_t top = uint32_t(m.positions.size()), bottom = top + 1;
    m.positions.push_back(c + vec3(0, h, 0));
    m.positions.push_back(c - vec3(0, h, 0));
    for (int j = 0; j < slices; ++j) {
      const uint32_t a = uint32_t(2 * j), b = a + 1, d = uint32_t(2 * ((j + 1) % slices)),
                     e = d + 1;
      m.indices.insert(m.indices.end(), {a, d, b, d, e, b, top, d, a, bottom, b, e});
    }
    m.material = mat;
    add(std::move(m));
  }

  void point_light(const vec3& position, const vec3& intensity) {
    PunctualLight l;
    l.name = "point";
    l.position = position;
    l.intensity = intensity;
    scene.lights.push_back(l);
  }

  // Light travelling along `direction` with irradiance `irradiance` on a surface facing it.
  void directional_light(const vec3& direction, const vec3& irradiance) {
    PunctualLight l;
    l.name = "sun";
    l.kind = PunctualKind::Directional;
    l.direction = glm::normalize(direction);
    l.intensity = irradiance;
    scene.lights.push_back(l);
  }

  void camera(const vec3& eye, const vec3& target, float yfov, const vec3& up = vec3(0, 1, 0)) {
    Camera c;
    c.name = "camera";
    c.position = eye;
    c.forward = glm::normalize(target - eye);
    c.right = glm::normalize(glm::cross(c.forward, up));
    c.up = glm::cross(c.right, c.forward);
    c.yfov = yfov;
    scene.cameras.push_back(c);
  }

  void add(Mesh m) {
    for (const vec3& p : m.positions) scene.bounds.extend(p);
    scene.meshes.push_back(std::move(m));
  }
};

}  // namespace pb::test
