#include "io/jpeg_header.h"

// jpeglib.h needs size_t and FILE declared first.
#include <cstdio>
// clang-format off
#include <jpeglib.h>
// clang-format on

#include <algorithm>
#include <csetjmp>

#include "io/image_io.h"
#include "util/memory.h"

namespace pb {

namespace {

// libjpeg reports a fatal error through error_exit, which by default ends the process: this
// one jumps back to read_header. Warnings are not printed.
struct ErrorJump {
  jpeg_error_mgr manager;
  std::jmp_buf back;
};
[[noreturn]] void jump_back(j_common_ptr info) {
  std::longjmp(reinterpret_cast<ErrorJump*>(info->err)->back, 1);
}
void keep_quiet(j_common_ptr) {}

struct Frame {
  uint64_t width = 0, height = 0;
  bool whole_buffer = false;  // libjpeg will hold every coefficient
  uint64_t coefficient_bytes = 0;
};

// jpeg_read_header over the bytes; false when libjpeg refuses them. No object with a
// destructor lives between setjmp and a longjmp here (libjpeg's example.c pattern).
bool read_header(const unsigned char* data, size_t size, Frame& frame) {
  jpeg_decompress_struct info;
  ErrorJump error;
  info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = jump_back;
  error.manager.output_message = keep_quiet;
  if (setjmp(error.back)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, data, static_cast<unsigned long>(size));
  if (jpeg_read_header(&info, TRUE) != JPEG_HEADER_OK) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  frame.width = info.image_width;
  frame.height = info.image_height;
  frame.whole_buffer = jpeg_has_multiple_scans(&info);
  // jdcoefct.c jinit_d_coef_controller: each component's blocks rounded up to whole sampling
  // factors, a JBLOCK (64 JCOEFs) each.
  for (int c = 0; c < info.num_components; ++c) {
    const jpeg_component_info& comp = info.comp_info[c];
    const uint64_t h = uint64_t(std::max(comp.h_samp_factor, 1));
    const uint64_t v = uint64_t(std::max(comp.v_samp_factor, 1));
    const uint64_t across = (uint64_t(comp.width_in_blocks) + h - 1) / h * h;
    const uint64_t down = (uint64_t(comp.height_in_blocks) + v - 1) / v * v;
    frame.coefficient_bytes += across * down * sizeof(JBLOCK);
  }
  jpeg_destroy_decompress(&info);
  return true;
}

}  // namespace

void check_jpeg(const unsigned char* data, size_t size, bool truncated, const std::string& name,
                uint64_t max_texels, uint64_t max_bytes) {
  Frame frame;
  if (!read_header(data, size, frame)) {
    if (truncated)
      throw ImageError(name + ": the JPEG's markers before its first scan pass " +
                       bytes_text(size) + ": a corrupt or hostile file");
    return;
  }
  const std::string claim = std::to_string(frame.width) + "x" + std::to_string(frame.height);
  if (frame.width * frame.height > max_texels)
    throw ImageError(name + ": the JPEG's frame header claims " + claim + ", over the " +
                     std::to_string(max_texels) + " texels this read allows");
  // A decoder's own buffer, like an EXR chunk's, may take at least 256 MiB (a 2^28-texel 4:2:0
  // image holds 768 MiB; the texels are checked apart, against the budget itself), so that a
  // small budget does not refuse a small image for it.
  const uint64_t allowed = std::max(max_bytes, uint64_t(256) << 20);
  if (frame.whole_buffer && frame.coefficient_bytes > allowed)
    throw ImageTooLarge(name + ": the image is a " + claim + " JPEG whose decoding holds " +
                            bytes_text(frame.coefficient_bytes) + " of coefficients, over the " +
                            bytes_text(allowed) + " this read may take",
                        frame.coefficient_bytes);
}

}  // namespace pb
