#include "photonbound/options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <map>

namespace pb {

namespace {

[[noreturn]] void fail(const std::string& message) { throw UsageError(message); }

uint64_t parse_uint(const std::string& flag, const std::string& text, uint64_t lo, uint64_t hi) {
  uint64_t v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec == std::errc::result_out_of_range)
    fail(flag + ": '" + text + "' is not a whole number in [" + std::to_string(lo) + ", " +
         std::to_string(hi) + "]");
  if (ec != std::errc() || ptr != end) fail(flag + ": '" + text + "' is not a whole number");
  if (v < lo || v > hi)
    fail(flag + ": " + text + " is out of range [" + std::to_string(lo) + ", " +
         std::to_string(hi) + "]");
  return v;
}

double parse_real(const std::string& flag, const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end)
    fail(flag + ": '" + text + "' is not a number");
  if (!std::isfinite(v)) fail(flag + ": '" + text + "' is not a finite number");
  return v;
}

void parse_resolution(const std::string& text, RenderOptions& o) {
  const size_t x = text.find('x');
  if (x == std::string::npos) fail("--resolution: '" + text + "' is not WIDTHxHEIGHT");
  o.width = int(parse_uint("--resolution width", text.substr(0, x), 1, 16384));
  o.height = int(parse_uint("--resolution height", text.substr(x + 1), 1, 16384));
}

// Flags that take a value, and how each is stored.
using Setter = std::function<void(RenderOptions&, const std::string&)>;

const std::map<std::string, Setter>& value_flags() {
  static const std::map<std::string, Setter> flags = {
      {"-o", [](RenderOptions& o, const std::string& v) { o.output = v; }},
      {"--passes",
       [](RenderOptions& o, const std::string& v) {
         o.passes = parse_uint("--passes", v, 1, 1000000000000ULL);
       }},
      {"--time",
       [](RenderOptions& o, const std::string& v) { o.time_seconds = parse_real("--time", v); }},
      {"--target-error",
       [](RenderOptions& o, const std::string& v) {
         o.target_error = parse_real("--target-error", v);
       }},
      {"--photons-per-pass",
       [](RenderOptions& o, const std::string& v) {
         o.photons_per_pass = parse_uint("--photons-per-pass", v, 1, 1000000000ULL);
       }},
      {"--alpha",
       [](RenderOptions& o, const std::string& v) { o.alpha = parse_real("--alpha", v); }},
      {"--radius",
       [](RenderOptions& o, const std::string& v) { o.radius = parse_real("--radius", v); }},
      {"--max-depth",
       [](RenderOptions& o, const std::string& v) {
         o.max_depth = int(parse_uint("--max-depth", v, 0, 32));
       }},
      {"--resolution", [](RenderOptions& o, const std::string& v) { parse_resolution(v, o); }},
      {"--camera",
       [](RenderOptions& o, const std::string& v) {
         if (v.empty()) fail("--camera: the name is empty");
         o.camera = v;
       }},
      {"--threads",
       [](RenderOptions& o, const std::string& v) {
         o.threads = int(parse_uint("--threads", v, 0, 1024));
       }},
      {"--seed", [](RenderOptions& o,
                    const std::string& v) { o.seed = parse_uint("--seed", v, 0, UINT64_MAX); }},
      {"--direct",
       [](RenderOptions& o, const std::string& v) {
         if (v == "nee")
           o.direct = DirectMode::NextEvent;
         else if (v == "photons")
           o.direct = DirectMode::Photons;
         else
           fail("--direct: '" + v + "' is not one of nee, photons");
       }},
      {"--confidence", [](RenderOptions& o,
                          const std::string& v) { o.confidence = parse_real("--confidence", v); }},
      {"--min-passes",
       [](RenderOptions& o, const std::string& v) {
         o.min_passes = parse_uint("--min-passes", v, 2, 1000000000000ULL);
       }},
      {"--checkpoint-every",
       [](RenderOptions& o, const std::string& v) {
         o.checkpoint_every = parse_real("--checkpoint-every", v);
       }},
      {"--state",
       [](RenderOptions& o, const std::string& v) {
         if (v.empty()) fail("--state: the path is empty");
         o.state_path = v;
       }},
      {"--resume",
       [](RenderOptions& o, const std::string& v) {
         if (v.empty()) fail("--resume: the path is empty");
         o.resume_from = v;
       }},
      {"--log",
       [](RenderOptions& o, const std::string& v) {
         if (v.empty()) fail("--log: the path is empty");
         o.log_path = v;
       }},
      {"--reference",
       [](RenderOptions& o, const std::string& v) {
         if (v.empty()) fail("--reference: the path is empty");
         o.reference_path = v;
       }},
      {"--error-metric",
       [](RenderOptions& o, const std::string& v) {
         if (v == "absolute")
           o.metric = ErrorMetric::Absolute;
         else if (v == "relative")
           o.metric = ErrorMetric::Relative;
         else
           fail("--error-metric: '" + v + "' is not one of absolute, relative");
       }},
  };
  return flags;
}

// Fills `o` from the flags; `given` collects the flags seen.
void parse_flags(int argc, const char* const* argv, int first, RenderOptions& o,
                 std::vector<std::string>& positional, std::vector<std::string>& given) {
  for (int k = first; k < argc; ++k) {
    const std::string arg = argv[k];
    if (!arg.empty() && arg[0] == '-') given.push_back(arg);
    if (arg == "--progress") {
      o.progress = ProgressMode::Always;
    } else if (arg == "--quiet") {
      o.progress = ProgressMode::Never;
    } else if (auto it = value_flags().find(arg); it != value_flags().end()) {
      if (k + 1 >= argc) fail(arg + ": missing value");
      it->second(o, argv[++k]);
    } else if (!arg.empty() && arg[0] == '-') {
      fail("unknown option '" + arg + "' (see photonbound --help)");
    } else {
      positional.push_back(arg);
    }
  }
}

std::string join_command_line(int argc, const char* const* argv) {
  std::string s;
  for (int k = 0; k < argc; ++k) s += (k ? " " : "") + std::string(argv[k]);
  return s;
}

RenderOptions parse_render(int argc, const char* const* argv, int first) {
  RenderOptions o;
  o.command_line = join_command_line(argc, argv);
  std::vector<std::string> positional, given;
  parse_flags(argc, argv, first, o, positional, given);
  if (positional.size() > 1)
    fail("unexpected argument '" + positional[1] + "': only one scene file is rendered");
  if (!positional.empty()) o.scene = positional[0];
  validate(o);
  return o;
}

ResumeOptions parse_resume(int argc, const char* const* argv, int first) {
  ResumeOptions r;
  std::vector<std::string> positional, given;
  parse_flags(argc, argv, first, r.overrides, positional, given);
  static const std::vector<std::string> allowed = {
      "-o",        "--passes",   "--time",  "--target-error", "--checkpoint-every", "--state",
      "--threads", "--progress", "--quiet", "--log",          "--reference"};
  for (const std::string& g : given)
    if (std::find(allowed.begin(), allowed.end(), g) == allowed.end())
      fail("resume: " + g + " cannot be given when resuming: the state file fixes it");
  if (positional.size() != 1)
    fail("resume: usage: photonbound resume STATE -o OUT.exr [stop conditions]");
  r.state = positional[0];
  if (r.overrides.output.empty()) fail("resume: no output file given (-o OUT.exr)");
  r.new_stop = r.overrides.passes || r.overrides.time_seconds || r.overrides.target_error;
  r.overrides.command_line = join_command_line(argc, argv);
  RenderOptions check = r.overrides;  // range checks of the flags given
  check.scene = r.state;
  if (!r.new_stop) check.passes = 1;
  validate(check);
  return r;
}

PreviewOptions parse_preview(int argc, const char* const* argv, int first) {
  PreviewOptions o;
  for (int k = first; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "-o" || arg == "--exposure") {
      if (k + 1 >= argc) fail(arg + ": missing value");
      const std::string v = argv[++k];
      if (arg == "-o")
        o.output = v;
      else
        o.exposure = parse_real("--exposure", v);
    } else if (!arg.empty() && arg[0] == '-') {
      fail("unknown option '" + arg + "' (see photonbound --help)");
    } else if (o.input.empty()) {
      o.input = arg;
    } else {
      fail("unexpected argument '" + arg + "'");
    }
  }
  if (o.input.empty() || o.output.empty())
    fail("preview: usage: photonbound preview IN.exr -o OUT.png");
  if (std::fabs(o.exposure) > 64.0) fail("--exposure: must be in [-64, 64] stops");
  return o;
}

CompareOptions parse_compare(int argc, const char* const* argv, int first) {
  CompareOptions o;
  std::vector<std::string> files;
  for (int k = first; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--json")
      o.json = true;
    else if (!arg.empty() && arg[0] == '-')
      fail("unknown option '" + arg + "' (see photonbound --help)");
    else
      files.push_back(arg);
  }
  if (files.size() != 2)
    fail("compare: usage: photonbound compare RENDER.exr REFERENCE.exr [--json]");
  o.render = files[0];
  o.reference = files[1];
  return o;
}

}  // namespace

void validate(const RenderOptions& o) {
  if (o.scene.empty()) fail("render: no scene file given");
  if (o.output.empty()) fail("render: no output file given (-o OUT.exr)");
  if (!o.passes && !o.time_seconds && !o.target_error)
    fail("render: no stop condition: give --passes, --time or --target-error");
  if (o.time_seconds && !(*o.time_seconds > 0.0 && *o.time_seconds <= 1e9))
    fail("--time: must be in (0, 1e9] seconds");
  // Every range of README "Command line" is checked here too, not only by the parser: options
  // built in process (tests, the library) must meet the same ranges.
  if (o.passes && !(*o.passes >= 1 && *o.passes <= 1000000000000ULL))
    fail("--passes: must be in [1, 1e12]");
  if (o.target_error && !(*o.target_error > 0.0 && std::isfinite(*o.target_error)))
    fail("--target-error: must be a finite number greater than 0");
  if (!(o.alpha > 0.0 && o.alpha <= 1.0)) fail("--alpha: must be in (0, 1]");
  if (o.radius && !(*o.radius > 0.0 && *o.radius < 1e30)) fail("--radius: must be in (0, 1e30)");
  if (!(o.confidence > 0.0 && o.confidence < 1.0)) fail("--confidence: must be in (0, 1)");
  if (!(o.photons_per_pass >= 1 && o.photons_per_pass <= 1000000000ULL))
    fail("--photons-per-pass: must be in [1, 1e9]");
  if (!(o.max_depth >= 0 && o.max_depth <= 32)) fail("--max-depth: must be in [0, 32]");
  if ((o.width && !(*o.width >= 1 && *o.width <= 16384)) ||
      (o.height && !(*o.height >= 1 && *o.height <= 16384)))
    fail("--resolution: width and height must be in [1, 16384]");
  if (!(o.threads >= 0 && o.threads <= 1024)) fail("--threads: must be in [0, 1024]");
  if (!(o.min_passes >= 2 && o.min_passes <= 1000000000000ULL))
    fail("--min-passes: must be in [2, 1e12]");
  if (!o.reference_path.empty() && o.log_path.empty())
    fail("--reference: only used by --log (give --log FILE.jsonl too)");
  if (o.checkpoint_every && !(*o.checkpoint_every > 0.0 && *o.checkpoint_every <= 1e9))
    fail("--checkpoint-every: must be in (0, 1e9] seconds");
}

std::string state_path_for(const RenderOptions& o) {
  if (!o.state_path.empty()) return o.state_path;
  const size_t slash = o.output.find_last_of('/');
  const size_t dot = o.output.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (has_ext ? o.output.substr(0, dot) : o.output) + ".pbstate";
}

Command parse_command_line(int argc, const char* const* argv) {
  Command c;
  if (argc < 2) fail("no command given (see photonbound --help)");
  const std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    c.kind = Command::Kind::Help;
  } else if (cmd == "--version") {
    c.kind = Command::Kind::Version;
  } else if (cmd == "render") {
    c.kind = Command::Kind::Render;
    c.render = parse_render(argc, argv, 2);
  } else if (cmd == "resume") {
    c.kind = Command::Kind::Resume;
    c.resume = parse_resume(argc, argv, 2);
  } else if (cmd == "compare") {
    c.kind = Command::Kind::Compare;
    c.compare = parse_compare(argc, argv, 2);
  } else if (cmd == "preview") {
    c.kind = Command::Kind::Preview;
    c.preview = parse_preview(argc, argv, 2);
  } else {
    fail("unknown command '" + cmd + "' (see photonbound --help)");
  }
  return c;
}

std::string usage_text() {
  return R"(photonbound: progressive photon mapping with per-pixel error bounds

usage:
  photonbound render SCENE.gltf|.glb -o OUT.exr [options]
  photonbound resume STATE -o OUT.exr [--passes N] [--time S] [--target-error E] [checkpoints]
  photonbound compare RENDER.exr REFERENCE.exr [--json]
  photonbound preview IN.exr -o OUT.png [--exposure STOPS]
  photonbound --help | --version

stop conditions (at least one; whichever is reached first):
  --passes N             passes to run (1 .. 1e12)
  --time SECONDS         wall-clock budget, finishing the current pass (0 .. 1e9]
  --target-error E       stop when the image mean error bound is <= E (> 0)

options:
  --photons-per-pass M   photons emitted per pass (1 .. 1e9; default 100000)
  --alpha A              PPM radius reduction (0, 1] (default 0.7)
  --radius R             initial search radius in scene units (0, 1e30) (default 4 pixel footprints)
  --max-depth D          specular bounces of camera paths (0 .. 32; default 8)
  --resolution WxH       image size (1 .. 16384 each; default 512 wide, camera aspect)
  --camera NAME          glTF camera name, "camera N" when unnamed (default: the first one)
  --threads T            worker threads (0 = all; default 0)
  --seed S               random seed (0 .. 2^64-1; default 1)
  --direct nee|photons   direct light by next-event estimation (default) or from photons
  --confidence C         confidence of the error bounds (0, 1) (default 0.9)
  --min-passes N         passes before any bound or stop test (>= 2; default 16)
  --error-metric absolute|relative   what --target-error measures (default absolute)
  --progress | --quiet   force the progress line on or off (default: on when stderr is a terminal)

checkpoints:
  --checkpoint-every S   write the EXR and a state file every S seconds (0 .. 1e9]
  --state FILE           state file (default: OUT with the extension .pbstate); written at
                         checkpoints, on Ctrl-C, and at the end when checkpoints are on
  --resume STATE         continue the render saved in STATE (its scene and options must match)

measuring:
  --log FILE.jsonl       one JSON line per logged pass: pass, seconds, photons, mean bound,
                         mean noise, mean |bias|, fraction below target, unknown pixels
                         (sparse: logging stays within 3% of the run time; last pass always)
  --reference REF.exr    with --log: also the actual mean error, RMSE and coverage
)";
}

std::string number_text(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::vector<std::pair<std::string, std::string>> describe(const RenderOptions& o) {
  const auto num = number_text;
  std::vector<std::pair<std::string, std::string>> d = {
      {"scene", o.scene},
      {"passes", o.passes ? std::to_string(*o.passes) : "none"},
      {"time", o.time_seconds ? num(*o.time_seconds) : "none"},
      {"target_error", o.target_error ? num(*o.target_error) : "none"},
      {"photons_per_pass", std::to_string(o.photons_per_pass)},
      {"alpha", num(o.alpha)},
      {"radius", o.radius ? num(*o.radius) : "auto"},
      {"max_depth", std::to_string(o.max_depth)},
      {"camera", o.camera.empty() ? "first" : o.camera},
      {"seed", std::to_string(o.seed)},
      {"direct", o.direct == DirectMode::NextEvent ? "nee" : "photons"},
      {"confidence", num(o.confidence)},
      {"min_passes", std::to_string(o.min_passes)},
      {"error_metric", o.metric == ErrorMetric::Absolute ? "absolute" : "relative"},
  };
  return d;
}

}  // namespace pb
