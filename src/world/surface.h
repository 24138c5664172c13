// A point on a surface as the passes see it: made in one place, World::surface().
#pragma once

#include "bsdf/bsdf.h"
#include "scene/scene.h"

namespace pb {

struct Surface {
  vec3 position{0.0f};
  vec3 ng{0.0f};       // geometric normal from the winding (the front side), unit
  vec3 ns{0.0f};       // shading normal, unit, flipped if needed to lie on ng's side
  float error = 0.0f;  // how far position may lie off the surface along ng (ray_offset.h)
  vec2 uv[2] = {vec2(0.0f), vec2(0.0f)};  // TEXCOORD_0/1 (0 without them or without textures)
  const Material* material = nullptr;
  Bsdf bsdf;  // the material's scattering here (textures and normal texture applied)
  // KHR_materials_unlit: the radiance the camera sees here (base colour factor x texture x
  // COLOR_0), the Bsdf then black; 0 on other materials.
  vec3 painted{0.0f};
};

}  // namespace pb
