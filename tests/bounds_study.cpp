// Prints the README's evidence for the error bounds: coverage against the exact answers of the
// analytic scenes, and renders to halving target errors (specified vs actual error).
// Run: build/tests/bounds_study [all|coverage|termination|stopping] [ppm|sppm]
// (a few minutes on 2 cores)
#include "analytic.h"
#include "render_fixture.h"

#include <cstdio>

namespace {

using namespace pb;

Method g_method = Method::PPM;  // `bounds_study TABLE sppm` studies SPPM

RenderOptions study_options(const std::string& scene, int size, uint64_t passes) {
  RenderOptions o = test::quick_options(scene, size, passes);
  o.method = g_method;
  return o;
}

void coverage_table() {
  std::printf("### Coverage against the exact answer (%s, 64x64, 4 seeds pooled)\n\n",
              g_method == Method::PPM ? "PPM" : "SPPM");
  std::printf(
      "| scene | direct | passes | confidence | mean actual error | mean bound | bound / actual | "
      "coverage |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  const std::pair<const char*, DirectMode> cases[] = {
      {"plane", DirectMode::Photons}, {"box", DirectMode::Photons}, {"box", DirectMode::NextEvent}};
  for (const auto& [name, mode] : cases) {
    std::vector<analytic::CoverageRow> pooled;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
      RenderOptions o = study_options(analytic::by_name(name).file, 64, 256);
      o.direct = mode;
      o.seed = seed;
      const auto rows = analytic::coverage_run(name, o, {16, 64, 256}, {0.5, 0.9, 0.95});
      if (pooled.empty()) {
        pooled = rows;
        continue;
      }
      for (size_t k = 0; k < rows.size(); ++k) {
        auto& a = pooled[k].accuracy;
        const auto& b = rows[k].accuracy;
        const double n = double(a.samples), m = double(b.samples);
        a.mean_abs_error = (a.mean_abs_error * n + b.mean_abs_error * m) / (n + m);
        a.mean_bound = (a.mean_bound * n + b.mean_bound * m) / (n + m);
        a.coverage = (a.coverage * n + b.coverage * m) / (n + m);
        a.samples += b.samples;
      }
    }
    for (const auto& r : pooled)
      std::printf("| %s | %s | %llu | %.0f%% | %.5f | %.5f | %.2f | %.3f |\n", r.scene.c_str(),
                  mode == DirectMode::Photons ? "photons" : "nee", (unsigned long long)r.passes,
                  100.0 * r.confidence, r.accuracy.mean_abs_error, r.accuracy.mean_bound,
                  r.accuracy.mean_bound / r.accuracy.mean_abs_error, r.accuracy.coverage);
  }
  std::printf("\n");
}

void termination_table() {
  std::printf(
      "### Render to a target error: plane under a point light (32x32, --direct photons)\n\n");
  std::printf(
      "| confidence | target (specified) | actual mean error | specified / actual | passes | "
      "seconds | stop |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (double confidence : {0.5, 0.9}) {
    for (double target : confidence < 0.7 ? std::vector<double>{0.016, 0.008, 0.004}
                                          : std::vector<double>{0.04, 0.02, 0.01}) {
      RenderOptions o = study_options("plane_point.gltf", 32, 100000);
      o.passes.reset();
      o.direct = DirectMode::Photons;
      o.confidence = confidence;
      o.target_error = target;
      const analytic::TerminationRow r = analytic::termination_run("plane", o);
      std::printf("| %.0f%% | %.4f | %.5f | %.2f | %llu | %.1f | %s |\n", 100.0 * confidence,
                  target, r.actual, target / r.actual, (unsigned long long)r.passes, r.seconds,
                  r.stop_reason.c_str());
      std::fflush(stdout);
    }
  }
  std::printf("\n");
}

// Optional stopping: how often a render stops with its actual mean error above the target.
void stopping_table() {
  const int kSeeds = 20;
  std::printf("### Early stops over %d seeds (plane, 32x32, --direct photons)\n\n", kSeeds);
  std::printf(
      "| confidence | target | runs with actual > target | mean specified / actual | mean passes "
      "|\n");
  std::printf("|---|---|---|---|---|\n");
  for (const auto& [confidence, target] : {std::pair{0.5, 0.008}, std::pair{0.9, 0.02}}) {
    int above = 0;
    double ratio = 0.0, passes = 0.0;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      RenderOptions o = study_options("plane_point.gltf", 32, 1);
      o.passes = 100000;
      o.direct = DirectMode::Photons;
      o.confidence = confidence;
      o.target_error = target;
      o.seed = uint64_t(seed) * 7919u;
      const analytic::TerminationRow r = analytic::termination_run("plane", o);
      above += r.actual > target;
      ratio += target / r.actual / kSeeds;
      passes += double(r.passes) / kSeeds;
    }
    std::printf("| %.0f%% | %.3f | %d / %d | %.2f | %.0f |\n", 100.0 * confidence, target, above,
                kSeeds, ratio, passes);
    std::fflush(stdout);
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const std::string which = argc > 1 ? argv[1] : "all";
  if (argc > 2 && std::string(argv[2]) == "sppm") g_method = Method::SPPM;
  if (which == "all" || which == "coverage") coverage_table();
  if (which == "all" || which == "termination") termination_table();
  if (which == "all" || which == "stopping") stopping_table();
  return 0;
}
