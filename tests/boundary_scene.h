// A scene for the boundary index's tests (tests/world/): the given meshes, one material, a point
// light (World needs one; the moments ignore it), its bounds those of the meshes.
#pragma once

#include "scene/scene.h"

#include <utility>
#include <vector>

namespace pb::test {

inline Scene boundary_scene(const char* source, std::vector<Mesh> meshes) {
  Scene s;
  s.source = source;
  s.materials.emplace_back();
  s.meshes = std::move(meshes);
  PunctualLight light;
  light.position = vec3(0, 0, 1);
  light.intensity = vec3(1);
  s.lights.push_back(light);
  for (const Mesh& m : s.meshes)
    for (const vec3& p : m.positions) s.bounds.extend(p);
  return s;
}

}  // namespace pb::test
