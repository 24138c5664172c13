// Which glTF extensions the loader reads, which it leaves out without a word (they change
// nothing drawn), and which it warns about (docs/gltf.md "Compression, instancing, deformation and
// extensions").
#include "gltf/gltf_loader_impl.h"

namespace pb::gltf {

void Loader::check_extensions() {
  // What photonbound reads (basisu: its fallback image, or a warning).
  static const std::set<std::string> known = {
      "KHR_lights_punctual",        "KHR_materials_transmission",
      "KHR_materials_ior",          "KHR_materials_emissive_strength",
      "KHR_materials_specular",     "KHR_materials_volume",
      "KHR_materials_clearcoat",    "KHR_materials_sheen",
      "KHR_materials_anisotropy",   "KHR_materials_iridescence",
      "KHR_materials_dispersion",   "KHR_materials_pbrSpecularGlossiness",
      "KHR_draco_mesh_compression", "EXT_meshopt_compression",
      "KHR_mesh_quantization",      "KHR_texture_transform",
      "KHR_texture_basisu",         "EXT_texture_webp",
      "EXT_mesh_gpu_instancing",    "KHR_materials_diffuse_transmission",
      "KHR_materials_unlit"};
  // What changes nothing photonbound draws, so that leaving it out is exact: metadata, the
  // material variants' default (what a viewer shows first), and MSFT_lod's base node (the
  // finest level of detail).
  static const std::set<std::string> exact_without = {"KHR_xmp", "KHR_xmp_json_ld",
                                                      "KHR_materials_variants", "MSFT_lod"};
  // Unknown extensions, even required ones, are rendered without (docs/gltf.md "Compression,
  // instancing, deformation and extensions"): a material extension then falls back to the core
  // factors; data an unknown extension holds is missing, and the accessors that lack it are refused
  // with their own message. What rendering without it means, where that is not only a material
  // falling back to its core factors (none today):
  auto without = [](const std::string&) -> std::string { return ""; };
  for (const std::string& e : m_.extensionsRequired)
    if (!known.count(e) && !exact_without.count(e))
      warn("extension '" + e + "' is required but not implemented; rendered without it" +
           without(e));
  for (const std::string& e : m_.extensionsUsed)
    if (!known.count(e) && !exact_without.count(e) &&
        !std::count(m_.extensionsRequired.begin(), m_.extensionsRequired.end(), e))
      warn("extension '" + e + "' is ignored" + without(e));
  if (!m_.animations.empty())
    warn(std::to_string(m_.animations.size()) +
         (m_.animations.size() == 1 ? " animation is" : " animations are") +
         " ignored; the scene is drawn as the nodes place it");
}

}  // namespace pb::gltf
