// One JSON object on one line, for the per-pass log and `compare --json`: numbers with enough
// digits to read back, strings escaped.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pb {

class JsonObject {
 public:
  JsonObject& add(std::string_view key, double value);  // non-finite values become null
  JsonObject& add(std::string_view key, uint64_t value);
  JsonObject& add(std::string_view key, int value) { return add(key, uint64_t(value)); }
  JsonObject& add(std::string_view key, std::string_view value);
  std::string str() const { return text_ + "}"; }  // without a newline

 private:
  void key(std::string_view k);
  std::string text_ = "{";
};

}  // namespace pb
