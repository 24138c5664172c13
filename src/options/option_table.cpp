// The option table: every render option once, with its flag, member, range, default, help and
// kind (options.h). Adding an option means a row here, a member in RenderOptions and the code
// that uses it; parsing, validation, --help, metadata, the state file and resume follow.
#include "options/options.h"

#include "options/option_builders.h"
#include "options/option_lists.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

namespace pb {

namespace {

using namespace option_builders;
using namespace option_lists;

std::vector<OptionSpec> make_table() {
  using K = OptionKind;
  const char* stop = "stop conditions (at least one; whichever is reached first)";
  const char* render = "rendering";
  const char* bounds = "error bounds";
  const char* run = "running";
  const char* ckpt = "checkpoints";
  const char* measure = "measuring";
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<OptionSpec> t;
  t.push_back(text(
      base("-o", "output", "OUT.exr", run, K::Run, "the EXR to write (the name must end in .exr)"),
      &RenderOptions::output));
  t.back().accepted = {"x.exr"};  // validate() refuses any other extension
  t.push_back(integer(base("--passes", "passes", "N", stop, K::Stop, "passes to run"),
                      &RenderOptions::passes, {1, 1000000000000ULL}, "none"));
  t.push_back(real(
      base("--time", "time", "S", stop, K::Stop,
           "wall-clock budget in seconds (steady clock); a pass still running then is discarded"),
      &RenderOptions::time_seconds, {0, 1e9, true, false, " seconds", ""}, "none"));
  t.push_back(real(base("--target-error", "target_error", "E", stop, K::Stop,
                        "stop when the image is within E (see --stop-rule), at --confidence"),
                   &RenderOptions::target_error,
                   {0, kInf, true, true, "", "must be a finite number greater than 0"}, "none"));
  t.push_back(choice(base("--method", "method", "sppm|ppm", render, K::Image,
                          "stochastic PPM, whose pixels are area averages (anti-aliased), or PPM "
                          "with fixed pixel-centre points (HJJ10's setting)"),
                     &RenderOptions::method, {{"sppm", Method::SPPM}, {"ppm", Method::PPM}}));
  t.push_back(integer(base("--photons-per-pass", "photons_per_pass", "M", render, K::Image,
                           "photons emitted per pass (M_e)"),
                      &RenderOptions::photons_per_pass, {1, 1000000000ULL}));
  t.push_back(real(base("--alpha", "alpha", "A", render, K::Image,
                        "PPM radius reduction (with --adaptive radius: the fastest where the "
                        "photons are not the noise); 1 with --adaptive none never shrinks it"),
                   &RenderOptions::alpha, {0, 1, true, false, "", ""}));
  t.push_back(adaptive());
  t.push_back(real(
      base("--radius", "radius", "R", render, K::Image, "initial search radius in scene units"),
      &RenderOptions::radius, {0, 1e30, true, true, "", ""}, "4 pixel footprints"));
  t.push_back(integer(base("--max-depth", "max_depth", "D", render, K::Image,
                           "specular bounces a camera path may take"),
                      &RenderOptions::max_depth, {0, 32}));
  t.push_back(real(base("--mirror-roughness", "mirror_roughness", "R", render, K::Image,
                        "GGX lobes with a glTF roughness below R are rendered as perfect mirrors"),
                   &RenderOptions::mirror_roughness,
                   {kMinMirrorRoughness, 1, false, false, "", ""}));
  t.push_back(real(base("--follow-roughness", "follow_roughness", "R", render, K::Image,
                        "SPPM with next-event direct light: camera paths follow GGX lobes with a "
                        "roughness below R, and gather photons at their diffuse base; 0: never "
                        "(rough glass and diffuse transmission are followed at any R)"),
                   &RenderOptions::follow_roughness, {0, 1, false, false, "", ""}));
  t.push_back(resolution());
  t.push_back(text(base("--camera", "camera", "NAME", render, K::Image,
                        "glTF camera name, \"camera N\" when unnamed"),
                   &RenderOptions::camera, "first"));
  constexpr double kWorld = 1e10;  // the loader's limit on world coordinates
  t.push_back(triple(base("--look-from", "look_from", "X,Y,Z", render, K::Image,
                          "camera position, replacing the camera's (or the default view's)"),
                     &RenderOptions::look_from, kWorld, false, "the camera's"));
  t.push_back(triple(base("--look-at", "look_at", "X,Y,Z", render, K::Image,
                          "point the camera looks at (with --look-from alone: the bounds' centre)"),
                     &RenderOptions::look_at, kWorld, false, "the camera's"));
  t.push_back(
      triple(base("--up", "up", "X,Y,Z", render, K::Image, "direction that is up in the image"),
             &RenderOptions::up, kWorld, true, "the camera's, or +Y"));
  t.push_back(real(base("--fov", "fov", "DEGREES", render, K::Image,
                        "vertical field of view, replacing the camera's"),
                   &RenderOptions::fov, {0, 180, true, true, "", ""}, "the camera's, or 45"));
  t.push_back(
      environment(base("--environment", "environment", "COLOR|FILE.exr|FILE.hdr", render, K::Image,
                       "environment light: radiance V or R,G,B, or an equirectangular map "
                       "(centre column -Z, top row +Y)"),
                  "none; 1 without lights"));
  t.push_back(real(base("--environment-scale", "environment_scale", "S", render, K::Image,
                        "factor on the environment's radiance"),
                   &RenderOptions::environment_scale, {0, 1e30, true, false, "", ""}));
  t.push_back(asset_dirs());
  t.push_back(choice(base("--texture-formats", "texture_formats", "gltf|any", render, K::Image,
                          "formats a scene's images are decoded from: glTF's (PNG, JPEG, WebP; "
                          "others give a warning and their textures' factors), or any "
                          "OpenImageIO reads (TIFF, EXR, TGA, ...: only for files you trust)"),
                     &RenderOptions::texture_formats,
                     {{"gltf", TextureFormats::Gltf}, {"any", TextureFormats::Any}}));
  t.push_back(integer(base("--threads", "threads", "T", run, K::Run,
                           "worker threads, 0 = all; the image does not depend on it"),
                      &RenderOptions::threads, {0, 1024}));
  t.push_back(max_memory());
  t.push_back(integer(base("--seed", "seed", "S", render, K::Image,
                           "random seed; same seed, same image, bit for bit"),
                      &RenderOptions::seed, {0, UINT64_MAX}));
  t.push_back(choice(base("--direct", "direct", "nee|photons", render, K::Image,
                          "direct light by next-event estimation, or from photons"),
                     &RenderOptions::direct,
                     {{"nee", DirectMode::NextEvent}, {"photons", DirectMode::Photons}}));
  t.push_back(real(base("--confidence", "confidence", "C", bounds, K::Adjust,
                        "confidence 1 - beta of the error bounds"),
                   &RenderOptions::confidence, {0, 1, true, true, "", ""}));
  t.push_back(choice(base("--bias-model", "bias_model", "two-scale|laplacian", bounds, K::Adjust,
                          "the bias in the bounds: the Laplacian's a R^2 plus the fourth-order "
                          "part the two kernel scales measure, or HJJ10's a R^2 alone"),
                     &RenderOptions::bias_model,
                     {{"two-scale", BiasModel::TwoScale}, {"laplacian", BiasModel::Laplacian}}));
  t.push_back(integer(base("--min-passes", "min_passes", "N", bounds, K::Adjust,
                           "passes before the first stop test"),
                      &RenderOptions::min_passes, {2, 1000000000000ULL}));
  t.push_back(choice(base("--error-metric", "error_metric", "absolute|relative", bounds, K::Adjust,
                          "what --target-error measures; relative divides by max(L, 0.01 x "
                          "image mean)"),
                     &RenderOptions::metric,
                     {{"absolute", ErrorMetric::Absolute}, {"relative", ErrorMetric::Relative}}));
  t.push_back(stop_rule());
  OptionSpec progress = choice(base("--progress", "progress", "", run, K::Run,
                                    "progress lines on stderr (pass, photons, the tested quantity "
                                    "against the target, unknown "
                                    "pixels, elapsed, time left); auto = on a terminal"),
                               &RenderOptions::progress,
                               {{"auto", ProgressMode::Auto},
                                {"always", ProgressMode::Always},
                                {"never", ProgressMode::Never}});
  progress.switches = {{"--progress", "always"}, {"--quiet", "never"}};
  t.push_back(std::move(progress));
  t.push_back(real(base("--checkpoint-every", "checkpoint_every", "S", ckpt, K::Run,
                        "write the EXR and the state every S seconds"),
                   &RenderOptions::checkpoint_every, {0, 1e9, true, false, " seconds", ""},
                   "none"));
  t.push_back(text(base("--state", "state", "FILE", ckpt, K::Run,
                        "where the state goes (OUT with the extension .pbstate)"),
                   &RenderOptions::state_path, "OUT.pbstate"));
  t.push_back(text(base("--resume", "resume", "STATE", ckpt, K::Run,
                        "continue the render saved in STATE (scene and image options must match)"),
                   &RenderOptions::resume_from, "none"));
  t.push_back(text(base("--log", "log", "FILE.jsonl", measure, K::Run,
                        "per-pass JSON log (docs/usage.md \"Logging\")"),
                   &RenderOptions::log_path, "none"));
  t.push_back(text(base("--reference", "reference", "REF.exr", measure, K::Run,
                        "with --log: add the actual error and coverage against this image"),
                   &RenderOptions::reference_path, "none"));
  return t;
}

}  // namespace

std::string OptionSpec::display(const RenderOptions& o) const {
  const std::string v = format(o);
  return v.empty() ? unset : v;
}

const std::vector<OptionSpec>& option_table() {
  static const std::vector<OptionSpec> table = make_table();
  return table;
}

const OptionSpec* find_option(std::string_view flag) {
  for (const OptionSpec& s : option_table()) {
    if (s.switches.empty() && s.flag == flag) return &s;
    for (const auto& [f, v] : s.switches)
      if (f == flag) return &s;
  }
  return nullptr;
}

const OptionSpec& option(std::string_view key) {
  for (const OptionSpec& s : option_table())
    if (s.key == key) return s;
  throw std::logic_error("no option with key " + std::string(key));
}

bool environment_is_map(const std::string& text) { return is_map_file(text); }

std::array<double, 3> environment_colour(const std::string& text) {
  std::vector<double> v;
  if (!parse_numbers(text, v) || (v.size() != 1 && v.size() != 3))
    throw UsageError("--environment: '" + text + "' is not a colour");
  return v.size() == 3 ? std::array<double, 3>{v[0], v[1], v[2]}
                       : std::array<double, 3>{v[0], v[0], v[0]};
}

std::string number_text(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace pb
