// photonbound command-line entry point. The only catch-all: maps failures to exit codes
// (0 done, 1 runtime failure or bad input file, 2 bad usage).
#include "app/checkpoint.h"
#include "app/checkpoint_writer.h"
#include "app/diagnostics.h"
#include "app/driver.h"
#include "app/image_commands.h"
#include "app/outputs.h"
#include "app/progress.h"
#include "dist/mpi_exchange.h"
#include "gltf/gltf_loader.h"
#include "io/image_io.h"
#include "options/options.h"
#include "render/camera_paths.h"
#include "render/render_memory.h"
#include "render/renderer.h"
#include "render/scene_defaults.h"
#include "util/file_io.h"
#include "util/memory.h"
#include "util/parallel.h"

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <new>
#include <optional>
#include <sstream>

namespace {

std::atomic<bool> g_stop{false};
// The MPI session (dist/): one process unless started by mpirun with several ranks.
pb::MpiSession* g_mpi = nullptr;

// "photonbound: error: " or, in a distributed render, which rank failed.
std::string error_prefix() {
  if (!g_mpi || !g_mpi->distributed()) return "photonbound: error: ";
  return "photonbound: error (rank " + std::to_string(g_mpi->rank()) + " of " +
         std::to_string(g_mpi->ranks()) + "): ";
}

// First Ctrl-C (or SIGTERM, SIGHUP, SIGUSR1): discard the pass in progress (Driver::run) and write
// the image and state of the last whole one. Second: leave at once, removing the temporary files
// being written and the lock files first (file_io.h's registry).
extern "C" void on_signal(int sig) {
  if (g_stop.exchange(true)) {
    pb::unlink_registered_files();
    _exit(128 + sig);
  }
}

// The files a render writes: -o, the state (written at the end, at checkpoints, or on Ctrl-C)
// and the log.
std::vector<pb::NamedFile> render_outputs(const pb::RenderOptions& o, const std::string& state) {
  std::vector<pb::NamedFile> out = {{"-o", o.output},
                                    {o.state_path.empty() ? "the state file" : "--state", state}};
  if (!o.log_path.empty()) out.push_back({"--log", o.log_path});
  return out;
}

// Every output (and its lock file) against the inputs named on the command line, before the scene
// loads; each output path checked, then locked for the whole render, and the temporaries a crashed
// render left beside them removed. The state being resumed may be replaced by its own
// continuation (docs/usage.md: `resume c.pbstate -o c.exr` carries on in place): it is read
// whole before anything is written, and the new state is written atomically.
std::vector<std::string> check_render_outputs(const pb::RenderOptions& o,
                                              const std::vector<pb::NamedFile>& outputs) {
  std::vector<pb::NamedFile> inputs = {{"the scene file", o.scene}};
  if (pb::environment_is_map(o.environment))
    inputs.push_back({"the --environment map", o.environment});
  if (!o.reference_path.empty()) inputs.push_back({"the --reference image", o.reference_path});
  // The lock files first: an output naming one is reported by its own flag.
  std::vector<pb::NamedFile> all, not_state;
  for (size_t k = 0; k < outputs.size(); ++k) {
    all.push_back({outputs[k].role + "'s lock file", pb::lock_path(outputs[k].path)});
    if (k != 1) not_state.push_back(outputs[k]);  // outputs[1]: the state
  }
  all.insert(all.end(), outputs.begin(), outputs.end());
  pb::check_distinct(outputs, inputs);
  pb::check_distinct(all, inputs);  // what is left: a lock file that is an input or an output
  if (!o.resume_from.empty())
    pb::check_distinct(not_state, {{"the state being resumed", o.resume_from}});
  std::vector<std::string> paths;
  for (const pb::NamedFile& f : outputs) {
    pb::check_output_path(f);
    paths.push_back(f.path);
  }
  return paths;
}

// After the scene loaded: no output is a file the loader read (an external buffer or image).
void check_scene_files(const std::vector<pb::NamedFile>& outputs, const pb::Scene& scene) {
  std::vector<pb::NamedFile> files;
  for (size_t k = 0; k < scene.files.size(); ++k)
    files.push_back({k == 0 ? "the scene file" : "a file the scene loads", scene.files[k]});
  pb::check_distinct(outputs, files);
}

void print_lines(const std::vector<std::string>& lines) {
  for (const std::string& line : lines) std::cerr << line << "\n";
}

// The scene, completed for rendering (its warnings and notes printed); with `saved`, checked to
// be the scene and options that render was made with.
// `quiet`: a distributed render's other ranks, whose warnings rank 0 has printed.
pb::Scene load_scene(const pb::RenderOptions& options, const pb::SavedRender* saved,
                     bool quiet = false) {
  pb::Scene scene = pb::load_gltf(
      options.scene, pb::LoadPolicy{options.asset_dirs, pb::memory_budget(options),
                                    options.texture_formats == pb::TextureFormats::Any});
  const std::vector<std::string> notes = pb::complete_scene(scene, options);
  if (!quiet) {
    for (const std::string& w : scene.warnings)
      std::cerr << "photonbound: warning: " << options.scene << ": " << w << "\n";
    for (const std::string& n : notes) std::cerr << "photonbound: note: " << n << "\n";
  }
  if (saved) {
    const std::vector<std::string> diff = pb::differences(*saved, options, scene.content_hash);
    if (!diff.empty()) {
      std::string msg = options.resume_from + ": cannot continue this render: ";
      for (size_t k = 0; k < diff.size(); ++k) msg += (k ? "; " : "") + diff[k];
      throw pb::StateError(msg);
    }
  }
  return scene;
}

std::ofstream open_log(const std::string& path) {
  std::ofstream log_file;
  if (!path.empty()) {
    log_file.open(path, std::ios::trunc);
    if (!log_file) throw std::runtime_error(path + ": cannot write the log");
  }
  return log_file;
}

void check_reference_size(const pb::RenderOptions& options, const pb::ExrImage& reference,
                          const pb::Renderer& renderer) {
  if (!options.reference_path.empty() && (reference.width != renderer.camera_pass().width ||
                                          reference.height != renderer.camera_pass().height))
    throw pb::ImageError(options.reference_path + " is " + std::to_string(reference.width) + "x" +
                         std::to_string(reference.height) + " but the render is " +
                         std::to_string(renderer.camera_pass().width) + "x" +
                         std::to_string(renderer.camera_pass().height));
}

// The pass observers: the progress line, the log, and the checkpoints. A checkpoint is the image
// and the state, each written atomically; the state goes last, so a state file never refers to
// passes the image does not show.
struct Observers {
  pb::ProgressPrinter progress{std::cerr};
  pb::PassLogger logger;
  pb::CheckpointWriter checkpoints;
  std::vector<pb::PassObserver*> list;
  Observers(const pb::RenderOptions& options, bool show, std::ofstream& log_file,
            const pb::ExrImage& reference, uint64_t scene_hash, const pb::Renderer& renderer,
            const std::string& state_path)
      : logger(log_file, options.reference_path.empty() ? nullptr : &reference),
        checkpoints(options.checkpoint_every.value_or(0.0), options, scene_hash,
                    [&options, &renderer, &state_path](const pb::SavedRender& s) {
                      // On the background thread, from the snapshot (CheckpointWriter).
                      pb::write_exr(options.output,
                                    renderer.image({s.schedule.seconds, ""}, s.render),
                                    pb::ExrCompression::None);
                      pb::save_state(state_path, s);
                    }) {
    if (show) list.push_back(&progress);
    if (log_file.is_open()) list.push_back(&logger);
    if (options.checkpoint_every) list.push_back(&checkpoints);
  }
};

std::string start_line(const pb::RenderOptions& options, const pb::Renderer& renderer, int threads,
                       bool resumed) {
  const pb::Exchange* exchange = renderer.exchange();
  std::ostringstream line;
  line << "photonbound: "
       << (options.method == pb::Method::PPM
               ? std::to_string(renderer.camera_pass().points.size()) + " visible points"
               : std::to_string(renderer.states().size()) + " pixels (SPPM)")
       << ", " << threads << (threads == 1 ? " thread" : " threads")
       << (exchange ? " on each of " + std::to_string(exchange->ranks()) + " MPI ranks" : "")
       << (resumed ? ", resumed" : "");
  return line.str();
}

// ESTIMATOR.md section 7: the image, the warnings it draws, the state, and the stop line.
void finish_render(const pb::RenderOptions& options, const pb::Renderer& renderer,
                   const pb::RenderReport& report, const pb::DriverState& schedule,
                   uint64_t scene_hash, bool keep_state, const std::string& state_path) {
  // Ctrl-C keeps the work: the state is written then too. The EXR is written from the film's
  // planes (Renderer::image_view), not from an interleaved copy of them.
  std::optional<pb::FilmImage> developed;
  pb::FilmSummary summary = report.summary;
  if (!report.film) summary = renderer.develop(&developed.emplace());
  const pb::ExrView image =
      renderer.image_view(report.run(), report.film ? *report.film : *developed, summary);
  pb::write_exr(options.output, image);
  print_lines(pb::result_diagnostics(options, image, renderer.world().scene(), summary,
                                     report.work.passes));
  if (keep_state || report.stop == pb::StopReason::Interrupted)
    pb::save_state(state_path, {options, scene_hash, renderer.snapshot(), schedule});
  const pb::Exchange* ex = renderer.exchange();
  if (ex && options.progress != pb::ProgressMode::Never && report.work.passes > 0) {
    const double passes = double(report.work.passes);
    std::cerr << "photonbound: " << ex->ranks() << " MPI ranks; per pass, rank 0 received "
              << double(ex->hits.bytes) / passes / 1e6 << " MB of photon hits in "
              << 1e3 * ex->hits.seconds / passes << " ms and "
              << double(ex->states.bytes) / passes / 1e6 << " MB of radii and states in "
              << 1e3 * ex->states.seconds / passes << " ms (waits for slower ranks included)\n";
  }
  if (options.progress != pb::ProgressMode::Never)
    std::cerr << "photonbound: stopped (" << pb::stop_text(report.stop) << ") after "
              << report.work.passes << " passes, " << report.seconds << " s; "
              << pb::stop_figures(options, report.summary) << "; wrote " << options.output << "\n";
}

// A distributed render's rank other than 0: the same scene and state, its share of every pass
// as rank 0 commands; no output, no lock, no line printed (rank 0 does all of that).
int follow(const pb::RenderOptions& options, const pb::SavedRender* saved, pb::Exchange& exchange) {
  pb::check_render_memory(options, nullptr);
  pb::Scene scene = load_scene(options, saved, true);
  pb::check_render_memory(options, &scene);
  pb::ThreadLimit threads(options.threads);
  pb::Renderer renderer(std::move(scene), options);
  if (saved) renderer.restore(saved->render);
  renderer.distribute(&exchange);
  renderer.follow();
  return 0;
}

// Renders `options`; with `saved`, continues that render (already checked to match).
int render(const pb::RenderOptions& options, const pb::SavedRender* saved) {
  const std::unique_ptr<pb::Exchange> exchange = g_mpi->exchange();
  // mpirun forwards SIGUSR1 to every rank (not Ctrl-C, on which it kills them all after 1 s):
  // rank 0 takes it as a Ctrl-C, the others leave the decision to rank 0.
  if (exchange && exchange->rank() != 0) {
    std::signal(SIGUSR1, SIG_IGN);
    return follow(options, saved, *exchange);
  }
  // Installed first: a Ctrl-C while the scene loads still ends with an image and a state.
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGHUP, on_signal);  // a closed terminal: the same, not a death with nothing written
  std::signal(SIGUSR1, on_signal);
  const bool keep_state = options.checkpoint_every || !options.state_path.empty();
  const std::string state_path = pb::state_path_for(options);
  // Fail before hours of rendering, not after; and never write over an input.
  const std::vector<pb::NamedFile> outputs = render_outputs(options, state_path);
  const pb::OutputLock lock(check_render_outputs(options, outputs));
  pb::remove_stale_temporaries(options.output);
  pb::remove_stale_temporaries(state_path);
  pb::check_render_memory(options, nullptr);  // an explicit --resolution, before the scene loads
  pb::Scene scene = load_scene(options, saved);
  check_scene_files(outputs, scene);
  pb::check_render_memory(options, &scene);
  const uint64_t scene_hash = scene.content_hash;
  pb::ExrImage reference;
  if (!options.reference_path.empty())
    reference = pb::read_exr(options.reference_path, {pb::memory_budget(options)});
  std::ofstream log_file = open_log(options.log_path);
  print_lines(pb::option_diagnostics(options));
  pb::ThreadLimit threads(options.threads);
  pb::Renderer renderer(std::move(scene), options);
  if (saved) renderer.restore(saved->render);
  renderer.distribute(exchange.get());
  print_lines(pb::preflight_diagnostics(options, renderer));
  check_reference_size(options, reference, renderer);

  const bool show = options.progress == pb::ProgressMode::Always ||
                    (options.progress == pb::ProgressMode::Auto && isatty(STDERR_FILENO));
  Observers observers(options, show, log_file, reference, scene_hash, renderer, state_path);
  if (show) std::cerr << start_line(options, renderer, threads.threads(), saved) << "\n";
  pb::Driver driver(renderer, saved ? saved->schedule : pb::DriverState{});
  const pb::RenderReport report = driver.run(&g_stop, observers.list);
  finish_render(options, renderer, report, driver.state(), scene_hash, keep_state, state_path);
  renderer.release_followers();
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

int run(int argc, char** argv) {
  try {
    const pb::Command cmd = pb::parse_command_line(argc, argv);
    // Under mpirun only render and resume are shared; every other command is rank 0's alone
    // (one answer, one output file).
    if (g_mpi->distributed() && g_mpi->rank() != 0 && cmd.kind != pb::Command::Kind::Render &&
        cmd.kind != pb::Command::Kind::Resume)
      return 0;
    switch (cmd.kind) {
      case pb::Command::Kind::Help:
        std::cout << pb::usage_text();
        return 0;
      case pb::Command::Kind::HelpTable:
        std::cout << pb::markdown_option_table();
        return 0;
      case pb::Command::Kind::Version: {
        const std::string mpi = pb::mpi_library_version();
        std::cout << "photonbound " << PHOTONBOUND_VERSION << "\n"
                  << (mpi.empty() ? "built without MPI: renders run in one process\n"
                                  : "distributed renders with mpirun (" + mpi + ")\n");
        return 0;
      }
      case pb::Command::Kind::Render:
        return render(cmd.render);
      case pb::Command::Kind::Resume:
        return resume(cmd.resume);
      case pb::Command::Kind::Compare:
        return pb::compare_command(cmd.compare);
      case pb::Command::Kind::Preview:
        return pb::preview_command(cmd.preview);
    }
  } catch (const pb::UsageError& e) {
    // Every rank parses the same command line: one message is enough.
    if (!g_mpi->distributed() || g_mpi->rank() == 0)
      std::cerr << "photonbound: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    // What the up-front estimates (render_memory.h) did not foresee.
    std::cerr << error_prefix()
              << "out of memory (an allocation failed); lower --resolution "
                 "or --photons-per-pass, or use smaller textures\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << error_prefix() << e.what() << "\n";
    return 1;
  }
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    pb::MpiSession mpi(argc, argv);
    g_mpi = &mpi;
    const int code = run(argc, argv);
    // One rank's failure ends every rank (none waits in a collective for it).
    if (code != 0 && mpi.distributed()) mpi.abort(code);
    return code;
  } catch (const std::exception& e) {  // MPI failed to start
    std::cerr << "photonbound: error: " << e.what() << "\n";
    return 1;
  }
}
