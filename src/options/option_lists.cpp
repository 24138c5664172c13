// The options whose values are lists or carry units (option_lists.h).
#include "options/option_lists.h"

#include "options/option_builders.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

namespace pb::option_lists {

namespace {

using namespace option_builders;

// The parts of a list between separators, empty ones included ("a," is "a" and "").
std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  for (size_t at = 0; at <= text.size();) {
    const size_t end = std::min(text.find(separator, at), text.size());
    parts.push_back(text.substr(at, end - at));
    at = end + 1;
  }
  return parts;
}

}  // namespace

using namespace option_builders;

OptionSpec resolution() {
  OptionSpec s =
      base("--resolution", "resolution", "WxH", "rendering", OptionKind::Image, "image size");
  const IntRange r{1, 16384};
  s.range = r.text() + " each";
  s.unset = "512 wide, camera aspect";
  auto side = [](const std::string& t) -> long double {
    if (t.empty() || t.find_first_not_of("0123456789") != std::string::npos) return -1;
    return t.size() > 9 ? 1e30L : (long double)std::stoull(t);
  };
  const std::string bad = "width and height must be in " + r.text();
  s.parse = [=](RenderOptions& o, const std::string& t) {
    const size_t x = t.find('x');
    if (x == std::string::npos) fail("--resolution", "'" + t + "' is not WIDTHxHEIGHT");
    const long double w = side(t.substr(0, x)), h = side(t.substr(x + 1));
    if (w < 0 || h < 0) fail("--resolution", "'" + t + "' is not WIDTHxHEIGHT");
    if (!(w >= 1 && w <= 16384 && h >= 1 && h <= 16384)) fail("--resolution", bad);
    o.width = int(w);
    o.height = int(h);
  };
  s.check = [=](const RenderOptions& o) {
    if ((o.width && !(*o.width >= 1 && *o.width <= 16384)) ||
        (o.height && !(*o.height >= 1 && *o.height <= 16384)))
      fail("--resolution", bad);
  };
  s.format = [](const RenderOptions& o) {
    return o.width && o.height ? std::to_string(*o.width) + "x" + std::to_string(*o.height) : "";
  };
  s.reset = [](RenderOptions& o) {
    o.width.reset();
    o.height.reset();
  };
  s.accepted = {"1x1", "16384x16384"};
  s.rejected = {"0x4", "4x16385", "4"};
  return s;
}

OptionSpec stop_rule() {
  OptionSpec s = base("--stop-rule", "stop_rule", "mean-error|mean-bound|pixels:Q", "error bounds",
                      OptionKind::Adjust,
                      "what --target-error tests: the image's mean error at the confidence, the "
                      "mean of the per-pixel bounds (HJJ10), or the share Q of pixels whose bound "
                      "meets the target");
  const std::string bad = "is not one of mean-error, mean-bound, pixels:Q with Q in (0, 1]";
  s.parse = [=](RenderOptions& o, const std::string& t) {
    if (t == "mean-error") {
      o.stop_rule = StopRule::MeanError;
    } else if (t == "mean-bound") {
      o.stop_rule = StopRule::MeanBound;
    } else if (t.rfind("pixels:", 0) == 0) {
      double q = 0.0;
      const std::string v = t.substr(7);
      const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), q);
      if (v.empty() || ec != std::errc() || ptr != v.data() + v.size() || !(q > 0.0 && q <= 1.0))
        fail("--stop-rule", "'" + t + "' " + bad);
      o.stop_rule = StopRule::Pixels;
      o.stop_fraction = q;
    } else {
      fail("--stop-rule", "'" + t + "' " + bad);
    }
  };
  s.check = [=](const RenderOptions& o) {
    if (o.stop_rule == StopRule::Pixels && !(o.stop_fraction > 0.0 && o.stop_fraction <= 1.0))
      fail("--stop-rule", "pixels:Q needs Q in (0, 1]");
  };
  s.format = [](const RenderOptions& o) -> std::string {
    switch (o.stop_rule) {
      case StopRule::MeanError:
        return "mean-error";
      case StopRule::MeanBound:
        return "mean-bound";
      case StopRule::Pixels:
        return "pixels:" + number_text(o.stop_fraction);
    }
    return "mean-error";
  };
  s.reset = [](RenderOptions& o) {
    o.stop_rule = RenderOptions{}.stop_rule;
    o.stop_fraction = RenderOptions{}.stop_fraction;
  };
  s.accepted = {"mean-error", "mean-bound", "pixels:0.9", "pixels:1"};
  s.rejected = {"", "mean", "pixels:0", "pixels:1.5", "pixels:", "pixels:x"};
  return s;
}

// --asset-dir: repeatable, each folder appended, made absolute (the state is resumed from any
// working directory). The list is one text, a folder a line, so that a state or the metadata
// reads it back (a name with a line break is read as two folders).
OptionSpec asset_dirs() {
  OptionSpec s = base("--asset-dir", "asset_dir", "DIR", "rendering", OptionKind::Image,
                      "a folder the scene's buffers and images may also be read from (besides "
                      "the scene file's own); repeatable");
  s.unset = "the scene's folder only";
  s.parse = [](RenderOptions& o, const std::string& t) {
    for (const std::string& dir : split(t, '\n')) {
      if (dir.empty()) fail("--asset-dir", "an empty folder name");
      std::error_code ec;
      const std::filesystem::path abs = std::filesystem::absolute(dir, ec);
      o.asset_dirs.push_back(ec ? dir : abs.lexically_normal().string());
    }
  };
  s.check = [](const RenderOptions&) {};
  s.format = [](const RenderOptions& o) {
    std::string t;
    for (const std::string& d : o.asset_dirs) t += (t.empty() ? "" : "\n") + d;
    return t;
  };
  s.reset = [](RenderOptions& o) { o.asset_dirs.clear(); };
  s.accepted = {"/tmp", "assets"};
  s.rejected = {""};
  return s;
}

// --adaptive LIST: a comma list of the parts that follow the error estimates: `radius`
// (ESTIMATOR.md section 13, the default), `photons` (section 14) and `paths` (section 15).
OptionSpec adaptive() {
  OptionSpec s = base("--adaptive", "adaptive", "LIST", "rendering", OptionKind::Image,
                      "comma list of what follows each pixel's error estimates: radius (each "
                      "point's radius between the schedules of alpha 0.9 and --alpha by what its "
                      "photons cost against its other noise, below where its bias dominates), "
                      "photons (emission learnt from where past photons met the "
                      "error), paths (more camera paths where the camera part is a pixel's noise; "
                      "SPPM), or none");
  s.parse = [](RenderOptions& o, const std::string& t) {
    bool radius = false, photons = false, paths = false, none = false;
    for (const std::string& part : split(t, ',')) {
      if (part == "radius")
        radius = true;
      else if (part == "photons")
        photons = true;
      else if (part == "none")
        none = true;
      else if (part == "paths")
        paths = true;
      else
        fail("--adaptive", "'" + part + "' is not one of radius, photons, paths, none");
    }
    if (none && (radius || photons || paths))
      fail("--adaptive", "none cannot be combined with others");
    o.adaptive_radius = radius;
    o.adaptive_photons = photons;
    o.adaptive_paths = paths;
  };
  s.check = [](const RenderOptions&) {};
  s.format = [](const RenderOptions& o) -> std::string {
    std::string parts;
    if (o.adaptive_radius) parts += ",radius";
    if (o.adaptive_photons) parts += ",photons";
    if (o.adaptive_paths) parts += ",paths";
    return parts.empty() ? "none" : parts.substr(1);
  };
  s.reset = [](RenderOptions& o) {
    o.adaptive_radius = RenderOptions{}.adaptive_radius;
    o.adaptive_photons = RenderOptions{}.adaptive_photons;
    o.adaptive_paths = RenderOptions{}.adaptive_paths;
  };
  s.accepted = {"radius",         "none",  "radius,radius",       "photons",
                "photons,radius", "paths", "paths,radius,photons"};
  s.rejected = {"", "radius,none", "none,photons", "none,paths", "radius,", "speed"};
  return s;
}

// --max-memory: bytes, or a number with K, M, G or T (powers of 1024: "1.5G"). Unset, it is
// default_memory_budget() (util/memory.h): 3/4 of the machine's memory.
OptionSpec max_memory() {
  OptionSpec s = base("--max-memory", "max_memory", "BYTES", "running", OptionKind::Run,
                      "memory the render may take (K, M, G, T: powers of 1024); a scene, its "
                      "textures or a render estimated beyond it is refused before it is loaded "
                      "or started");
  s.unset = "3/4 of the machine's memory";
  s.range = "[1M, 1024T]";
  const std::string bad = "must be a size from 1M to 1024T, e.g. 512M or 16G";
  s.parse = [=](RenderOptions& o, const std::string& t) {
    const std::string units = "KMGT";
    const size_t u = t.empty() ? std::string::npos : units.find(char(std::toupper(t.back())));
    const std::string number = u == std::string::npos ? t : t.substr(0, t.size() - 1);
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), v);
    if (number.empty() || ec != std::errc() || ptr != number.data() + number.size())
      fail("--max-memory", "'" + t + "' is not a size (e.g. 512M, 16G)");
    if (u != std::string::npos) v = std::ldexp(v, 10 * int(u + 1));
    if (!(v >= 1048576.0 && v <= std::ldexp(1.0, 50))) fail("--max-memory", bad);
    o.max_memory = uint64_t(v);
  };
  s.check = [=](const RenderOptions& o) {
    if (o.max_memory &&
        !(*o.max_memory >= (uint64_t(1) << 20) && *o.max_memory <= (uint64_t(1) << 50)))
      fail("--max-memory", bad);
  };
  s.format = [](const RenderOptions& o) -> std::string {
    if (!o.max_memory) return "";
    uint64_t v = *o.max_memory;
    const char* units = "KMGT";
    int u = -1;
    while (u < 3 && v % 1024 == 0) v /= 1024, ++u;
    return std::to_string(v) + (u >= 0 ? std::string(1, units[u]) : "");
  };
  s.reset = [](RenderOptions& o) { o.max_memory.reset(); };
  s.accepted = {"1M", "1048576", "1.5G", "16g", "1024T"};
  s.rejected = {"", "0", "1048575", "1025T", "G", "12X", "-1G"};
  return s;
}

}  // namespace pb::option_lists
