// The glTF loader's textures (see gltf_loader_impl.h): textureInfo objects with
// KHR_texture_transform, their textures and samplers, images decoded on first use
// (image_io.h), and the tangent frames normal textures need.
#include "gltf/gltf_loader_impl.h"

#include "io/image_io.h"
#include "scene/tangents.h"
#include "scene/texture.h"
#include "util/file_io.h"
#include "util/memory.h"

#include <cmath>
#include <cstring>

namespace pb::gltf {

namespace {

// glTF sampler wrap codes.
Wrap wrap_mode(int code) {
  return code == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? Wrap::ClampToEdge
         : code == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? Wrap::MirroredRepeat
                                                         : Wrap::Repeat;
}

// A number member of a JSON object, or `fallback`; false when present but not a finite number.
bool number_of(const tinygltf::Value& obj, const char* key, double& out) {
  if (!obj.IsObject() || !obj.Has(key)) return true;
  const tinygltf::Value& v = obj.Get(key);
  if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble())) return false;
  out = v.GetNumberAsDouble();
  return true;
}

// A pair of numbers, e.g. KHR_texture_transform's offset and scale.
bool pair_of(const tinygltf::Value& obj, const char* key, vec2& out) {
  if (!obj.IsObject() || !obj.Has(key)) return true;
  const tinygltf::Value& v = obj.Get(key);
  if (!v.IsArray() || v.ArrayLen() != 2) return false;
  for (int c = 0; c < 2; ++c) {
    const tinygltf::Value& x = v.Get(c);
    if (!x.IsNumber() || !fits_float(x.GetNumberAsDouble())) return false;
    out[c] = float(x.GetNumberAsDouble());
  }
  return true;
}

}  // namespace

int32_t Loader::image(int index, const std::string& where) {
  if (index < 0 || size_t(index) >= m_.images.size())
    fail(where + " refers to " + absent("image", index, m_.images.size()));
  int64_t& slot = image_slot_[size_t(index)];
  if (slot >= 0) return int32_t(slot);
  if (slot == kUndecodable) return -1;  // warned once
  const tinygltf::Image& gi = m_.images[size_t(index)];
  const std::string il = gi.uri.empty() || gi.uri.rfind("data:", 0) == 0
                             ? label("image", gi.name, size_t(index))
                             : "image '" + one_line(gi.uri) + "'";
  Bytes bytes{gi.image.data(), gi.image.size()};
  if (gi.bufferView >= 0) bytes = view_bytes(gi.bufferView, il);  // validated range
  if (bytes.size == 0) fail(il + " has no data (a missing file, or an empty bufferView)");
  // KTX2 (Basis Universal) has no decoder here. A file may point texture.source at one without
  // requiring KHR_texture_basisu (glTF-Sample-Assets' KTX2 variants do): the textures using it
  // fall back to their factors, as for a basisu-only texture, with one warning per image.
  if (is_ktx2(bytes.data, bytes.size)) {
    warn(il +
         " is KTX2 (Basis Universal), which photonbound does not read; the textures using "
         "it take their factors");
    slot = kUndecodable;
    return -1;
  }
  // The same bytes under another image index (four images naming one file) are decoded once.
  Checksum sum(bytes.size);
  sum.add(bytes.data, bytes.size);
  const uint64_t key = sum.finish();
  for (auto [at, end] = image_by_bytes_.equal_range(key); at != end; ++at) {
    const Bytes& seen = image_source_[size_t(at->second)];
    if (seen.size == bytes.size && std::memcmp(seen.data, bytes.data, bytes.size) == 0)
      return int32_t(slot = at->second);
  }
  // The uri's extension tells OpenImageIO the format where the signature does not.
  const std::string name = gi.uri.empty() ? il : one_line(gi.uri);
  try {
    const uint64_t left = max_memory_ - std::min(held_bytes_, max_memory_);
    Image decoded = decode_image(bytes.data, bytes.size, name, left,
                                 any_texture_format_ ? ImageFormats::Any : ImageFormats::Gltf);
    held_bytes_ += image_bytes(decoded);
    decoded.name = il;
    slot = int64_t(scene_.images.size());
    scene_.images.push_back(std::move(decoded));
    image_by_bytes_.emplace(key, slot);
    image_source_.push_back(bytes);
  } catch (const ImageError& e) {
    // An image in a format photonbound recognises but does not decode by default renders as
    // its factors, like KTX2 (approximate: a warning, not a refusal); bytes in no recognised
    // format are a corrupt image, refused below.
    if (const auto* other = dynamic_cast<const ImageFormatRefused*>(&e);
        other && !other->format.empty()) {
      warn(il + " is " + other->format +
           ", not one of glTF's image formats (PNG, JPEG, WebP); the textures using it take "
           "their factors (--texture-formats any decodes it, for files you trust)");
      slot = kUndecodable;
      return -1;
    }
    // decode_image names the image itself; il is said once.
    std::string what = e.what();
    if (what.rfind(name + ": ", 0) == 0) what.erase(0, name.size() + 2);
    if (const auto* big = dynamic_cast<const ImageTooLarge*>(&e))
      what += ": the scene's files and textures would take " +
              bytes_text(saturating_add(held_bytes_, big->bytes)) + ", over the " +
              bytes_text(max_memory_) + " of --max-memory";
    fail(il + ": " + what);
  }
  return int32_t(slot);
}

TextureRef Loader::texture(int index, int tex_coord, const tinygltf::ExtensionMap& info_ext,
                           const std::string& where) {
  TextureRef ref;
  if (index < 0) return ref;
  if (size_t(index) >= m_.textures.size())
    fail(where + " refers to " + absent("texture", index, m_.textures.size()));
  const tinygltf::Texture& gt = m_.textures[size_t(index)];
  const std::string tl = where + " (" + label("texture", gt.name, size_t(index)) + ")";
  int source = gt.source;
  if (source < 0) {  // no PNG/JPEG fallback: a WebP source is decoded, KTX2 (basisu) is not
    const auto webp = gt.extensions.find("EXT_texture_webp");
    double s = -1.0;
    if (webp != gt.extensions.end() && !number_of(webp->second, "source", s))
      fail(tl + ": EXT_texture_webp.source is not a number");
    if (s < 0.0) {
      warn(tl + " has no image photonbound can decode (KHR_texture_basisu?); its factor is used");
      return ref;
    }
    source = int(std::min(s, 1e9));
  }
  ref.image = image(source, tl);
  if (ref.image < 0) return TextureRef{};  // undecodable (KTX2): the factor alone
  if (gt.sampler >= 0) {
    if (size_t(gt.sampler) >= m_.samplers.size())
      fail(tl + " refers to " + absent("sampler", gt.sampler, m_.samplers.size()));
    const tinygltf::Sampler& s = m_.samplers[size_t(gt.sampler)];
    ref.wrap_s = wrap_mode(s.wrapS);
    ref.wrap_t = wrap_mode(s.wrapT);
    ref.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
  }
  int set = tex_coord;
  const auto xf = info_ext.find("KHR_texture_transform");
  if (xf != info_ext.end()) {
    vec2 offset(0.0f), scale(1.0f);
    double rotation = 0.0, coord = double(set);
    if (!pair_of(xf->second, "offset", offset) || !pair_of(xf->second, "scale", scale) ||
        !number_of(xf->second, "rotation", rotation) || !number_of(xf->second, "texCoord", coord))
      fail(tl + ": KHR_texture_transform has a malformed offset, rotation, scale or texCoord");
    set = coord >= 0.0 && coord <= 1e9 ? int(coord) : -1;
    set_texture_transform(ref, offset, float(rotation), scale);
  }
  if (set < 0 || set > 1) {
    warn(tl + " uses TEXCOORD_" + std::to_string(set) +
         "; only TEXCOORD_0 and _1 are read, so its factor is used");
    return TextureRef{};
  }
  ref.texcoord = uint8_t(set);
  return ref;
}

TextureRef Loader::ext_texture(const tinygltf::ExtensionMap& ext, const std::string& owner,
                               const char* name, const char* key) {
  const auto it = ext.find(name);
  if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key)) return TextureRef{};
  const tinygltf::Value& info = it->second.Get(key);
  const std::string where = owner + " " + name + "." + key;
  double index = -1.0, coord = 0.0;
  if (!info.IsObject() || !number_of(info, "index", index) || !number_of(info, "texCoord", coord) ||
      index < 0.0 || coord < 0.0)
    fail(where + " is not a textureInfo with an index");
  tinygltf::ExtensionMap info_ext;
  if (info.Has("extensions") && info.Get("extensions").IsObject()) {
    const tinygltf::Value& e = info.Get("extensions");
    for (const std::string& k : e.Keys()) info_ext[k] = e.Get(k);
  }
  return texture(int(std::min(index, 1e9)), int(std::min(coord, 1e9)), info_ext, where);
}

// The normal texture's tangent frames: the file's TANGENT (through the node's linear part, w
// flipped with a mirroring transform, whose bitangent cross(n, t) flips), or made from the
// texture coordinates of the normal texture after its transform (tangents.h).
void Loader::add_tangents(Mesh& out, const tinygltf::Primitive& prim, const DracoPrimitive* dp,
                          const Placement& place, const std::vector<dvec3>& offsets,
                          const std::string& where) {
  const Material& mat = scene_.materials[out.material];
  // One tangent space for both normal textures (KHR_materials_clearcoat asks them to share it)
  // and the anisotropy direction (KHR_materials_anisotropy: TANGENT, or made as for the normal
  // texture; without one, from the anisotropy texture's coordinates or TEXCOORD_0).
  TextureRef normal =
      mat.normal_texture.present() ? mat.normal_texture : mat.clearcoat_normal_texture;
  const bool aniso = mat.anisotropy > 0.0f;
  if (!normal.present() && aniso) {
    normal = mat.anisotropy_texture.present() ? mat.anisotropy_texture : TextureRef{};
    if (!normal.present()) normal.image = 0;  // only its coordinate set and transform are read
  }
  if (!normal.present()) return;
  if (const std::optional<View> tan = attribute(prim, dp, "TANGENT", where)) {
    if (tan->count != out.positions.size())
      fail(where + " has " + std::to_string(tan->count) + " tangents for " +
           std::to_string(out.positions.size()) + " positions");
    out.tangents.resize(tan->count);
    const float sign = place.flip ? -1.0f : 1.0f;
    for (size_t i = 0; i < tan->count; ++i) {
      const dvec3 t =
          place.direction(i, offsets.empty() ? tan->vec3(i) : tan->vec3(i) + offsets[i]);
      const double len = glm::length(t), w = tan->scalar(i, 3);
      if (!(len > 0.0) || !std::isfinite(len) || !std::isfinite(w)) {
        warn(where + ": zero or non-finite tangents; tangents are computed instead");
        out.tangents.clear();
        break;
      }
      out.tangents[i] = glm::vec4(vec3(t / len), (w < 0.0 ? -1.0f : 1.0f) * sign);
    }
    if (!out.tangents.empty()) return;
  }
  const std::vector<vec2>& uv = out.texcoords[normal.texcoord];
  if (uv.empty()) {  // no coordinates: the normal texture reads one texel (warned)
    if (aniso)
      warn(where +
           ": anisotropy without TANGENT or texture coordinates has no direction; "
           "rendered isotropic");
    return;
  }
  std::vector<vec2> st(uv.size());
  for (size_t i = 0; i < uv.size(); ++i) {
    const vec2 both[2] = {uv[i], uv[i]};
    st[i] = texture_coords(normal, both);
  }
  out.tangents = compute_tangents(out, st);
}

}  // namespace pb::gltf
