// Which files a scene may read (docs/gltf.md "Which files a scene may read"): the buffers and
// images a glTF file names by URI are read through this, and only from inside the scene file's
// own folder or an --asset-dir folder. tinygltf-free; gltf_loader.cpp hands it to tinygltf as
// its file-system callbacks, so that tinygltf opens nothing itself.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pb::gltf {

class AssetFiles {
 public:
  // The scene file's folder and the --asset-dir folders, made canonical. Throws SceneError
  // "<dir>: --asset-dir ..." when one is not a folder.
  // The files read together may take at most `max_bytes` (--max-memory; the scene file's own
  // bytes, `scene_bytes`, count).
  AssetFiles(const std::string& scene_path, const std::vector<std::string>& asset_dirs,
             uint64_t max_bytes = UINT64_MAX, uint64_t scene_bytes = 0);

  // The scene's folder, absolute and canonical: the folder relative URIs resolve against.
  const std::string& base() const { return base_; }

  enum class Verdict { Readable, Missing, Refused };
  // `name` is a URI as decoded (relative to base(), or absolute). Readable: a regular file inside
  // an allowed folder. Missing: inside, but not there (the loader's "cannot be opened" message).
  // Refused: outside, not a regular file, or not a file name at all; refusal() says why, and
  // nothing was opened or examined outside the allowed folders.
  Verdict check(const std::string& name);
  // Reads a file check() found Readable (opened without following a last symlink, without
  // blocking, and checked again to be a regular file once open). False with `err` set when it
  // cannot; a file that stopped being a regular file, or one larger than what is left of
  // `max_bytes`, is refused.
  bool read(const std::string& name, std::vector<unsigned char>& out, std::string& err);

  // The files read so far, canonical, in reading order (the outputs may not be any of them).
  const std::vector<std::string>& read_paths() const { return read_; }

  // The first name refused and what is wrong with it ("is outside the scene's folder (allow its
  // folder with --asset-dir)").
  const std::optional<std::pair<std::string, std::string>>& refusal() const { return refusal_; }

 private:
  struct Resolved {
    Verdict verdict = Verdict::Refused;
    std::filesystem::path path;  // canonical, when inside
  };
  Resolved resolve(const std::string& name);
  void refuse(const std::string& name, const std::string& why);

  std::string base_;
  std::vector<std::filesystem::path> roots_;  // base_ first
  std::optional<std::pair<std::string, std::string>> refusal_;
  std::vector<std::string> read_;
  uint64_t max_bytes_, read_bytes_;
};

// Why read_regular_file failed: at open() or fstat(), a file that is not a regular one (`why`
// is then "is a named pipe, not a regular file" and the like), a read(), or a file over
// `max_size` (4 GiB unless less is asked).
struct ReadFailure {
  enum Stage { Open, NotRegular, Read, TooLarge } stage;
  std::string why;
};
// Reads the regular file at `path` whole: opened without blocking (a named pipe or a device is
// refused, never waited on) and, unless `follow_last_link`, without following a last symbolic
// link; its type checked on the open file. The scene file and every file it refers to are read
// by it.
std::optional<ReadFailure> read_regular_file(const std::filesystem::path& path,
                                             bool follow_last_link, std::vector<unsigned char>& out,
                                             uint64_t max_size = UINT32_MAX);

// A buffer or image URI as tinygltf 2.7 decodes it before it asks for the file: %XX decoded and,
// unlike RFC 3986, '+' read as a space.
std::string tinygltf_decoded(const std::string& uri);

// tinygltf's file-system callbacks over an AssetFiles (`user`): tinygltf asks whether
// `base/NAME` exists, then for its bytes; it would then try `./NAME` (the working directory),
// which is never there. Nothing is ever written.
bool fs_exists(const std::string& joined, void* user);
std::string fs_expand(const std::string& path, void* user);
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& joined,
             void* user);
bool fs_write(std::string* err, const std::string& path, const std::vector<unsigned char>& bytes,
              void* user);

}  // namespace pb::gltf
