// photonbound command-line entry point. The only catch-all: maps failures to exit codes
// (0 done, 1 runtime failure or bad input file, 2 bad usage).
#include "photonbound/compare.h"
#include "photonbound/gltf_loader.h"
#include "photonbound/image_io.h"
#include "photonbound/options.h"
#include "photonbound/parallel.h"
#include "photonbound/renderer.h"

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>

namespace {

std::atomic<bool> g_stop{false};

// First Ctrl-C (or SIGTERM): finish the pass and write the image. Second: leave at once.
extern "C" void on_signal(int sig) {
  if (g_stop.exchange(true)) _exit(128 + sig);
}

int render(const pb::RenderOptions& options) {
  pb::check_writable(options.output);  // fail before hours of rendering, not after
  const pb::Scene scene = pb::load_gltf(options.scene);
  for (const std::string& w : scene.warnings)
    std::cerr << "photonbound: warning: " << options.scene << ": " << w << "\n";

  pb::ThreadLimit threads(options.threads);
  pb::Renderer renderer(scene, options);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  const bool show = options.progress == pb::ProgressMode::Always ||
                    (options.progress == pb::ProgressMode::Auto && isatty(STDERR_FILENO));
  if (show)
    std::cerr << "photonbound: " << renderer.eye().points.size() << " measurement points, "
              << threads.threads() << " threads\n";
  const pb::RenderReport report = renderer.run(&g_stop, show ? &std::cerr : nullptr);
  pb::write_exr(options.output, renderer.image(report));
  if (show || report.stop_reason != "passes")
    std::cerr << "photonbound: stopped (" << report.stop_reason << ") after " << report.passes
              << " passes, " << report.seconds << " s; mean bound " << report.summary.mean_bound
              << "; wrote " << options.output << "\n";
  return 0;
}

int compare(const pb::CompareOptions& o) {
  const pb::CompareResult r =
      pb::compare_images(pb::read_exr(o.render), pb::read_exr(o.reference), o.render, o.reference);
  std::cout << (o.json ? pb::to_json(r) : pb::to_text(r));
  return 0;
}

// sRGB-encoded PNG of the radiance channels, for quick looks and the README.
int preview(const pb::PreviewOptions& o) {
  const pb::ExrImage in = pb::read_exr(o.input);
  const int r = in.channel_index("R"), g = in.channel_index("G"), b = in.channel_index("B");
  if (r < 0 || g < 0 || b < 0) throw pb::ImageError(o.input + ": has no R, G, B channels");
  const double scale = std::exp2(o.exposure);
  const size_t pixels = size_t(in.width) * size_t(in.height), nc = in.channels.size();
  std::vector<unsigned char> rgb(3 * pixels);
  for (size_t p = 0; p < pixels; ++p) {
    const int src[3] = {r, g, b};
    for (int c = 0; c < 3; ++c) {
      double v = std::clamp(double(in.pixels[p * nc + size_t(src[c])]) * scale, 0.0, 1.0);
      if (!(v == v)) v = 0.0;
      v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
      rgb[3 * p + size_t(c)] = static_cast<unsigned char>(std::lround(255.0 * v));
    }
  }
  pb::write_png(o.output, in.width, in.height, rgb);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const pb::Command cmd = pb::parse_command_line(argc, argv);
    switch (cmd.kind) {
      case pb::Command::Kind::Help:
        std::cout << pb::usage_text();
        return 0;
      case pb::Command::Kind::Version:
        std::cout << "photonbound " << PHOTONBOUND_VERSION << "\n";
        return 0;
      case pb::Command::Kind::Render:
        return render(cmd.render);
      case pb::Command::Kind::Compare:
        return compare(cmd.compare);
      case pb::Command::Kind::Preview:
        return preview(cmd.preview);
    }
  } catch (const pb::UsageError& e) {
    std::cerr << "photonbound: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "photonbound: error: " << e.what() << "\n";
    return 1;
  }
  return 1;
}
