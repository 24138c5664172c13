// The builders the option table (option_table.cpp) makes its rows with: ranges with the text
// docs/usage.md and --help show, and one builder per kind of member (real, integer, choice, text,
// three numbers). Internal to option_table.cpp.
#pragma once

#include "options/options.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace pb::option_builders {

[[noreturn]] inline void fail(std::string_view flag, const std::string& what) {
  throw UsageError(std::string(flag) + ": " + what);
}

// A closed or open interval of doubles, with the text docs/usage.md and --help show.
struct RealRange {
  double lo, hi;
  bool lo_open, hi_open;
  std::string unit;     // " seconds" appended to the message
  std::string message;  // replaces "must be in <range><unit>" when set
  std::string text() const {
    auto n = [](double v) {
      if (std::isinf(v)) return std::string(v < 0 ? "-inf" : "inf");
      const double e = std::log10(std::fabs(v));
      if (std::fabs(v) >= 1e6 && e == std::floor(e))  // "1e9", "-1e10"
        return (v < 0 ? "-1e" : "1e") + std::to_string(int(e));
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

inline double parse_real(std::string_view flag, const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end) fail(flag, "'" + text + "' is not a number");
  if (!std::isfinite(v)) fail(flag, "'" + text + "' is not a finite number");
  return v;
}

// A whole number, possibly negative or beyond 64 bits (then out of range, not malformed).
inline long double parse_integer(std::string_view flag, const std::string& text) {
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

inline OptionSpec base(std::string_view flag, std::string_view key, std::string_view metavar,
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
inline OptionSpec text(OptionSpec s, std::string RenderOptions::*m, std::string unset = "") {
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

// Splits "a,b,c" at commas into finite numbers; false when a part is not one.
inline bool parse_numbers(const std::string& text, std::vector<double>& out) {
  out.clear();
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? comma : comma - start);
    double v = 0.0;
    const char* end = part.data() + part.size();
    const auto [ptr, ec] = std::from_chars(part.data(), end, v);
    if (part.empty() || ec != std::errc() || ptr != end || !std::isfinite(v)) return false;
    out.push_back(v);
    if (comma == std::string::npos) return true;
    start = comma + 1;
  }
}

inline std::string numbers_text(const double* v, size_t n) {
  std::string s;
  for (size_t k = 0; k < n; ++k) s += (k ? "," : "") + number_text(v[k]);
  return s;
}

// Three numbers "X,Y,Z", each within [-limit, limit]; `nonzero`: not all zero (a direction).
inline OptionSpec triple(OptionSpec s, std::optional<std::array<double, 3>> RenderOptions::*m,
                         double limit, bool nonzero, std::string unset) {
  s.reset = [=](RenderOptions& o) { o.*m = RenderOptions{}.*m; };
  s.unset = std::move(unset);
  const RealRange r{-limit, limit, false, false, "", ""};
  s.range = r.text() + " each";
  const std::string_view flag = s.flag;
  auto check = [=](const std::array<double, 3>& v) {
    for (double x : v)
      if (!r.contains(x)) fail(flag, "each of X, Y and Z must be in " + r.text());
    if (nonzero && v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0) fail(flag, "must not be 0,0,0");
  };
  s.parse = [=](RenderOptions& o, const std::string& t) {
    std::vector<double> v;
    if (!parse_numbers(t, v) || v.size() != 3) fail(flag, "'" + t + "' is not X,Y,Z");
    const std::array<double, 3> a = {v[0], v[1], v[2]};
    check(a);
    o.*m = a;
  };
  s.check = [=](const RenderOptions& o) {
    if ((o.*m).has_value()) check(*(o.*m));
  };
  s.format = [=](const RenderOptions& o) -> std::string {
    return (o.*m) ? numbers_text((o.*m)->data(), 3) : "";
  };
  const std::string lo = number_text(-limit), hi = number_text(limit);
  s.accepted = {"0,1,0", lo + "," + hi + ",0.5"};
  s.rejected = {"1,2", "1,2,3,4", "1,x,3", number_text(std::nextafter(limit, INFINITY)) + ",0,0"};
  if (nonzero) s.rejected.push_back("0,0,0");
  return s;
}

// True when `text` names an environment map: it ends in .exr or .hdr (any case).
inline bool is_map_file(const std::string& text) {
  if (text.size() < 5) return false;
  std::string ext = text.substr(text.size() - 4);
  for (char& c : ext) c = char(std::tolower((unsigned char)c));
  return ext == ".exr" || ext == ".hdr";
}

// --environment: a colour "V" or "R,G,B" (finite, >= 0) or an .exr / .hdr file.
inline OptionSpec environment(OptionSpec s, std::string unset) {
  s.reset = [](RenderOptions& o) { o.environment.clear(); };
  s.unset = std::move(unset);
  const std::string_view flag = s.flag;
  auto check = [=](const std::string& t) {
    if (is_map_file(t)) return;
    std::vector<double> v;
    if (!parse_numbers(t, v) || (v.size() != 1 && v.size() != 3))
      fail(flag, "'" + t + "' is neither a colour (V or R,G,B) nor an .exr or .hdr file");
    for (double x : v)
      if (!(x >= 0.0 && x <= 1e30)) fail(flag, "colour components must be in [0, 1e30]");
  };
  s.parse = [=](RenderOptions& o, const std::string& t) {
    check(t);
    // A map as an absolute path, like the scene in the state: `resume` may run elsewhere.
    std::error_code ec;
    const std::filesystem::path abs = std::filesystem::absolute(t, ec);
    o.environment = is_map_file(t) && !ec ? abs.lexically_normal().string() : t;
  };
  s.check = [=](const RenderOptions& o) {
    if (!o.environment.empty()) check(o.environment);
  };
  s.format = [](const RenderOptions& o) { return o.environment; };
  s.accepted = {"0", "1,0.5,0.25", "sky.hdr", "sky.EXR"};
  s.rejected = {"", "-1", "1,2", "sky.png", "nan", "1,1,1e31"};
  return s;
}

}  // namespace pb::option_builders
