// glTF 2.0 -> pb::Scene. Only the loader's files (src/gltf_*.cpp through gltf_loader_impl.h)
// include tiny_gltf.h; the helpers that need no tinygltf types live in gltf_support.cpp.
//
// Phases: read the file (checking the GLB container), rewrite the JSON where tinygltf 2.7 would
// refuse valid glTF (gltf_prepass.h), let tinygltf parse it (images are kept encoded and decoded
// when a material uses them), walk the
// default scene's node tree composing transforms, and turn every
// node x primitive into a world-space Mesh, every KHR_lights_punctual light instance into a
// PunctualLight and every perspective camera into a Camera. Each accessor is validated before
// it is read; Draco and meshoptimizer data are decoded on first use (gltf_decode.h). Errors throw
// SceneError("<file>: <one line>"); a Scene is only returned whole.
//
// Material rules (docs/materials.md repeats them): glTF 2.0's metallic-roughness material with
// glTF's defaults (metallicFactor and roughnessFactor 1: a material without
// pbrMetallicRoughness is a rough metal), KHR_materials_ior, _specular, _transmission,
// _volume, _clearcoat, _sheen and _emissive_strength, textures (base colour,
// metallic-roughness, normal, emissive, transmission, specular, specular colour, the clear
// coat's three, the sheen's two) with
// KHR_texture_transform, alphaMode
// MASK cut-outs, BLEND coverage and doubleSided emitters. Factors must be in their documented
// ranges (a reflectance above 1 creates energy) or the file is rejected; what is rendered
// approximately (rough transmission in PPM) is warned about. Primitives without a material share
// one Lambertian material named "default" with base_color 0.8 (one warning).
#include "gltf/gltf_loader_impl.h"

#include "gltf/gltf_files.h"
#include "lights/lights.h"
#include "util/file_io.h"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cstring>
#include <filesystem>

namespace pb {
namespace gltf {

namespace {

// Keeps an image's encoded bytes for the loader, which decodes the images materials use
// (gltf_texture.cpp). An image in a bufferView is read from the buffer there, where its range is
// checked; tinygltf does not check it before this call.
bool keep_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
  return true;
}

// tinygltf 2.7 parses "inverseBindMatrices" as required (glTF makes it optional: identity
// matrices) but still reads the skin; this is the one error line it then reports.
bool spurious(const std::string& line) {
  return line == "'inverseBindMatrices' property is missing in Skin.";
}

// GLB by its magic, otherwise glTF JSON, rewritten first where tinygltf needs it
// (gltf_prepass.h). Every error tinygltf reports is fatal, even when it returns true (2.7 drops
// e.g. a baseColorFactor of the wrong length with only a message), but the spurious ones.
tinygltf::Model parse(const std::string& path, const std::vector<unsigned char>& bytes,
                      std::vector<std::string>& warnings, Prepass& pre, AssetFiles& files) {
  // By the magic bytes, whatever the name: a .glb saved as .gltf is still binary. A name ending
  // in .glb (any case: BOX.GLB) without the magic is a broken GLB, and check_glb says so.
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const bool glb =
      (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) || ext == ".glb";
  uint32_t size = glb ? check_glb(path, bytes) : uint32_t(bytes.size());
  std::optional<std::vector<unsigned char>> aligned;
  if (glb && (aligned = align_glb(bytes, size))) size = uint32_t(aligned->size());
  const std::vector<unsigned char>& in = aligned ? *aligned : bytes;
  const unsigned char* data = in.data();
  std::string json;
  std::vector<unsigned char> rewritten_glb;
  const std::string_view text =
      glb ? glb_json(in) : std::string_view(reinterpret_cast<const char*>(data), size);
  // Before any recursive parser (nlohmann's, in the prepass and in tinygltf) sees the text.
  if (const std::string problem = json_problem(text); !problem.empty())
    throw SceneError(path + ": " + one_line(problem));
  if (prepass(text, glb, pre, json)) {
    if (glb) {
      rewritten_glb = replace_glb_json(in, size, json);
      data = rewritten_glb.data();
      size = uint32_t(rewritten_glb.size());
    } else {
      data = reinterpret_cast<const unsigned char*>(json.data());
      size = uint32_t(json.size());
    }
  }
  tinygltf::TinyGLTF reader;
  reader.SetImageLoader(&keep_image, nullptr);
  reader.SetFsCallbacks(tinygltf::FsCallbacks{&fs_exists, &fs_expand, &fs_read, &fs_write, &files});
  const std::string& dir = files.base();
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    ok = glb ? reader.LoadBinaryFromMemory(&model, &err, &warn, data, size, dir)
             : reader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(data),
                                          size, dir);
  } catch (const std::exception& e) {
    err = e.what();
    ok = false;
  }
  // A refused file is the error, whatever tinygltf made of it (for an image only a warning).
  if (const auto& refused = files.refusal())
    throw SceneError(path + ": " + uri_owner(text, refused->first) + " " + refused->second);
  std::vector<std::string> errors = nonempty_lines(err);
  const std::vector<std::string> notes = nonempty_lines(warn);
  const std::vector<std::string> all_errors = errors;
  errors.erase(std::remove_if(errors.begin(), errors.end(), spurious), errors.end());
  if (!ok || !errors.empty()) {
    // A failure whose only words were a spurious line still says them, not "unknown error".
    std::string first = !errors.empty()       ? errors[0]
                        : !all_errors.empty() ? all_errors[0]
                        : !notes.empty()      ? notes[0]
                                              : "tinygltf could not read it and gave no reason";
    if (first.size() > 160) first = first.substr(0, 160) + "...";  // it may quote a data URI
    // tinygltf's words for a buffer file that is not there ("File not found : NAME"): the file
    // is not malformed, it is incomplete.
    const std::string missing = "File not found : ";
    if (first.rfind(missing, 0) == 0)
      throw SceneError(path + ": the buffer file '" + first.substr(missing.size()) +
                       "' it refers to cannot be opened (it is missing or unreadable)");
    throw SceneError(path + ": malformed glTF: " + first);
  }
  for (const std::string& l : notes) warnings.push_back("glTF: " + l);
  return model;
}

}  // namespace

// The default scene (or scene 0, or every node that is nobody's child when there are none).
Scene Loader::run(const std::vector<std::string>& parse_warnings) {
  for (const std::string& w : parse_warnings) warn(w);
  check_extensions();
  visited_.assign(m_.nodes.size(), 0);
  material_slot_.assign(m_.materials.size(), -1);
  image_slot_.assign(m_.images.size(), -1);
  const int s = m_.defaultScene;
  if (s != -1 && (s < 0 || size_t(s) >= m_.scenes.size()))
    fail("\"scene\" refers to " + absent("scene", s, m_.scenes.size()));
  auto traverse = [&] {
    visited_.assign(m_.nodes.size(), 0);
    if (!m_.scenes.empty()) {
      const size_t si = s >= 0 ? size_t(s) : 0;
      for (int r : m_.scenes[si].nodes) walk(r, label("scene", m_.scenes[si].name, si));
    } else {
      std::vector<char> child(m_.nodes.size(), 0);
      for (const tinygltf::Node& n : m_.nodes)
        for (int c : n.children)
          if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = 1;
      for (size_t i = 0; i < child.size(); ++i)
        if (!child[i]) walk(int(i), "the file");
    }
  };
  // Twice: the accessors' bounds first, to choose the origin the positions are stored about,
  // then the scene itself (the hierarchy's errors come from the first walk, unchanged).
  measuring_ = true;
  traverse();
  measuring_ = false;
  choose_origin();
  traverse();
  finish();
  return std::move(scene_);
}

dmat4 Loader::local_matrix(const tinygltf::Node& n, const std::string& nl) const {
  auto check = [&](const std::vector<double>& v, size_t want, const char* what) {
    if (!v.empty() && v.size() != want)
      fail(nl + " has a " + what + " of " + std::to_string(v.size()) + " numbers; expected " +
           std::to_string(want));
  };
  check(n.matrix, 16, "matrix");
  check(n.translation, 3, "translation");
  check(n.rotation, 4, "rotation");
  check(n.scale, 3, "scale");
  dmat4 m(1.0);
  if (!n.matrix.empty()) {  // column-major
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[size_t(c * 4 + r)];
    // glTF 2.0 "Transformations": a matrix must be decomposable to TRS, so its last row is
    // (0, 0, 0, 1). Any other is projective: no triangle stays a triangle, and reading it as
    // affine would move every vertex without a word.
    if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
      fail(nl + " has a matrix whose last row is (" + num(m[0][3]) + ", " + num(m[1][3]) + ", " +
           num(m[2][3]) + ", " + num(m[3][3]) +
           "), not (0, 0, 0, 1): glTF node matrices are affine (translation, rotation, scale)");
    return m;
  }
  if (!n.translation.empty())
    m[3] = glm::dvec4(n.translation[0], n.translation[1], n.translation[2], 1.0);
  dmat3 r(1.0);
  if (!n.rotation.empty() && !rotation_matrix(n.rotation, r))
    fail(nl + " has a zero or non-finite rotation quaternion");
  for (int c = 0; c < 3; ++c) m[c] = glm::dvec4(r[c] * (n.scale.empty() ? 1.0 : n.scale[c]), 0.0);
  return m;  // T * R * S
}

// Depth-first, parents before children, with an explicit stack (no recursion depth limit
// but kMaxDepth). Each node may be reached once: that rejects cycles and shared children.
void Loader::walk(int root, const std::string& root_from) {
  struct Pending {
    int index;
    int depth;
    dmat4 parent;
    std::string from;
  };
  std::vector<Pending> stack{{root, 0, dmat4(1.0), root_from}};
  while (!stack.empty()) {
    const Pending item = std::move(stack.back());
    stack.pop_back();
    if (item.index < 0 || size_t(item.index) >= m_.nodes.size())
      fail(item.from + " refers to " + absent("node", item.index, m_.nodes.size()));
    const tinygltf::Node& n = m_.nodes[size_t(item.index)];
    const std::string nl = label("node", n.name, size_t(item.index));
    if (item.depth > kMaxDepth)
      fail("the node hierarchy is deeper than " + std::to_string(kMaxDepth) + " levels");
    if (visited_[size_t(item.index)])
      fail(nl + " is reached twice: the node hierarchy has a cycle or a shared child");
    visited_[size_t(item.index)] = 1;
    const Xform xf(item.parent * local_matrix(n, nl));
    if (!xf.finite()) fail(nl + " has a non-finite transform");
    if (!n.matrix.empty() && sheared(dmat3(local_matrix(n, nl))))
      warn(nl +
           "'s matrix shears (its columns are not orthogonal), which glTF does not allow (a "
           "node's matrix is a translation, rotation and scale); it is rendered as the "
           "affine transform it is");
    visit(n, nl, xf);
    for (auto c = n.children.rbegin(); c != n.children.rend(); ++c)
      stack.push_back({*c, item.depth + 1, xf.m, nl});
  }
}

// The world box of the node's mesh from its POSITION accessors' min and max (glTF requires
// them; a primitive without them, or of a kind the loader skips, is left out).
void Loader::measure(const tinygltf::Node& n, const std::string& nl, const Xform& xf) {
  if (n.mesh < 0 || size_t(n.mesh) >= m_.meshes.size()) return;
  const std::vector<dmat4> copies = instances(n, nl);
  if (copies.empty()) return measure_mesh(n, xf);
  for (const dmat4& c : copies) measure_mesh(n, Xform(xf.m * c));
}

void Loader::measure_mesh(const tinygltf::Node& n, const Xform& xf) {
  for (const tinygltf::Primitive& p : m_.meshes[size_t(n.mesh)].primitives) {
    const auto it = p.attributes.find("POSITION");
    if (it == p.attributes.end() || it->second < 0 || size_t(it->second) >= m_.accessors.size())
      continue;
    const tinygltf::Accessor& a = m_.accessors[size_t(it->second)];
    if (a.minValues.size() != 3 || a.maxValues.size() != 3) continue;
    for (int k = 0; k < 8; ++k) {
      const dvec3 corner(k & 1 ? a.maxValues[0] : a.minValues[0],
                         k & 2 ? a.maxValues[1] : a.minValues[1],
                         k & 4 ? a.maxValues[2] : a.minValues[2]);
      const dvec3 w = xf.point(corner);
      if (!is_finite(vec3(w))) continue;
      measured_lo_ = glm::min(measured_lo_, w);
      measured_hi_ = glm::max(measured_hi_, w);
    }
  }
}

// Positions are stored in float: at a distance c from the origin its step is c 2^-24 to
// c 2^-23, so a model of size D far from the origin (geo-referenced tiles sit at 4e6 m) loses its
// shape (a 10 m house at 6e6 m: 169 of its triangles degenerate, 21 in the file). Past c > 64 D
// (a step above 4e-6 D) the model is centred in double first; near the origin nothing moves, so
// ordinary files keep their bits. Quantised POSITION (KHR_mesh_quantization) has min / max in
// its stored units, so the box can be off by the dequantisation scale: that only moves the
// threshold, as centring any model is exact up to float rounding of its centred positions.
void Loader::choose_origin() {
  if (!(measured_lo_.x <= measured_hi_.x)) return;
  const dvec3 centre = 0.5 * (measured_lo_ + measured_hi_);
  const double size = glm::length(measured_hi_ - measured_lo_);
  const double far = std::max({std::abs(centre.x), std::abs(centre.y), std::abs(centre.z)});
  if (far > kRecentreRatio * std::max(size, 1e-30) && far <= kMaxCoordinate) scene_.origin = centre;
}

// A node's own content: mesh instances, camera, light.
void Loader::visit(const tinygltf::Node& n, const std::string& nl, const Xform& xf) {
  if (measuring_) return measure(n, nl, xf);
  if (n.mesh != -1) {
    if (n.mesh < 0 || size_t(n.mesh) >= m_.meshes.size())
      fail(nl + " refers to " + absent("mesh", n.mesh, m_.meshes.size()));
    const tinygltf::Mesh& mesh = m_.meshes[size_t(n.mesh)];
    if (n.skin != -1 && (n.skin < 0 || size_t(n.skin) >= m_.skins.size()))
      fail(nl + " refers to " + absent("skin", n.skin, m_.skins.size()));
    // A skinned mesh is placed by its joints alone ("Skins": the node's own transform is
    // ignored), so only an unskinned node's transform must be invertible.
    if (n.skin == -1 && xf.singular())
      fail(nl + " has a singular transform (determinant " + num(xf.det) + "); cannot place " +
           label("mesh", mesh.name, size_t(n.mesh)));
    Instance inst;
    inst.xf = &xf;
    inst.weights = n.weights.empty() ? &mesh.weights : &n.weights;
    inst.skin = n.skin;
    inst.label = nl;
    const std::vector<dmat4> copies = instances(n, nl);
    if (copies.empty())
      for (size_t p = 0; p < mesh.primitives.size(); ++p) add_primitive(size_t(n.mesh), p, inst);
    for (size_t k = 0; k < copies.size(); ++k) {  // EXT_mesh_gpu_instancing: node x instance
      const Xform each(xf.m * copies[k]);
      if (!each.finite() || each.singular())
        fail(nl + " EXT_mesh_gpu_instancing instance " + std::to_string(k) +
             " has a non-finite or singular transform");
      inst.xf = &each;
      for (size_t p = 0; p < mesh.primitives.size(); ++p) add_primitive(size_t(n.mesh), p, inst);
    }
  }
  if (n.camera != -1) add_camera(n.camera, nl, xf);
  if (n.extensions.count("KHR_lights_punctual")) add_light(n, nl, xf);
}

void Loader::finish() {
  if (scene_.degenerate_triangles > 0)
    warn(std::to_string(scene_.degenerate_triangles) + " degenerate triangles skipped");
  // The nodes of the scene drew nothing: no mesh, or meshes of points, lines or degenerate
  // triangles alone (a primitives member that is not an array also leaves none).
  if (unbound_vertices_ > 0)
    warn(std::to_string(unbound_vertices_) + " skinned vertices have no joint weight (" +
         first_unbound_ + " the first): they follow their node's transform");
  if (draco_counts_differ_ > 0)
    warn(std::to_string(draco_counts_differ_) + " Draco-compressed accessor" +
         (draco_counts_differ_ == 1 ? "'s count differs" : "s' counts differ") +
         " from the decoded data (" + first_draco_count_ +
         "): the decoded data is used, as the faces index it");
  if (scene_.meshes.empty())
    fail(
        "no triangles to render: the scene's nodes reference no mesh with a non-degenerate "
        "triangle" +
        (skipped_points_lines_ > 0 ? " (" + std::to_string(skipped_points_lines_) + " primitive" +
                                         (skipped_points_lines_ == 1 ? " is" : "s are") +
                                         " points or lines, which have no area)"
                                   : std::string()));
  // No camera and no light are not errors: scene_defaults.h frames the bounds and lights the scene
  // with the default sky, as glTF viewers do.
  for (const Mesh& m : scene_.meshes)
    for (uint32_t i : m.indices) scene_.bounds.extend(m.positions[i]);
  // Photon flux is carried in float: the total emitted power must fit, or the light
  // distribution overflows later with no file to name.
  const double power = total_emitted_power(scene_);
  if (!(power <= double(std::numeric_limits<float>::max())))
    fail("the lights emit " + num(power) +
         " W in total, beyond the float range (3.4e+38) photon power is carried in");
  scene_.source = file_;
}

}  // namespace gltf

Scene load_gltf(const std::string& path, const LoadPolicy& policy) {
  Scene scene = load_gltf_bytes(path, gltf::read_file(path, policy.max_memory), policy);
  scene.files.insert(scene.files.begin(), path);
  return scene;
}

Scene load_gltf_bytes(const std::string& path, const std::vector<unsigned char>& bytes,
                      const LoadPolicy& policy) {
  std::vector<std::string> warnings;
  gltf::Prepass pre;
  gltf::AssetFiles files(path, policy.asset_dirs, policy.max_memory, bytes.size());
  const tinygltf::Model model = gltf::parse(path, bytes, warnings, pre, files);
  uint64_t total = bytes.size();
  for (const tinygltf::Buffer& b : model.buffers) total += b.data.size();
  for (const tinygltf::Image& im : model.images) total += im.image.size();
  // The decoded texels may take what the file and its buffers and images leave of the budget.
  Scene scene = gltf::Loader(path, model, pre, policy.max_memory, total, policy.any_texture_format)
                    .run(warnings);
  scene.files = files.read_paths();
  // External images are part of the identity too (embedded ones already are: their bytes are in
  // the file or a buffer).
  Checksum hash(total);
  hash.add(bytes.data(), bytes.size());
  for (const tinygltf::Buffer& b : model.buffers) hash.add(b.data.data(), b.data.size());
  for (const tinygltf::Image& im : model.images)
    if (!im.image.empty()) hash.add(im.image.data(), im.image.size());
  scene.content_hash = hash.finish();
  return scene;
}

}  // namespace pb
