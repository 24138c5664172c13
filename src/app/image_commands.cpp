#include "app/image_commands.h"

#include "app/compare.h"
#include "app/outputs.h"
#include "estimator/channels.h"
#include "io/image_io.h"
#include "util/file_io.h"
#include "util/memory.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace pb {

namespace {

// compare and preview read whole images: each within a share of the machine's memory.
ReadLimit machine_share(int images) {
  return {default_memory_budget() / uint64_t(images),
          images == 1 ? "3/4 of the machine's memory" : "half of 3/4 of the machine's memory"};
}

}  // namespace

int compare_command(const CompareOptions& o) {
  const CompareResult r =
      compare_images(read_exr(o.render, machine_share(2)), read_exr(o.reference, machine_share(2)),
                     o.render, o.reference);
  std::cout << (o.json ? to_json(r) : to_text(r));
  return 0;
}

// sRGB-encoded PNG of the radiance channels, for quick looks and the README.
int preview_command(const PreviewOptions& o) {
  check_distinct({{"-o", o.output}}, {{"the input image", o.input}});
  check_output_path({"-o", o.output});
  const ExrImage in = read_exr(o.input, machine_share(1));
  const int r = in.channel_index(channel_name(Channel::Radiance, 0));
  const int g = in.channel_index(channel_name(Channel::Radiance, 1));
  const int b = in.channel_index(channel_name(Channel::Radiance, 2));
  if (r < 0 || g < 0 || b < 0) throw ImageError(o.input + ": has no R, G, B channels");
  const double scale = std::exp2(o.exposure);
  const size_t pixels = size_t(in.width) * size_t(in.height), nc = in.channels.size();
  std::vector<unsigned char> rgb(3 * pixels);
  std::vector<float> levels(pixels);
  for (size_t p = 0; p < pixels; ++p) {
    const int src[3] = {r, g, b};
    levels[p] = std::max({in.pixels[p * nc + size_t(r)], in.pixels[p * nc + size_t(g)],
                          in.pixels[p * nc + size_t(b)]});
    for (int c = 0; c < 3; ++c) {
      double v = std::clamp(double(in.pixels[p * nc + size_t(src[c])]) * scale, 0.0, 1.0);
      if (!(v == v)) v = 0.0;
      v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
      rgb[3 * p + size_t(c)] = static_cast<unsigned char>(std::lround(255.0 * v));
    }
  }
  write_png(o.output, in.width, in.height, rgb);
  if (const auto w = exposure_warning(std::move(levels), o.exposure, o.input))
    std::cerr << *w << "\n";
  return 0;
}

}  // namespace pb
