// Tangent frames for normal textures when a glTF file has no TANGENT attribute (glTF 2.0
// "Meshes": clients compute them). Per vertex, from the triangles around it: the direction of
// increasing s (dP/ds) made orthogonal to the normal, and as w the sign that makes
// cross(normal, tangent) w point toward decreasing t (up the image: glTF normal textures are
// +Y up, and t runs down the image). Triangles are weighted by their area; mirrored texture
// layouts get w = -1. Close to MikkTSpace wherever the layout is smooth across vertices.
#pragma once

#include "scene/scene.h"

#include <vector>

namespace pb {

// One per position of `mesh`: the texture coordinates are st (one per position, already
// through the normal texture's transform), the normal the mesh's (or, without normals, the
// area-weighted face normals). Vertices no usable triangle touches get any unit tangent
// orthogonal to their normal, w = 1.
std::vector<glm::vec4> compute_tangents(const Mesh& mesh, const std::vector<vec2>& st);

}  // namespace pb
