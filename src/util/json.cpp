#include "util/json.h"

#include <cmath>
#include <cstdio>

namespace pb {

void JsonObject::key(std::string_view k) {
  if (text_.size() > 1) text_ += ", ";
  text_ += '"';
  text_ += k;
  text_ += "\": ";
}

JsonObject& JsonObject::add(std::string_view k, double v) {
  key(k);
  if (!std::isfinite(v)) {
    text_ += "null";
    return *this;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  text_ += buf;
  return *this;
}

JsonObject& JsonObject::add(std::string_view k, uint64_t v) {
  key(k);
  text_ += std::to_string(v);
  return *this;
}

JsonObject& JsonObject::add(std::string_view k, std::string_view v) {
  key(k);
  text_ += '"';
  for (const char c : v) {
    if (c == '"' || c == '\\') {
      text_ += '\\';
      text_ += c;
    } else if ((unsigned char)c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      text_ += buf;
    } else {
      text_ += c;
    }
  }
  text_ += '"';
  return *this;
}

}  // namespace pb
