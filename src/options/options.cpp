// Command-line parsing, validation, --help, metadata and resume rules, all from the option table
// (option_table.cpp).
#include "options/options.h"

#include "util/memory.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

namespace pb {

namespace {

[[noreturn]] void fail(const std::string& message) { throw UsageError(message); }

// -o names an OpenEXR file: the bound channels and float radiance exist only there (another
// extension would make OpenImageIO write another format, dropping them, or fail after the render).
void check_exr_output(const std::string& output) {
  std::string ext = std::filesystem::path(output).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".exr")
    fail("-o " + output +
         ": the output must be an OpenEXR file ending in .exr (only EXR holds the float radiance "
         "and the bound channels)");
}

double parse_exposure(const std::string& text) {
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size()) fail("--exposure: '" + text + "' is not a number");
  if (!std::isfinite(v)) fail("--exposure: '" + text + "' is not a finite number");
  if (std::fabs(v) > 64.0) fail("--exposure: must be in [-64, 64] stops");
  return v;
}

// Calls use(spec, value) for every flag from argv[first], in order; collects positionals.
template <class Use>
void for_each_flag(int argc, const char* const* argv, int first,
                   std::vector<std::string>& positional, Use&& use) {
  for (int k = first; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg.empty() || arg[0] != '-') {
      positional.push_back(arg);
      continue;
    }
    const OptionSpec* spec = find_option(arg);
    if (!spec) fail("unknown option '" + arg + "' (see photonbound --help)");
    std::string value;
    if (!spec->switches.empty()) {
      for (const auto& [f, v] : spec->switches)
        if (f == arg) value = v;
    } else {
      if (k + 1 >= argc) fail(arg + ": missing value");
      value = argv[++k];
    }
    use(*spec, value);
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
  std::vector<std::string> positional;
  for_each_flag(argc, argv, first, positional,
                [&](const OptionSpec& s, const std::string& v) { s.parse(o, v); });
  if (positional.size() > 1)
    fail("unexpected argument '" + positional[1] + "': only one scene file is rendered");
  if (!positional.empty()) o.scene = positional[0];
  validate(o);
  return o;
}

ResumeOptions parse_resume(int argc, const char* const* argv, int first) {
  ResumeOptions r;
  r.command_line = join_command_line(argc, argv);
  std::vector<std::string> positional;
  RenderOptions check;  // the values' own ranges
  for_each_flag(argc, argv, first, positional, [&](const OptionSpec& s, const std::string& v) {
    if (s.kind == OptionKind::Image)
      fail("resume: " + std::string(s.flag) +
           " cannot be given when resuming: the state file "
           "fixes it");
    if (s.key == "resume") fail("resume: --resume is the command itself; give the state once");
    s.parse(check, v);
    r.given.emplace_back(&s, v);
  });
  if (positional.size() != 1)
    fail("resume: usage: photonbound resume STATE -o OUT.exr [stop conditions]");
  r.state = positional[0];
  if (check.output.empty()) fail("resume: no output file given (-o OUT.exr)");
  check_exr_output(check.output);
  if (!check.reference_path.empty() && check.log_path.empty())
    fail("--reference: only used by --log (give --log FILE.jsonl too)");
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
        o.exposure = parse_exposure(v);
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
  check_exr_output(o.output);
  if (!o.passes && !o.time_seconds && !o.target_error)
    fail("render: no stop condition: give --passes, --time or --target-error");
  for (const OptionSpec& s : option_table()) s.check(o);
  if (!o.reference_path.empty() && o.log_path.empty())
    fail("--reference: only used by --log (give --log FILE.jsonl too)");
}

RenderOptions resumed_options(const RenderOptions& saved, const ResumeOptions& r) {
  RenderOptions o = saved;
  bool new_stop = false;
  for (const auto& [spec, value] : r.given) new_stop |= spec->kind == OptionKind::Stop;
  for (const OptionSpec& s : option_table())  // this run's own options start afresh
    if (s.kind == OptionKind::Run || (new_stop && s.kind == OptionKind::Stop)) s.reset(o);
  for (const auto& [spec, value] : r.given) spec->parse(o, value);
  o.resume_from = r.state;
  o.command_line = r.command_line;
  validate(o);
  return o;
}

std::vector<std::string> image_differences(const RenderOptions& a, const RenderOptions& b) {
  std::vector<std::string> d;
  for (const OptionSpec& s : option_table()) {
    if (s.kind != OptionKind::Image) continue;
    const std::string x = s.display(a), y = s.display(b);
    if (x != y)
      d.push_back(std::string(s.flag.substr(2)) + ": " + x + " in the state, " + y + " now");
  }
  return d;
}

std::string state_path_for(const RenderOptions& o) {
  if (!o.state_path.empty()) return o.state_path;
  const size_t slash = o.output.find_last_of('/');
  const size_t dot = o.output.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (has_ext ? o.output.substr(0, dot) : o.output) + ".pbstate";
}

uint64_t memory_budget(const RenderOptions& o) {
  return o.max_memory ? *o.max_memory : default_memory_budget();
}

Command parse_command_line(int argc, const char* const* argv) {
  Command c;
  if (argc < 2) fail("no command given (see photonbound --help)");
  const std::string cmd = argv[1];
  // `photonbound render --help` and the like ask for the same text as `photonbound --help`.
  bool asks_help = false;
  for (int k = 2; k < argc; ++k)
    asks_help = asks_help || std::string(argv[k]) == "--help" || std::string(argv[k]) == "-h";
  if (cmd == "--help" || cmd == "-h" || cmd == "help" || asks_help) {
    c.kind = Command::Kind::Help;
  } else if (cmd == "--help-table") {
    c.kind = Command::Kind::HelpTable;
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
  std::string s = R"(photonbound: progressive photon mapping with per-pixel error bounds

usage:
  photonbound render SCENE.gltf|.glb -o OUT.exr [options]
  photonbound resume STATE -o OUT.exr [options other than rendering ones]
  photonbound compare RENDER.exr REFERENCE.exr [--json]
  photonbound preview IN.exr -o OUT.png [--exposure STOPS]
  photonbound --help | --version
)";
  // Sections in this order; an option's own group name decides where it goes.
  std::vector<std::string_view> groups;
  for (const OptionSpec& o : option_table())
    if (std::find(groups.begin(), groups.end(), o.group) == groups.end()) groups.push_back(o.group);
  std::stable_partition(groups.begin(), groups.end(), [](std::string_view g) {
    return g.substr(0, 4) == "stop" || g == "rendering" || g == "error bounds";
  });
  for (const std::string_view g : groups) {
    s += "\n" + std::string(g) + ":\n";
    for (const OptionSpec& o : option_table()) {
      if (o.group != g) continue;
      std::string head = "  ";
      if (o.switches.empty()) {
        head += std::string(o.flag) + " " + std::string(o.metavar);
      } else {
        for (size_t k = 0; k < o.switches.size(); ++k)
          head += (k ? " | " : "") + std::string(o.switches[k].first);
      }
      head.resize(std::max<size_t>(head.size() + 1, 25), ' ');
      std::string tail = std::string(o.help);
      std::string notes = o.range;
      const std::string def = o.default_text();
      if (!o.switches.empty() || o.kind == OptionKind::Run) {
        // Outputs and switches: the default says itself in the help.
      } else {
        notes += (notes.empty() ? "" : "; ") + ("default " + (def.empty() ? "none" : def));
      }
      s += head + tail + (notes.empty() ? "" : " (" + notes + ")") + "\n";
    }
  }
  return s;
}

std::string markdown_option_table() {
  auto cell = [](std::string text) {  // a | inside a cell must be escaped in Markdown
    std::string out;
    for (const char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
  };
  auto on_resume = [](OptionKind k) {
    switch (k) {
      case OptionKind::Image:
        return "fixed by the state";
      case OptionKind::Stop:
        return "replaces the saved stop conditions";
      case OptionKind::Adjust:
        return "kept unless given";
      case OptionKind::Run:
        return "this run only";
    }
    return "";
  };
  std::string s = "| option | range | default | meaning | on resume |\n|---|---|---|---|---|\n";
  for (const OptionSpec& o : option_table()) {
    std::string flags;
    if (o.switches.empty()) {
      flags =
          "`" + std::string(o.flag) + (o.metavar.empty() ? "" : " " + std::string(o.metavar)) + "`";
    } else {
      for (size_t k = 0; k < o.switches.size(); ++k)
        flags += (k ? ", `" : "`") + std::string(o.switches[k].first) + "`";
    }
    const std::string def = o.default_text();
    s += "| " + cell(flags) + " | " + o.range + " | " + cell(def.empty() ? "none" : def) + " | " +
         cell(std::string(o.help)) + " | " + on_resume(o.kind) + " |\n";
  }
  return s;
}

std::vector<std::pair<std::string, std::string>> describe(const RenderOptions& o) {
  std::vector<std::pair<std::string, std::string>> d = {{"scene", o.scene}};
  for (const OptionSpec& s : option_table()) d.emplace_back(std::string(s.key), s.display(o));
  return d;
}

}  // namespace pb
