// The one options struct: filled by the command-line parser, validated once, passed explicitly
// and written into the EXR metadata. Every option's range and default is documented here and in
// README "Options".
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb {

// Bad command-line usage; main maps it to exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class DirectMode { NextEvent, Photons };
enum class ErrorMetric { Absolute, Relative };
enum class ProgressMode { Auto, Always, Never };

struct RenderOptions {
  std::string scene;   // glTF file
  std::string output;  // EXR file
  // Stop conditions: whichever comes first; at least one is required.
  std::optional<uint64_t> passes;      // --passes, 1 .. 1e12
  std::optional<double> time_seconds;  // --time, (0, 1e9] wall-clock seconds
  std::optional<double> target_error;  // --target-error, (0, inf): image mean of the bound
  uint64_t photons_per_pass = 100000;  // --photons-per-pass, 1 .. 1e9 (M_e)
  double alpha = 0.7;                  // --alpha, (0, 1]
  std::optional<double> radius;        // --radius, (0, inf) world units; default from footprint
  int max_depth = 8;                   // --max-depth, 0 .. 32 specular bounces of camera paths
  std::optional<int> width, height;    // --resolution WxH, 1 .. 16384 each
  std::string camera;                  // --camera NAME; empty = first perspective camera
  int threads = 0;                     // --threads, 0 (all) .. 1024
  uint64_t seed = 1;                   // --seed, 0 .. 2^64-1
  DirectMode direct = DirectMode::NextEvent;   // --direct nee|photons
  double confidence = 0.9;                     // --confidence, (0, 1): 1 - beta
  uint64_t min_passes = 16;                    // --min-passes, 2 .. 1e12
  ErrorMetric metric = ErrorMetric::Absolute;  // --error-metric absolute|relative
  ProgressMode progress = ProgressMode::Auto;  // --progress / --quiet
  std::string command_line;                    // as typed, for the metadata
  // Checkpoints (README "Checkpoints"): none of these changes the image.
  std::optional<double> checkpoint_every;  // --checkpoint-every, (0, 1e9] seconds
  std::string state_path;                  // --state FILE; default OUT with .pbstate
  std::string resume_from;                 // --resume STATE: continue that render
  // Per-pass log (README "Measuring the trade"): none of these changes the image.
  std::string log_path;        // --log FILE.jsonl
  std::string reference_path;  // --reference REF.exr: adds actual error and coverage to the log
};

// The state file a render writes: --state, or the output path with its extension replaced by
// ".pbstate".
std::string state_path_for(const RenderOptions& options);

// photonbound preview IN.exr -o OUT.png [--exposure STOPS]
struct PreviewOptions {
  std::string input, output;
  double exposure = 0.0;  // stops: radiance is scaled by 2^exposure before the sRGB curve
};

// photonbound compare RENDER.exr REFERENCE.exr [--json]
struct CompareOptions {
  std::string render, reference;
  bool json = false;
};

// photonbound resume STATE -o OUT.exr [--passes N] [--time S] [--target-error E]
//   [--checkpoint-every S] [--state FILE] [--threads T] [--progress | --quiet]
// Every other option comes from the state. New stop conditions replace the saved ones; without
// any, the saved ones apply (passes and target count the whole render, time this run).
struct ResumeOptions {
  std::string state;
  RenderOptions overrides;  // output, stop conditions, checkpoints, threads, progress
  bool new_stop = false;    // at least one stop condition was given
};

struct Command {
  enum class Kind { Help, Version, Render, Resume, Preview, Compare } kind = Kind::Help;
  RenderOptions render;
  ResumeOptions resume;
  PreviewOptions preview;
  CompareOptions compare;
};

// Parses argv. Throws UsageError with a one-line message for unknown flags, missing or bad
// values, out-of-range numbers and a render with no stop condition.
Command parse_command_line(int argc, const char* const* argv);

// Range checks of section "Options"; parse_command_line calls it, tests may call it directly.
void validate(const RenderOptions& options);

// The --help text.
std::string usage_text();

// Shortest text that reads back as the same double (metadata, messages).
std::string number_text(double v);

// "name=value" pairs of every option, for the EXR metadata and the progress header.
std::vector<std::pair<std::string, std::string>> describe(const RenderOptions& options);

}  // namespace pb
