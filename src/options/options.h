// The one options struct, filled by the command-line parser, validated once, passed explicitly.
// Every option is described once, in the table of option_table.cpp (flag, member, range,
// default, help, and what resume may change); parsing, validation, --help, the EXR metadata, the
// state file's options block and resume's list of differences are all made from that table.
#pragma once

#include "bsdf/mirror_roughness.h"
#include "estimator/error_model.h"  // ErrorMetric

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pb {

// Bad command-line usage; main maps it to exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Method { SPPM, PPM };
enum class DirectMode { NextEvent, Photons };
enum class ProgressMode { Auto, Always, Never };
// What --target-error tests (docs/usage.md "Stop rules", ESTIMATOR.md section 7).
enum class StopRule { MeanError, MeanBound, Pixels };
// Which image formats a scene's textures may be in (gltf_loader.h LoadPolicy).
enum class TextureFormats { Gltf, Any };

// Members only: ranges, defaults and help live in the option table.
// Below this roughness a gathered GGX lobe's sparse-photon bound falls slowly where photons
// are few (10^4-fold on Blender's 01_principled_material at 32 passes), while following a lobe
// at or above it costs at most about 3x where they are plentiful (docs/materials.md, "Sharp
// lobes are followed in SPPM").
inline constexpr double kDefaultFollowRoughness = 0.7;

struct RenderOptions {
  std::string scene;  // glTF file (the positional argument, not an option)
  // Folders besides the scene's own that its buffers and images may be read from (--asset-dir,
  // repeatable; absolute: the state is resumed from anywhere).
  std::vector<std::string> asset_dirs;
  // --texture-formats: glTF's image formats only (PNG, JPEG, WebP), or any OpenImageIO reads.
  TextureFormats texture_formats = TextureFormats::Gltf;
  std::string output;  // -o
  // Stop conditions: whichever comes first; at least one is required.
  std::optional<uint64_t> passes;
  std::optional<double> time_seconds;
  std::optional<double> target_error;
  Method method = Method::SPPM;
  uint64_t photons_per_pass = 100000;  // M_e
  double alpha = 0.7;
  // --adaptive: which parts of the render follow each pixel's own error estimates
  // (ESTIMATOR.md sections 13-15); none = every point on the PPM schedule, every photon
  // emitted in proportion to power. The radius is the default: it reached every measured
  // target as soon or sooner (section 13, "Measured").
  bool adaptive_radius = true;
  bool adaptive_photons = false;
  bool adaptive_paths = false;   // SPPM: section 15
  std::optional<double> radius;  // world units; default from the pixel footprint
  // --bias-model (ESTIMATOR.md section 6c): the bounds' bias with the two scales' fourth-order
  // part, or the Laplacian's second-order part alone (HJJ10). Never changes the image.
  BiasModel bias_model = BiasModel::TwoScale;
  int max_depth = 8;
  double mirror_roughness = kDefaultMirrorRoughness;
  // SPPM with next-event direct light: camera paths follow GGX lobes below this roughness
  // (camera_paths.h); 0 gathers photons at every glossy surface.
  double follow_roughness = kDefaultFollowRoughness;
  std::optional<int> width, height;
  std::string camera;  // empty = first perspective camera
  // The view (camera_choice.h): each replaces the camera's own, or the default view's when the file
  // has no camera.
  std::optional<std::array<double, 3>> look_from, look_at, up;
  std::optional<double> fov;  // vertical field of view, degrees
  // The environment light (scene_defaults.h): "" for none, or the default sky when the scene has
  // no light; a colour "V" or "R,G,B"; or an .exr / .hdr equirectangular map.
  std::string environment;
  double environment_scale = 1.0;
  int threads = 0;
  // --max-memory in bytes; unset: default_memory_budget() (util/memory.h).
  std::optional<uint64_t> max_memory;
  uint64_t seed = 1;
  DirectMode direct = DirectMode::NextEvent;
  double confidence = 0.9;  // 1 - beta
  uint64_t min_passes = 16;
  ErrorMetric metric = ErrorMetric::Absolute;
  StopRule stop_rule = StopRule::MeanError;
  double stop_fraction = 0.9;  // pixels:Q, the share of pixels whose bound must meet the target
  ProgressMode progress = ProgressMode::Auto;
  std::optional<double> checkpoint_every;
  std::string state_path;
  std::string resume_from;
  std::string log_path;
  std::string reference_path;
  std::string command_line;  // as typed, for the metadata (not an option)
};

// What `resume` may do with an option (docs/usage.md "Checkpoints and interruption").
enum class OptionKind {
  Image,   // shapes the render state: a continued render must have the saved value
  Stop,    // a stop condition: given on resume, the three replace the saved ones together
  Adjust,  // how the render is stopped or reported: kept from the state unless given again
  Run,     // this run only (output, threads, progress, checkpoints, log): never carried over
};

struct OptionSpec {
  std::string_view flag;     // "--alpha"
  std::string_view key;      // "alpha": EXR metadata and state file
  std::string_view metavar;  // "A"; empty for a switch
  std::string_view help;     // one line
  std::string_view group;    // --help section
  OptionKind kind = OptionKind::Image;
  std::string range;  // "(0, 1]" as docs/usage.md and --help print it; empty when not numeric
  std::string unset;  // how an unset optional reads: "none", "auto", "first"
  // Value-less flags and the value each stands for (--progress = always, --quiet = never).
  std::vector<std::pair<std::string_view, std::string_view>> switches;
  // Text -> member, range-checked; throws UsageError "<flag>: ...".
  std::function<void(RenderOptions&, const std::string&)> parse;
  // Member -> text that parse() reads back to the same value; "" when unset.
  std::function<std::string(const RenderOptions&)> format;
  // Range check of a value set in process; throws the same UsageError as parse().
  std::function<void(const RenderOptions&)> check;
  // Sets the member back to its default.
  std::function<void(RenderOptions&)> reset;
  // For the table's own test: texts at and just beyond the documented bounds.
  std::vector<std::string> accepted, rejected;

  std::string display(const RenderOptions& o) const;  // format(), or `unset`
  std::string default_text() const { return display(RenderOptions{}); }
};

const std::vector<OptionSpec>& option_table();
const OptionSpec* find_option(std::string_view flag_or_switch);  // null when unknown
const OptionSpec& option(std::string_view key);                  // by key; throws when unknown

// --environment's text (accepted by the option table): true when it names a map file (.exr or
// .hdr, any case); otherwise its colour, grey "V" repeated.
bool environment_is_map(const std::string& text);
std::array<double, 3> environment_colour(const std::string& text);

// The state file a render writes: --state, or the output path with its extension replaced by
// ".pbstate".
std::string state_path_for(const RenderOptions& options);

// --max-memory, or its default (3/4 of the machine's memory).
uint64_t memory_budget(const RenderOptions& options);

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

// photonbound resume STATE -o OUT.exr [options of kind Stop, Adjust and Run]
struct ResumeOptions {
  std::string state;
  std::vector<std::pair<const OptionSpec*, std::string>> given;  // as typed, in order
  std::string command_line;
};

struct Command {
  enum class Kind { Help, HelpTable, Version, Render, Resume, Preview, Compare } kind = Kind::Help;
  RenderOptions render;
  ResumeOptions resume;
  PreviewOptions preview;
  CompareOptions compare;
};

// Parses argv. Throws UsageError with a one-line message for unknown flags, missing or bad
// values, out-of-range numbers and a render with no stop condition.
Command parse_command_line(int argc, const char* const* argv);

// The options a resumed render runs with: the saved ones, with what `given` sets applied by
// the rules of OptionKind. Throws UsageError for an option of kind Image.
RenderOptions resumed_options(const RenderOptions& saved, const ResumeOptions& resume);

// Every range of the table and the rules across options (a stop condition, --reference only
// with --log); parse_command_line calls it, tests may call it directly.
void validate(const RenderOptions& options);

// The --help text, made from the table.
std::string usage_text();
// The option table of docs/usage.md "Command line", made from the table (`photonbound
// --help-table`; Options.UsageOptionTableIsTheGeneratedOne checks that docs/usage.md holds
// exactly this).
std::string markdown_option_table();

// Shortest text that reads back as the same double (metadata, messages).
std::string number_text(double v);

// "key=value" pairs of the scene and every option, for the EXR metadata.
std::vector<std::pair<std::string, std::string>> describe(const RenderOptions& options);

// Options of kind Image whose values differ: "name: X in the state, Y now" each.
std::vector<std::string> image_differences(const RenderOptions& saved, const RenderOptions& now);

}  // namespace pb
