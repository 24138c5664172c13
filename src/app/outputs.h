// The files a command writes, checked before any work (docs/usage.md "Outputs and refusals"):
// none may be an input or another output (compared by resolved path and by device and inode),
// none may be a directory, device, fifo or socket, their folders must exist and be writable;
// and a render holds a lock beside each output for as long as it runs.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace pb {

// A file a command names: an output by its flag ("-o", "--state", "--log"), an input by what
// it is ("the scene file", "the --reference image").
struct NamedFile {
  std::string role;
  std::string path;
};

// Throws UsageError (exit 2) when an output is the same file as an input or as an earlier
// output: "--state scene.gltf is the scene file: choose another path".
void check_distinct(const std::vector<NamedFile>& outputs, const std::vector<NamedFile>& inputs);

// Throws FileError (exit 1) when `output` names something that is not a regular file (it is
// never replaced), or its folder is missing or not writable.
void check_output_path(const NamedFile& output);

// An advisory lock (flock) on PATH.lock for each path, held while this object lives; the lock
// files are removed when it ends, and by a signal handler that exits at once
// (unlink_registered_files). Throws FileError "PATH: another photonbound render is writing it
// (pid N)" when another process holds one.
class OutputLock {
 public:
  explicit OutputLock(const std::vector<std::string>& paths);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  struct Held;

 private:
  std::vector<std::unique_ptr<Held>> held_;
};

// The lock file of an output path.
std::string lock_path(const std::string& output);

}  // namespace pb
