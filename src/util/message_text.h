// Message text: whatever bytes a file, a parser or a library quotes, messages stay one line of
// valid, printable text.
#pragma once

#include <string>
#include <vector>

namespace pb {

// Trimmed non-empty lines; control characters and invalid UTF-8 become '?'.
std::vector<std::string> nonempty_lines(const std::string& s);

// Folds the lines of s into one: "a; b".
std::string one_line(const std::string& s);

}  // namespace pb
