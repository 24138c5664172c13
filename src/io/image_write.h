// The atomic write every image output of src/io goes through (exr_write.cpp).
#pragma once

#include <functional>
#include <string>

namespace pb {

// `write` fills the temporary file write_atomically (util/file_io.h) names (it keeps the
// extension); its errors and write_atomically's become one ImageError naming `path`.
void write_image(const std::string& path, const std::function<void(const std::string&)>& write);

}  // namespace pb
