// The glTF loader's deformations (see gltf_loader_impl.h): a primitive drawn as a glTF viewer
// draws it with no animation playing. Morph targets add their displacements at the weights the
// file gives (the node's "weights", else the mesh's; glTF 2.0 "Morph Targets"), and a skinned
// mesh is placed by its joints as the node hierarchy poses them, each vertex by the weighted sum
// of its joints' matrices, global transform x inverse bind matrix (glTF 2.0 "Skins": "only the
// joint transforms are applied to the skinned mesh; the transform of the skinned mesh node
// MUST be ignored"). And EXT_mesh_gpu_instancing's copies of a node's mesh.
#include "gltf/gltf_loader_impl.h"

#include <cmath>

namespace pb::gltf {

dvec3 Placement::normal(size_t i, const dvec3& n) const {
  if (skinned.empty()) return rigid_normal * n;
  // cofactor(A) = det(A) A^-T, so the cofactor matrix times sign(det) is the inverse transpose's
  // direction with no division (a singular blend gives 0, which the caller drops).
  const dmat3 a(skinned[i]);
  const dmat3 cof(glm::cross(a[1], a[2]), glm::cross(a[2], a[0]), glm::cross(a[0], a[1]));
  const double det = glm::dot(a[0], cof[0]);
  return (det > 0.0 ? 1.0 : det < 0.0 ? -1.0 : 0.0) * (cof * n);
}

std::vector<dvec3> Loader::morph_offsets(const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                                         const Instance& inst, const char* attribute, size_t count,
                                         const std::string& where) {
  std::vector<dvec3> out;
  if (prim.targets.empty() || !prim.attributes.count(attribute)) return out;
  const std::vector<double>& w = *inst.weights;
  if (w.size() != prim.targets.size())
    warn(where + ": " + std::to_string(prim.targets.size()) + " morph targets but " +
         std::to_string(w.size()) + " weights (" + inst.label +
         "); the targets without a weight are left out");
  for (size_t k = 0; k < prim.targets.size() && k < w.size(); ++k) {
    if (!std::isfinite(w[k])) fail(inst.label + " has a non-finite morph target weight");
    const auto it = prim.targets[k].find(attribute);
    if (w[k] == 0.0 || it == prim.targets[k].end()) continue;
    const std::string ctx = where + " morph target " + std::to_string(k) + " " + attribute;
    // Displacements are VEC3, TANGENT's too (it has no handedness to move).
    const View d = accessor(it->second, ctx,
                            {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                             TINYGLTF_COMPONENT_TYPE_SHORT},
                            TINYGLTF_TYPE_VEC3);
    if (d.count != count) {
      if (dp) {  // a Draco primitive's points are the decoder's, which its targets cannot index
        warn(where +
             ": morph targets of a Draco-compressed primitive whose point count differs "
             "from theirs are left out");
        return {};
      }
      fail(ctx + " has " + std::to_string(d.count) + " elements for " + std::to_string(count) +
           " vertices");
    }
    if (out.empty()) out.assign(count, dvec3(0.0));
    for (size_t i = 0; i < count; ++i) {
      const dvec3 v = d.vec3(i);
      if (!is_finite(vec3(v)))
        fail(ctx + " has a non-finite value (vertex " + std::to_string(i) + ")");
      out[i] += w[k] * v;
    }
  }
  return out;
}

const dmat4& Loader::node_world(int index, const std::string& from) {
  if (parent_.empty()) {  // once: every node's parent (walk() refuses a node with two)
    parent_.assign(m_.nodes.size(), -1);
    for (size_t i = 0; i < m_.nodes.size(); ++i)
      for (int c : m_.nodes[i].children)
        if (c >= 0 && size_t(c) < m_.nodes.size() && parent_[size_t(c)] < 0)
          parent_[size_t(c)] = int(i);
    node_world_.assign(m_.nodes.size(), dmat4(1.0));
    node_world_state_.assign(m_.nodes.size(), 0);
  }
  if (index < 0 || size_t(index) >= m_.nodes.size())
    fail(from + " refers to " + absent("node", index, m_.nodes.size()));
  // The chain up to a node already known (or a root), then down it.
  std::vector<int> chain;
  for (int k = index; k >= 0 && node_world_state_[size_t(k)] != 2; k = parent_[size_t(k)]) {
    if (node_world_state_[size_t(k)] == 1 || chain.size() > size_t(kMaxDepth))
      fail(from + ": the node hierarchy above " +
           label("node", m_.nodes[size_t(index)].name, size_t(index)) +
           " has a cycle or is deeper than " + std::to_string(kMaxDepth) + " levels");
    node_world_state_[size_t(k)] = 1;
    chain.push_back(k);
  }
  for (auto k = chain.rbegin(); k != chain.rend(); ++k) {
    const int parent = parent_[size_t(*k)];
    const tinygltf::Node& n = m_.nodes[size_t(*k)];
    node_world_[size_t(*k)] = (parent >= 0 ? node_world_[size_t(parent)] : dmat4(1.0)) *
                              local_matrix(n, label("node", n.name, size_t(*k)));
    node_world_state_[size_t(*k)] = 2;
  }
  return node_world_[size_t(index)];
}

Placement Loader::placement(const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                            const Instance& inst, size_t count, const std::string& where) {
  Placement place(*inst.xf);
  if (inst.skin < 0) return place;
  const tinygltf::Skin& skin = m_.skins[size_t(inst.skin)];
  const std::string sl = label("skin", skin.name, size_t(inst.skin));
  if (!prim.attributes.count("JOINTS_0") || !prim.attributes.count("WEIGHTS_0")) {
    warn(where + " has no JOINTS_0 and WEIGHTS_0 to bind it to " + sl +
         "; it is drawn by its node's transform");
    return place;
  }
  if (skin.joints.empty()) fail(sl + " has no joints");
  // Joint matrices: the joint's global transform x its inverse bind matrix (identity without
  // inverseBindMatrices), in double.
  std::vector<dmat4> joint(skin.joints.size());
  View ibm;
  if (skin.inverseBindMatrices >= 0) {
    ibm = accessor(skin.inverseBindMatrices, sl + " inverseBindMatrices",
                   {TINYGLTF_COMPONENT_TYPE_FLOAT}, TINYGLTF_TYPE_MAT4);
    if (ibm.count < skin.joints.size())
      fail(sl + " has " + std::to_string(ibm.count) + " inverse bind matrices for " +
           std::to_string(skin.joints.size()) + " joints");
  }
  for (size_t j = 0; j < skin.joints.size(); ++j) {
    dmat4 inverse_bind(1.0);
    if (ibm.base)
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) inverse_bind[c][r] = ibm.scalar(j, 4 * c + r);
    joint[j] = node_world(skin.joints[j], sl) * inverse_bind;
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(glm::dot(joint[j][c], joint[j][c])))
        fail(sl + ": joint " + std::to_string(j) + "'s matrix is not finite");
  }
  // Each vertex: sum_k w_k joint[j_k] over every JOINTS_n / WEIGHTS_n set, divided by the sum of
  // the weights (glTF asks it to be 1; exporters round, and three.js divides as well).
  place.skinned.assign(count, dmat4(0.0));
  std::vector<double> total(count, 0.0);
  for (int set = 0;; ++set) {
    const std::string jn = "JOINTS_" + std::to_string(set), wn = "WEIGHTS_" + std::to_string(set);
    if (!prim.attributes.count(jn) || !prim.attributes.count(wn)) break;
    const View js = *attribute(prim, dp, jn, where), ws = *attribute(prim, dp, wn, where);
    if (js.component != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        js.component != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)
      fail(where + " " + jn + " has componentType " + component_name(js.component) +
           "; expected UNSIGNED_BYTE or UNSIGNED_SHORT");
    if (js.count != count || ws.count != count)
      fail(where + " has " + std::to_string(js.count) + " " + jn + " and " +
           std::to_string(ws.count) + " " + wn + " values for " + std::to_string(count) +
           " positions");
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < 4; ++c) {
        const double w = ws.scalar(i, c);
        if (!(w >= 0.0 && w <= 1e30))
          fail(where + " " + wn + " vertex " + std::to_string(i) + " has weight " + num(w));
        if (w == 0.0) continue;  // an unused slot may name any joint
        const double j = js.scalar(i, c);
        if (!(j < double(skin.joints.size())))
          fail(where + " " + jn + " vertex " + std::to_string(i) + " names joint " + num(j) +
               " of " + sl + ", which has " + std::to_string(skin.joints.size()));
        place.skinned[i] += w * joint[size_t(j)];
        total[i] += w;
      }
  }
  size_t negative = 0;
  for (size_t i = 0; i < count; ++i) {
    if (total[i] > 0.0) {
      place.skinned[i] /= total[i];
    } else {
      if (unbound_vertices_++ == 0) first_unbound_ = where + " vertex " + std::to_string(i);
      place.skinned[i] = inst.xf->m;
    }
    negative += glm::determinant(dmat3(place.skinned[i])) < 0.0;
  }
  // The winding follows the determinant (glTF 2.0 "Meshes"); per vertex here, by majority.
  place.flip = 2 * negative > count;
  return place;
}

std::vector<dmat4> Loader::instances(const tinygltf::Node& n, const std::string& nl) {
  // EXT_mesh_gpu_instancing: the node's mesh is drawn once per instance, at node x T * R * S
  // from the TRANSLATION, ROTATION (a quaternion) and SCALE accessors (each optional, the same
  // count; float or, as KHR_mesh_quantization allows, normalised integers). Copied: the scene
  // holds plain triangles.
  const auto ext = n.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == n.extensions.end() || n.mesh < 0 || size_t(n.mesh) >= m_.meshes.size()) return {};
  const std::string el = nl + " EXT_mesh_gpu_instancing";
  const tinygltf::Value& e = ext->second;
  if (!e.IsObject() || !e.Has("attributes") || !e.Get("attributes").IsObject())
    fail(el + " has no attributes object");
  if (n.skin != -1) {
    warn(el +
         ": a skinned mesh is placed by its joints, so its instances would coincide; it is "
         "drawn once");
    return {};
  }
  const tinygltf::Value& attributes = e.Get("attributes");
  const char* names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  std::optional<View> views[3];
  size_t count = 0;
  for (int k = 0; k < 3; ++k) {
    if (!attributes.Has(names[k])) continue;
    const tinygltf::Value& v = attributes.Get(names[k]);
    if (!v.IsInt() && !v.IsNumber()) fail(el + " " + names[k] + " is not an accessor index");
    views[k] = accessor(v.GetNumberAsInt(), el + " " + names[k],
                        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                        k == 1 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3);
    if (count != 0 && views[k]->count != count)
      fail(el + " has " + std::to_string(views[k]->count) + " " + names[k] + " values and " +
           std::to_string(count) + " of another attribute");
    count = views[k]->count;
  }
  if (count == 0) {
    warn(el + " has no TRANSLATION, ROTATION or SCALE; the mesh is drawn once");
    return {};
  }
  // The copies' triangles, from the primitives' index (or vertex) counts, within the budget.
  uint64_t triangles = 0;
  for (const tinygltf::Primitive& p : m_.meshes[size_t(n.mesh)].primitives) {
    const int a = p.indices >= 0
                      ? p.indices
                      : (p.attributes.count("POSITION") ? p.attributes.at("POSITION") : -1);
    if (a >= 0 && size_t(a) < m_.accessors.size()) triangles += m_.accessors[size_t(a)].count / 3;
  }
  if (!measuring_) instanced_triangles_ += triangles * count;  // the second walk places them
  if (instanced_triangles_ > kMaxInstancedTriangles)
    fail(el + " asks for " + std::to_string(count) + " copies of " +
         label("mesh", m_.meshes[size_t(n.mesh)].name, size_t(n.mesh)) + " (" +
         std::to_string(triangles) + " triangles each): instancing would hold more than " +
         std::to_string(kMaxInstancedTriangles) + " triangles, which photonbound copies");
  std::vector<dmat4> out(count, dmat4(1.0));
  for (size_t i = 0; i < count; ++i) {
    dmat3 r(1.0);
    if (views[1]) {
      const std::vector<double> q = {views[1]->scalar(i, 0), views[1]->scalar(i, 1),
                                     views[1]->scalar(i, 2), views[1]->scalar(i, 3)};
      if (!rotation_matrix(q, r))
        fail(el + " ROTATION " + std::to_string(i) + " is a zero or non-finite quaternion");
    }
    const dvec3 s = views[2] ? views[2]->vec3(i) : dvec3(1.0);
    for (int c = 0; c < 3; ++c) out[i][c] = glm::dvec4(r[c] * s[c], 0.0);
    if (views[0]) out[i][3] = glm::dvec4(views[0]->vec3(i), 1.0);
  }
  return out;
}

}  // namespace pb::gltf
