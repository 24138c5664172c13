// photonbound command-line entry point. The only catch-all: maps failures to exit codes
// (0 done, 1 runtime failure or bad input file, 2 bad usage).
#include "render/camera_paths.h"
#include "estimator/channels.h"
#include "app/checkpoint.h"
#include "app/checkpoint_writer.h"
#include "app/compare.h"
#include "app/driver.h"
#include "util/file_io.h"
#include "gltf/gltf_loader.h"
#include "io/image_io.h"
#include "options/options.h"
#include "util/parallel.h"
#include "app/progress.h"
#include "render/renderer.h"
#include "render/scene_setup.h"

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace {

std::atomic<bool> g_stop{false};

// --radius above this fraction of the scene size draws a warning (render()).
constexpr double kRadiusWarnFraction = 0.05;
// The share of the view that back-face culling leaves out above which the render notes it.
constexpr double kCulledNoteShare = 0.01;

// First Ctrl-C (or SIGTERM): finish the pass and write the image. Second: leave at once.
extern "C" void on_signal(int sig) {
  if (g_stop.exchange(true)) _exit(128 + sig);
}

// Renders `options`; with `saved`, continues that render (already checked to match).
// What the stop line reports: the quantity the stop rule tests, then the mean bound.
std::string stop_figures(const pb::RenderOptions& o, const pb::FilmSummary& s) {
  std::ostringstream out;
  const double tested = pb::tested_quantity(o, s);  // what the progress line shows, too
  if (o.stop_rule != pb::StopRule::MeanBound && std::isfinite(tested))
    out << pb::tested_name(o) << " <= " << tested << " at " << pb::number_text(100.0 * o.confidence)
        << "%, ";
  out << "mean bound " << s.mean_bound;
  // The mean is over the known pixels: say how many it leaves out (+inf, not small).
  if (s.unknown_pixels > 0 && std::isfinite(s.mean_bound))
    out << " over the known pixels, " << s.unknown_pixels << " unknown";
  return out.str();
}

int render(const pb::RenderOptions& options, const pb::SavedRender* saved) {
  // Installed first: a Ctrl-C while the scene loads still ends with an image and a state.
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  pb::check_writable(options.output);  // fail before hours of rendering, not after
  const bool keep_state = options.checkpoint_every || !options.state_path.empty();
  const std::string state_path = pb::state_path_for(options);
  pb::Scene scene = pb::load_gltf(options.scene);
  for (const std::string& w : scene.warnings)
    std::cerr << "photonbound: warning: " << options.scene << ": " << w << "\n";
  for (const std::string& n : pb::complete_scene(scene, options))
    std::cerr << "photonbound: note: " << n << "\n";
  const uint64_t scene_hash = scene.content_hash;
  if (saved) {
    const std::vector<std::string> diff = pb::differences(*saved, options, scene_hash);
    if (!diff.empty()) {
      std::string msg = options.resume_from + ": cannot continue this render: ";
      for (size_t k = 0; k < diff.size(); ++k) msg += (k ? "; " : "") + diff[k];
      throw pb::StateError(msg);
    }
  }

  pb::ExrImage reference;
  if (!options.reference_path.empty()) reference = pb::read_exr(options.reference_path);
  std::ofstream log_file;
  if (!options.log_path.empty()) {
    log_file.open(options.log_path, std::ios::trunc);
    if (!log_file) throw std::runtime_error(options.log_path + ": cannot write the log");
  }

  // ESTIMATOR.md section 8: with error estimation the accumulated Laplacian converges only for
  // alpha > 2/3, so the bias part of the bound is unreliable below it.
  if (options.alpha <= 2.0 / 3.0)
    std::cerr << "photonbound: warning: --alpha " << options.alpha
              << " is at or below 2/3: the Laplacian (bias) estimate does not converge and the "
                 "error bounds are unreliable\n";
  // The default is silent where following does not apply; a chosen value is not.
  if (options.follow_roughness > 0.0 && options.follow_roughness != pb::kDefaultFollowRoughness &&
      (options.method == pb::Method::PPM || options.direct != pb::DirectMode::NextEvent))
    std::cerr << "photonbound: warning: --follow-roughness does nothing here: it needs "
                 "--method sppm with next-event direct light\n";
  pb::ThreadLimit threads(options.threads);
  pb::Renderer renderer(std::move(scene), options);
  if (saved) renderer.restore(saved->render);
  // PPM's points are fixed, so it cannot follow rough glass or diffuse transmission through a
  // surface (bsdf.h BsdfParams::follows_transmission).
  if (const std::string glass = renderer.world().followed_transmission_names();
      !glass.empty() && options.method == pb::Method::PPM)
    std::cerr << "photonbound: warning: " << options.scene << ": " << glass
              << ": rough and diffuse transmission are rendered by --method ppm as smooth glass "
                 "and as diffuse reflection (its fixed points cannot follow a path through a "
                 "surface); --method sppm renders them\n";
  // Which materials the mirror threshold turns into perfect mirrors (a choice, not a flaw).
  if (const std::string note = renderer.world().mirror_note();
      !note.empty() && options.progress != pb::ProgressMode::Never)
    std::cerr << "photonbound: note: " << options.scene << ": " << note << "\n";
  // glTF's back-face culling (World::camera_hit) can leave out much of a view: say so, since a
  // renderer that draws every face (a path tracer ignoring doubleSided) shows another picture.
  if (const double culled = pb::culled_view_share(renderer.world(), renderer.camera());
      culled >= kCulledNoteShare && options.progress != pb::ProgressMode::Never)
    std::cerr << "photonbound: note: " << options.scene << ": " << std::setprecision(3)
              << 100.0 * culled << std::setprecision(6)
              << "% of the view looks through the back of single-sided faces (doubleSided "
                 "false), which glTF culls as its viewers do; a face meant to be seen from "
                 "behind needs doubleSided true\n";
  // An environment outside a closed shell around the camera lights nothing it sees: a sky box
  // or dome drawn for glTF viewers (which light it by the environment, without shadows) is
  // opaque here. Said before the render, which would come out black.
  if (const pb::Scene& sc = renderer.world().scene(); sc.environment)
    if (const auto shell = renderer.world().camera_enclosure(renderer.camera().origin())) {
      std::string outer;
      for (const auto& [mesh, share] : shell->outermost) {
        std::ostringstream item;
        item << "'" << mesh << "' in " << std::setprecision(3) << 100.0 * share << "%";
        outer += (outer.empty() ? " (outermost: mesh " : ", ") + item.str();
      }
      if (!outer.empty()) outer += " of the directions)";
      std::cerr << "photonbound: warning: " << options.scene
                << ": every ray from the camera meets a surface before the environment" << outer
                << ", so " << sc.environment->source
                << " cannot light what the camera sees; a sky box or dome made for viewers is "
                   "opaque to light here: remove it from the file, or light the scene inside it\n";
    }
  // The bias term models the radiance as smooth (second order) within the radius. A radius of
  // the scene's size breaks that (the extremes suite measured a bound of 0.128 against an error
  // of ~1 at R = scene size), so say so rather than report a bound that cannot be trusted.
  if (renderer.boundary().truncated())
    std::cerr << "photonbound: warning: " << options.scene
              << ": too many boundary segments within the radius for the boundary correction "
                 "(ESTIMATOR.md section 11); every disc counts as whole, so bounds along edges "
                 "may be too small (a higher --resolution or a smaller --radius avoids this)\n";
  if (options.radius && *options.radius > kRadiusWarnFraction * renderer.world().scene_size())
    std::cerr << "photonbound: warning: --radius " << *options.radius << " is "
              << std::setprecision(3) << 100.0 * *options.radius / renderer.world().scene_size()
              << std::setprecision(6)
              << "% of the scene size: the bias estimate assumes the radiance is smooth within "
                 "the radius, so the error bounds may be far too small until the radii shrink\n";
  if (!options.reference_path.empty() &&
      (reference.width != renderer.eye().width || reference.height != renderer.eye().height))
    throw pb::ImageError(options.reference_path + " is " + std::to_string(reference.width) + "x" +
                         std::to_string(reference.height) + " but the render is " +
                         std::to_string(renderer.eye().width) + "x" +
                         std::to_string(renderer.eye().height));

  // A checkpoint is the image and the state, each written atomically; the state goes last, so
  // a state file never refers to passes the image does not show.
  const bool show = options.progress == pb::ProgressMode::Always ||
                    (options.progress == pb::ProgressMode::Auto && isatty(STDERR_FILENO));
  std::vector<pb::PassObserver*> observers;
  pb::ProgressPrinter progress(std::cerr);
  if (show) observers.push_back(&progress);
  pb::PassLogger logger(log_file, options.reference_path.empty() ? nullptr : &reference);
  if (log_file.is_open()) observers.push_back(&logger);
  pb::CheckpointWriter checkpoints(
      options.checkpoint_every.value_or(0.0), options, scene_hash, [&](const pb::SavedRender& s) {
        // On the background thread, from the snapshot (CheckpointWriter).
        pb::write_exr(options.output, renderer.image({s.schedule.seconds, ""}, s.render),
                      pb::ExrCompression::None);
        pb::save_state(state_path, s);
      });
  if (options.checkpoint_every) observers.push_back(&checkpoints);

  if (show)
    std::cerr << "photonbound: "
              << (options.method == pb::Method::PPM
                      ? std::to_string(renderer.eye().points.size()) + " measurement points"
                      : std::to_string(renderer.states().size()) + " pixels (SPPM)")
              << ", " << threads.threads() << (threads.threads() == 1 ? " thread" : " threads")
              << (saved ? ", resumed" : "") << "\n";
  pb::Driver driver(renderer, saved ? saved->schedule : pb::DriverState{});
  const pb::RenderReport report = driver.run(&g_stop, observers);
  // Ctrl-C keeps the work: the state is written then too.
  const pb::ExrImage image = renderer.image(report.run());
  pb::write_exr(options.output, image);
  if (const auto dark = pb::dark_image_warning(image, renderer.world().scene()))
    std::cerr << "photonbound: warning: " << options.scene << ": " << *dark << "\n";
  if (report.summary.model_refuted)
    std::cerr << "photonbound: warning: " << options.scene
              << ": every error bound with a photon part is unknown: the bias model fails at this "
                 "radius (in "
              << std::setprecision(3) << 100.0 * report.summary.slope_disagreement
              << "% of the points' channels the samples' drift with the radius disagrees with the "
                 "Laplacian, in "
              << 100.0 * report.summary.scale_disagreement << std::setprecision(6)
              << "% of the points the kernel at half the radius does); start with a smaller "
                 "--radius\n";
  if (keep_state || report.stop == pb::StopReason::Interrupted)
    pb::save_state(state_path, {options, scene_hash, renderer.snapshot(), driver.state()});
  if (options.progress != pb::ProgressMode::Never)
    std::cerr << "photonbound: stopped (" << pb::stop_text(report.stop) << ") after "
              << report.work.passes << " passes, " << report.seconds << " s; "
              << stop_figures(options, report.summary) << "; wrote " << options.output << "\n";
  return 0;
}

int render(const pb::RenderOptions& options) {
  if (options.resume_from.empty()) return render(options, nullptr);
  const pb::SavedRender saved = pb::load_state(options.resume_from);
  return render(options, &saved);
}

int resume(const pb::ResumeOptions& r) {
  const pb::SavedRender saved = pb::load_state(r.state);
  return render(pb::resumed_options(saved.options, r), &saved);
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
  const int r = in.channel_index(pb::channel_name(pb::Channel::Radiance, 0));
  const int g = in.channel_index(pb::channel_name(pb::Channel::Radiance, 1));
  const int b = in.channel_index(pb::channel_name(pb::Channel::Radiance, 2));
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
      case pb::Command::Kind::HelpTable:
        std::cout << pb::markdown_option_table();
        return 0;
      case pb::Command::Kind::Version:
        std::cout << "photonbound " << PHOTONBOUND_VERSION << "\n";
        return 0;
      case pb::Command::Kind::Render:
        return render(cmd.render);
      case pb::Command::Kind::Resume:
        return resume(cmd.resume);
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
