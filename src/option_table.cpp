// The option table: every render option once, with its flag, member, range, default, help and
// kind (options.h). Adding an option means a row here, a member in RenderOptions and the code
// that uses it; parsing, validation, --help, metadata, the state file and resume follow.
#include "photonbound/options.h"

#include <charconv>
#include <cmath>
#include <limits>

namespace pb {

namespace {

[[noreturn]] void fail(std::string_view flag, const std::string& what) {
  throw UsageError(std::string(flag) + ": " + what);
}

// A closed or open interval of doubles, with the text README and --help show.
struct RealRange {
  double lo, hi;
  bool lo_open, hi_open;
  std::string unit;     // " seconds" appended to the message
  std::string message;  // replaces "must be in <range><unit>" when set
  std::string text() const {
    auto n = [](double v) {
      if (std::isinf(v)) return std::string("inf");
      const double e = std::log10(v);
      if (v >= 1e6 && e == std::floor(e)) return "1e" + std::to_string(int(e));  // "1e9"
      return number_text(v);
    };
    return std::string(lo_open ? "(" : "[") + n(lo) + ", " + n(hi) + (hi_open ? ")" : "]");
  }
  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi) && std::isfinite(v);
  }
  void check(std::string_view flag, double v) const {
    if (!contains(v)) fail(flag, message.empty() ? "must be in " + text() + unit : message);
  }
};

// Integers: [lo, hi]; text with powers of ten where they read better ("1e12").
struct IntRange {
  uint64_t lo, hi;
  std::string text() const {
    auto n = [](uint64_t v) {
      if (v == UINT64_MAX) return std::string("2^64-1");
      int e = 0;
      uint64_t m = v;
      while (m >= 10 && m % 10 == 0) m /= 10, ++e;
      return e >= 6 && m == 1 ? "1e" + std::to_string(e) : std::to_string(v);
    };
    return "[" + n(lo) + ", " + n(hi) + "]";
  }
  void check(std::string_view flag, long double v) const {
    if (!(v >= (long double)lo && v <= (long double)hi)) fail(flag, "must be in " + text());
  }
};

double parse_real(std::string_view flag, const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end) fail(flag, "'" + text + "' is not a number");
  if (!std::isfinite(v)) fail(flag, "'" + text + "' is not a finite number");
  return v;
}

// A whole number, possibly negative or beyond 64 bits (then out of range, not malformed).
long double parse_integer(std::string_view flag, const std::string& text) {
  const bool negative = !text.empty() && text[0] == '-';
  const std::string digits = negative ? text.substr(1) : text;
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos)
    fail(flag, "'" + text + "' is not a whole number");
  uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  (void)ptr;
  const long double x = ec == std::errc::result_out_of_range ? 1e30L : (long double)v;
  return negative ? -x : x;
}

// The value type of a plain or optional member.
template <class M>
struct ValueType {
  using type = M;
};
template <class M>
struct ValueType<std::optional<M>> {
  using type = M;
};

using Parse = std::function<void(RenderOptions&, const std::string&)>;
using Format = std::function<std::string(const RenderOptions&)>;
using Check = std::function<void(const RenderOptions&)>;

OptionSpec base(std::string_view flag, std::string_view key, std::string_view metavar,
                std::string_view group, OptionKind kind, std::string_view help) {
  OptionSpec s;
  s.flag = flag;
  s.key = key;
  s.metavar = metavar;
  s.group = group;
  s.kind = kind;
  s.help = help;
  return s;
}

// A real member (plain or optional).
template <class Member>
OptionSpec real(OptionSpec s, Member RenderOptions::*m, RealRange r, std::string unset = "") {
  s.reset = [=](RenderOptions& o) { o.*m = RenderOptions{}.*m; };
  s.range = r.text();
  s.unset = std::move(unset);
  const std::string_view flag = s.flag;
  s.parse = [=](RenderOptions& o, const std::string& t) {
    const double v = parse_real(flag, t);
    r.check(flag, v);
    o.*m = v;
  };
  s.check = [=](const RenderOptions& o) {
    if constexpr (std::is_same_v<Member, double>)
      r.check(flag, o.*m);
    else if ((o.*m).has_value())
      r.check(flag, *(o.*m));
  };
  s.format = [=](const RenderOptions& o) -> std::string {
    if constexpr (std::is_same_v<Member, double>)
      return number_text(o.*m);
    else
      return (o.*m) ? number_text(*(o.*m)) : "";
  };
  const double lo_in = r.lo_open ? std::nextafter(r.lo, INFINITY) : r.lo;
  s.accepted = {number_text(lo_in)};
  s.rejected = {number_text(r.lo_open ? r.lo : std::nextafter(r.lo, -INFINITY))};
  if (std::isfinite(r.hi)) {
    s.accepted.push_back(number_text(r.hi_open ? std::nextafter(r.hi, -INFINITY) : r.hi));
    s.rejected.push_back(number_text(r.hi_open ? r.hi : std::nextafter(r.hi, INFINITY)));
  }
  return s;
}

// An integer member (plain or optional) of type T.
template <class Member>
OptionSpec integer(OptionSpec s, Member RenderOptions::*m, IntRange r, std::string unset = "") {
  s.reset = [=](RenderOptions& o) { o.*m = RenderOptions{}.*m; };
  s.range = r.text();
  s.unset = std::move(unset);
  const std::string_view flag = s.flag;
  using T = typename ValueType<Member>::type;
  s.parse = [=](RenderOptions& o, const std::string& t) {
    const long double v = parse_integer(flag, t);
    r.check(flag, v);
    o.*m = T(v);
  };
  s.check = [=](const RenderOptions& o) {
    if constexpr (std::is_integral_v<Member>)
      r.check(flag, (long double)(o.*m));
    else if ((o.*m).has_value())
      r.check(flag, (long double)(*(o.*m)));
  };
  s.format = [=](const RenderOptions& o) -> std::string {
    if constexpr (std::is_integral_v<Member>)
      return std::to_string(o.*m);
    else
      return (o.*m) ? std::to_string(*(o.*m)) : "";
  };
  auto text = [](long double v) { return std::to_string((long long)v); };
  s.accepted = {std::to_string(r.lo), std::to_string(r.hi)};
  s.rejected.push_back(text((long double)r.lo - 1));
  s.rejected.push_back(r.hi < UINT64_MAX ? std::to_string(r.hi + 1) : "18446744073709551616");
  return s;
}

// An enumeration member: the texts in order.
template <class E>
OptionSpec choice(OptionSpec s, E RenderOptions::*m, std::vector<std::pair<std::string, E>> names) {
  s.reset = [=](RenderOptions& o) { o.*m = RenderOptions{}.*m; };
  std::string list;
  for (const auto& [n, v] : names) list += (list.empty() ? "" : ", ") + n;
  const std::string_view flag = s.flag;
  s.parse = [=](RenderOptions& o, const std::string& t) {
    for (const auto& [n, v] : names)
      if (n == t) {
        o.*m = v;
        return;
      }
    fail(flag, "'" + t + "' is not one of " + list);
  };
  s.check = [](const RenderOptions&) {};
  s.format = [=](const RenderOptions& o) {
    for (const auto& [n, v] : names)
      if (o.*m == v) return n;
    return names.front().first;
  };
  for (const auto& [n, v] : names) s.accepted.push_back(n);
  s.rejected = {"", names.front().first + "x"};
  return s;
}

// A path or name; empty means unset.
OptionSpec text(OptionSpec s, std::string RenderOptions::*m, std::string unset = "") {
  s.reset = [=](RenderOptions& o) { o.*m = RenderOptions{}.*m; };
  s.unset = std::move(unset);
  const std::string_view flag = s.flag;
  const std::string what = s.metavar == "NAME" ? "the name is empty" : "the path is empty";
  s.parse = [=](RenderOptions& o, const std::string& t) {
    if (t.empty()) fail(flag, what);
    o.*m = t;
  };
  s.check = [](const RenderOptions&) {};
  s.format = [=](const RenderOptions& o) { return o.*m; };
  s.accepted = {"x"};
  s.rejected = {""};
  return s;
}

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
  t.push_back(text(base("-o", "output", "OUT.exr", run, K::Run, "the EXR to write"),
                   &RenderOptions::output));
  t.push_back(integer(base("--passes", "passes", "N", stop, K::Stop, "passes to run"),
                      &RenderOptions::passes, {1, 1000000000000ULL}, "none"));
  t.push_back(real(base("--time", "time", "S", stop, K::Stop,
                        "wall-clock budget in seconds (steady clock), checked after each pass"),
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
                        "PPM radius reduction; 1 never shrinks the radius"),
                   &RenderOptions::alpha, {0, 1, true, false, "", ""}));
  t.push_back(real(
      base("--radius", "radius", "R", render, K::Image, "initial search radius in scene units"),
      &RenderOptions::radius, {0, 1e30, true, true, "", ""}, "4 pixel footprints"));
  t.push_back(integer(base("--max-depth", "max_depth", "D", render, K::Image,
                           "specular bounces a camera path may take"),
                      &RenderOptions::max_depth, {0, 32}));
  t.push_back(resolution());
  t.push_back(text(base("--camera", "camera", "NAME", render, K::Image,
                        "glTF camera name, \"camera N\" when unnamed"),
                   &RenderOptions::camera, "first"));
  t.push_back(integer(base("--threads", "threads", "T", run, K::Run,
                           "worker threads, 0 = all; the image does not depend on it"),
                      &RenderOptions::threads, {0, 1024}));
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
                        "per-pass JSON log (\"Measuring the trade\")"),
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

std::string number_text(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace pb
