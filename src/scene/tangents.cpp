#include "scene/tangents.h"

#include <cmath>

namespace pb {

std::vector<glm::vec4> compute_tangents(const Mesh& mesh, const std::vector<vec2>& st) {
  const size_t n = mesh.positions.size();
  std::vector<dvec3> sum_t(n, dvec3(0.0)), sum_b(n, dvec3(0.0)), sum_n(n, dvec3(0.0));
  for (size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
    const uint32_t i[3] = {mesh.indices[k], mesh.indices[k + 1], mesh.indices[k + 2]};
    const dvec3 p0(mesh.positions[i[0]]);
    const dvec3 e1 = dvec3(mesh.positions[i[1]]) - p0, e2 = dvec3(mesh.positions[i[2]]) - p0;
    const glm::dvec2 d1 = glm::dvec2(st[i[1]]) - glm::dvec2(st[i[0]]);
    const glm::dvec2 d2 = glm::dvec2(st[i[2]]) - glm::dvec2(st[i[0]]);
    const dvec3 face = glm::cross(e1, e2);  // twice the area, along the normal
    const double area2 = glm::length(face);
    const double det = d1.x * d2.y - d2.x * d1.y;
    for (uint32_t v : i) sum_n[v] += face;
    if (!(std::fabs(det) > 1e-20) || !(area2 > 0.0)) continue;
    // e = dP/ds ds + dP/dt dt on both edges, solved for dP/ds and dP/dt (Lengyel 2001).
    const dvec3 dp_ds = (e1 * d2.y - e2 * d1.y) / det;
    const dvec3 dp_dt = (e2 * d1.x - e1 * d2.x) / det;
    const double ls = glm::length(dp_ds), lt = glm::length(dp_dt);
    if (!(ls > 0.0 && lt > 0.0 && std::isfinite(ls) && std::isfinite(lt))) continue;
    for (uint32_t v : i) {
      sum_t[v] += dp_ds * (area2 / ls);
      sum_b[v] += dp_dt * (area2 / lt);
    }
  }
  std::vector<glm::vec4> out(n);
  for (size_t v = 0; v < n; ++v) {
    dvec3 nrm = mesh.normals.empty() ? sum_n[v] : dvec3(mesh.normals[v]);
    const double nl = glm::length(nrm);
    nrm = nl > 0.0 ? nrm / nl : dvec3(0.0, 0.0, 1.0);
    dvec3 t = sum_t[v] - glm::dot(sum_t[v], nrm) * nrm;
    double tl = glm::length(t);
    if (!(tl > 1e-12 * (glm::length(sum_t[v]) + 1e-300))) {  // no usable triangle: any tangent
      t = std::fabs(nrm.x) < 0.9 ? glm::cross(nrm, dvec3(1, 0, 0))
                                 : glm::cross(nrm, dvec3(0, 1, 0));
      tl = glm::length(t);
    }
    t /= tl;
    // The bitangent cross(n, t) w points up the image, against dP/dt.
    const float w = glm::dot(glm::cross(nrm, t), -sum_b[v]) < 0.0 ? -1.0f : 1.0f;
    out[v] = glm::vec4(vec3(t), w);
  }
  return out;
}

}  // namespace pb
