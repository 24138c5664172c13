#include "util/message_text.h"

#include <sstream>

namespace pb {

namespace {

// Length of the valid UTF-8 sequence at s[i], or 0 (overlong forms and surrogates count as
// invalid; a message must stay valid text whatever bytes a name or a parser error quotes).
size_t utf8_length(const std::string& s, size_t i) {
  const auto c = [&](size_t k) { return (unsigned char)s[k]; };
  const unsigned char b = c(i);
  size_t n = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // allowed range of the second byte
  if (b >= 0xc2 && b <= 0xdf)
    n = 2;
  else if (b >= 0xe0 && b <= 0xef)
    n = 3, lo = b == 0xe0 ? 0xa0 : 0x80, hi = b == 0xed ? 0x9f : 0xbf;
  else if (b >= 0xf0 && b <= 0xf4)
    n = 4, lo = b == 0xf0 ? 0x90 : 0x80, hi = b == 0xf4 ? 0x8f : 0xbf;
  else
    return 0;
  if (i + n > s.size() || c(i + 1) < lo || c(i + 1) > hi) return 0;
  for (size_t k = 2; k < n; ++k)
    if (c(i + k) < 0x80 || c(i + k) > 0xbf) return 0;
  return n;
}

// Control characters and invalid UTF-8 become '?'.
std::string printable(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size();) {
    const unsigned char b = (unsigned char)s[i];
    if (b >= 0x20 && b < 0x7f) {
      out += char(b);
      ++i;
    } else if (b == '\t' || b == '\r') {
      out += ' ';
      ++i;
    } else if (const size_t n = b >= 0x80 ? utf8_length(s, i) : 0) {
      out.append(s, i, n);
      i += n;
    } else {
      out += '?';
      ++i;
    }
  }
  return out;
}

}  // namespace

std::vector<std::string> nonempty_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const std::string l = printable(line);
    const size_t b = l.find_first_not_of(" \t\r");
    if (b != std::string::npos) out.push_back(l.substr(b, l.find_last_not_of(" \t\r") - b + 1));
  }
  return out;
}

std::string one_line(const std::string& s) {
  std::string out;
  for (const std::string& l : nonempty_lines(s)) out += (out.empty() ? "" : "; ") + l;
  return out;
}

}  // namespace pb
