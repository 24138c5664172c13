// Prints docs/error-bounds.md's evidence for the error bounds: coverage against the exact answers
// of the analytic scenes, and renders to halving target errors (specified vs actual error).
// Run: build/tools/bounds_study [all|coverage|termination|stopping|edges|cornell|rules|
// calibration|correlation|slope|modelcheck|modelnull|pixels] [ppm|sppm] [seeds]
// (a few minutes on 2 cores)
#include "analytic.h"
#include "reference_truth.h"
#include "render_fixture.h"

#include "estimator/error_model.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace {

using namespace pb;

Method g_method = Method::PPM;

// The confidence whose one-sided normal quantile is 1.
double normal_cdf_one() { return 0.8413447460685429; }  // `bounds_study TABLE sppm` studies SPPM

RenderOptions study_options(const std::string& scene, int size, uint64_t passes) {
  RenderOptions o = test::quick_options(scene, size, passes);
  o.method = g_method;
  // PB_STUDY_ADAPTIVE=radius,photons,paths (or any of them, or none for the --alpha schedule):
  // the tables with ESTIMATOR.md section 13's radius, section 14's photon guide and section 15's
  // camera paths. Unset: the defaults (the radius alone).
  // PB_STUDY_BIAS=laplacian: the bounds with HJJ10's a R^2 alone (ESTIMATOR.md section 6c).
  if (const char* b = std::getenv("PB_STUDY_BIAS"))
    o.bias_model = std::string(b) == "laplacian" ? BiasModel::Laplacian : BiasModel::TwoScale;
  if (const char* a = std::getenv("PB_STUDY_ADAPTIVE")) {
    o.adaptive_radius = std::string(a).find("radius") != std::string::npos;
    o.adaptive_photons = std::string(a).find("photons") != std::string::npos;
    o.adaptive_paths = std::string(a).find("paths") != std::string::npos;
  }
  return o;
}

void coverage_table() {
  std::printf("### Coverage against the exact answer (%s, 64x64, 4 seeds pooled)\n\n",
              g_method == Method::PPM ? "PPM" : "SPPM");
  std::printf(
      "| scene | direct | passes | confidence | mean actual error | mean bound | bound / actual | "
      "coverage |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  const std::pair<const char*, DirectMode> cases[] = {{"plane", DirectMode::Photons},
                                                      {"glossy", DirectMode::Photons},
                                                      {"box", DirectMode::Photons},
                                                      {"box", DirectMode::NextEvent},
                                                      {"block", DirectMode::NextEvent}};
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

// The closed box by where pixels lie (issue "Bounds along geometric edges"): all pixels, the
// band within two current radii of an edge of their wall, and the interior; coverage, mean
// error and mean bound / mean error, 4 seeds pooled, and the band's mean error over the
// interior's.
void edges_table() {
  std::printf(
      "### Closed box and the box with a block, by distance to an edge (%s, 64x64, 25k "
      "photons per pass, 4 seeds pooled)\n\n",
      g_method == Method::PPM ? "PPM" : "SPPM");
  std::printf(
      "| scene | direct | passes | pixels | share | mean error | bound / error at 50%% | 50%% | "
      "90%% | 95%% |\n|---|---|---|---|---|---|---|---|---|---|\n");
  const std::pair<const char*, DirectMode> cases[] = {{"box", DirectMode::Photons},
                                                      {"box", DirectMode::NextEvent},
                                                      {"block", DirectMode::Photons},
                                                      {"block", DirectMode::NextEvent}};
  for (const auto& [scene_name, mode] : cases) {
    // [checkpoint][band: all, edge, interior][confidence] pooled sums
    struct Sum {
      double err = 0, bound = 0, covered = 0, n = 0, pixels = 0;
    };
    const uint64_t checks[] = {16, 64, 256};
    const double confs[] = {0.5, 0.9, 0.95};
    Sum sums[3][3][3];
    for (uint64_t seed = 1; seed <= 4; ++seed) {
      RenderOptions o = study_options(analytic::by_name(scene_name).file, 64, 256);
      o.direct = mode;
      o.photons_per_pass = 25000;
      o.seed = seed;
      const pb::Scene scene = load_gltf(o.scene);
      Renderer r(scene, o);
      const std::vector<double> truth =
          analytic::pixel_truth(r, analytic::by_name(scene_name).exact);
      for (int ci = 0; ci < 3; ++ci) {
        while (r.passes() < checks[ci]) r.step();
        const std::vector<int> band = analytic::box_edge_band(r, 2.0);
        for (int bi = 0; bi < 3; ++bi)
          for (int k = 0; k < 3; ++k) {
            const analytic::Accuracy a =
                bi == 0 ? analytic::measure(r, truth, confs[k])
                        : analytic::measure(r, truth, confs[k], &band, bi == 1 ? 1 : 0);
            Sum& s = sums[ci][bi][k];
            s.err += a.mean_abs_error * double(a.samples);
            s.bound += a.mean_bound * double(a.samples);
            s.covered += a.coverage * double(a.samples);
            s.n += double(a.samples);
          }
      }
    }
    for (int ci = 0; ci < 3; ++ci) {
      const char* names[] = {"all", "edge band (< 2 R)", "interior"};
      for (int bi = 0; bi < 3; ++bi) {
        const Sum* s = sums[ci][bi];
        const double err = s[0].err / std::max(s[0].n, 1.0);
        std::printf("| %s | %s | %llu | %s | %.2f | %.5f | %.2f | %.3f | %.3f | %.3f |\n",
                    scene_name, mode == DirectMode::Photons ? "photons" : "nee",
                    (unsigned long long)checks[ci], names[bi],
                    s[0].n / std::max(sums[ci][0][0].n, 1.0), err,
                    s[0].bound / std::max(s[0].err, 1e-300), s[0].covered / std::max(s[0].n, 1.0),
                    s[1].covered / std::max(s[1].n, 1.0), s[2].covered / std::max(s[2].n, 1.0));
      }
      const double edge = sums[ci][1][0].err / std::max(sums[ci][1][0].n, 1.0);
      const double inner = sums[ci][2][0].err / std::max(sums[ci][2][0].n, 1.0);
      std::printf("| %s | %s | %llu | edge / interior mean error | | %.2f | | | | |\n", scene_name,
                  mode == DirectMode::Photons ? "photons" : "nee", (unsigned long long)checks[ci],
                  edge / inner);
      std::fflush(stdout);
    }
  }
  std::printf("\n");
}

// The Cornell box against its rendered reference (SPPM only: the reference is a long SPPM render,
// a pixel-area average), every pixel counted, and the pixels within two radii of an edge of the
// gather's surfaces (reference::edge_band) as their own rows. 10k photons per pass, so that the
// runs' errors stay well above the reference's own (docs/error-bounds.md "The Cornell box against
// its reference").
void cornell_table(int seeds) {
  if (g_method != Method::SPPM) {
    std::printf("(the Cornell reference is an SPPM render: run `bounds_study cornell sppm`)\n");
    return;
  }
  const reference::Truth truth =
      reference::load(std::string(PHOTONBOUND_REFERENCES) + "/cornell_64x64_sppm_reference.exr");
  std::printf(
      "### Cornell box against its reference (SPPM, 64x64, 10k photons per pass, %d seeds "
      "pooled)\n\n",
      seeds);
  std::printf(
      "| passes | pixels | share | mean error | bound / error at 50%% | 50%% | 90%% | 95%% | "
      "with the reference's noise: 50%% | 90%% | 95%% |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n");
  RenderOptions o = study_options("cornell.gltf", 64, 256);
  o.photons_per_pass = 10000;
  reference::PooledCoverage pc =
      reference::pooled_coverage(o, seeds, truth, {16, 64, 256}, {0.5, 0.9, 0.95});
  using S = reference::Sums;
  for (size_t ci = 0; ci < 3; ++ci) {
    const char* names[] = {"all", "edge band (< 2 R)", "interior"};
    for (int bi = 0; bi < 3; ++bi) {
      const S& s = pc.at(ci, bi, 0);
      std::printf("| %llu | %s | %.2f | %.5f | %.2f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |\n",
                  (unsigned long long)pc.checks[ci], names[bi],
                  s.n / std::max(pc.at(ci, 0, 0).n, 1.0), s.mean(&S::err),
                  s.bound / std::max(s.err, 1e-300), s.mean(&S::covered),
                  pc.at(ci, bi, 1).mean(&S::covered), pc.at(ci, bi, 2).mean(&S::covered),
                  s.mean(&S::covered_ref), pc.at(ci, bi, 1).mean(&S::covered_ref),
                  pc.at(ci, bi, 2).mean(&S::covered_ref));
    }
    const S &edge = pc.at(ci, 1, 0), &inner = pc.at(ci, 2, 0);
    std::printf(
        "| %llu | edge / interior mean error; relative error; mean signed error edge, interior | "
        "| %.2f; %.2f; %+.5f, %+.5f | | | | | | | |\n",
        (unsigned long long)pc.checks[ci], edge.mean(&S::err) / inner.mean(&S::err),
        edge.mean(&S::rel) / inner.mean(&S::rel), edge.mean(&S::sgn), inner.mean(&S::sgn));
    std::fflush(stdout);
  }
  std::printf("\n");
}

// The stop rules side by side (issue "Stop on the error the user asked for"): for each scene,
// confidence and target, seeds rendered to the target with each rule; how often the actual
// mean error ended within the target, the mean specified / actual, the mean share of pixels
// whose actual error (largest channel) is within the target, passes and seconds. The plane and
// the closed box against their exact answers at 32x32; the Cornell box at 64x64 against its
// reference, whose own mean error (about 0.002) adds to the actual error measured. Photons per
// pass are chosen so that even the largest target needs a few times --min-passes (16) passes:
// a run that stops at its first test has had no chance to stop late.
// `rules [ppm|sppm] SEEDS OTHER_SEEDS`: SEEDS for mean-error (default 20), OTHER_SEEDS for the
// two others (default SEEDS); PB_STUDY_RULE and PB_STUDY_SCENE select one rule or scene,
// PB_STUDY_TARGET one target, and PB_STUDY_RUNS=1 prints every run (section 15 of ESTIMATOR.md).
void rules_table(int seeds, int other_seeds) {
  std::printf("### Stop rules (%s; mean-error %d seeds per row, the other rules %d)\n\n",
              g_method == Method::PPM ? "PPM" : "SPPM", seeds, other_seeds);
  std::printf(
      "| scene | rule | confidence | target | runs within target | mean specified / actual | "
      "pixels within target | mean passes | mean seconds |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  struct SceneCase {
    const char* name;
    const char* file;
    int size;
    DirectMode direct;
    uint64_t photons;
    double targets[3];
  };
  const SceneCase scenes[] = {
      {"plane", "plane_point.gltf", 32, DirectMode::Photons, 5000, {0.04, 0.02, 0.01}},
      {"box", "closed_box.gltf", 32, DirectMode::NextEvent, 5000, {0.06, 0.03, 0.015}},
      {"cornell", "cornell.gltf", 64, DirectMode::NextEvent, 2500, {0.025, 0.0125, 0.00625}}};
  const std::pair<StopRule, const char*> rules[] = {{StopRule::MeanError, "mean-error"},
                                                    {StopRule::MeanBound, "mean-bound"},
                                                    {StopRule::Pixels, "pixels:0.9"}};
  const char* only = std::getenv("PB_STUDY_RULE");
  const char* only_scene = std::getenv("PB_STUDY_SCENE");
  for (const SceneCase& sc : scenes) {
    if (only_scene && std::string(only_scene) != sc.name) continue;
    const bool rendered = std::string(sc.name) == "cornell";
    if (rendered && g_method != Method::SPPM) continue;  // its reference is an SPPM render
    reference::Truth ref;
    if (rendered)
      ref = reference::load(std::string(PHOTONBOUND_REFERENCES) +
                            "/cornell_64x64_sppm_reference.exr");
    for (const auto& [rule, rule_name] : rules) {
      if (only && std::string(only) != rule_name) continue;
      const int n_seeds = rule == StopRule::MeanError ? seeds : other_seeds;
      for (double confidence : {0.5, 0.9, 0.95})
        for (double target : sc.targets) {
          // PB_STUDY_CONFIDENCE (0.5, 0.9 or 0.95) keeps one confidence's rows.
          if (const char* c = std::getenv("PB_STUDY_CONFIDENCE"); c && std::atof(c) != confidence)
            continue;
          // PB_STUDY_TARGET (a number) replaces the scene's targets by that one.
          if (const char* e = std::getenv("PB_STUDY_TARGET")) {
            if (target != sc.targets[0]) continue;
            target = std::atof(e);
          }
          int within = 0;
          double ratio = 0.0, passes = 0.0, seconds = 0.0, pixels_within = 0.0;
          for (int seed = 1; seed <= n_seeds; ++seed) {
            RenderOptions o = study_options(sc.file, sc.size, 1000000);
            o.direct = sc.direct;
            o.photons_per_pass = sc.photons;
            o.confidence = confidence;
            o.target_error = target;
            o.stop_rule = rule;
            o.stop_fraction = 0.9;
            o.seed = uint64_t(seed) * 7919u;
            const pb::Scene scene = load_gltf(o.scene);
            Renderer r(scene, o);
            const RenderReport report = test::run_to_stop(r);
            FilmImage img;
            const FilmSummary summary = r.develop(&img);
            // Per pixel-channel truth: the reference's, or the exact answer (grey; NaN where a
            // pixel has no point, which is exact and left out, as `compare` does).
            std::vector<double> truth = ref.value;
            if (!rendered) {
              const std::vector<double> t =
                  analytic::pixel_truth(r, analytic::by_name(sc.name).exact);
              truth.resize(3 * t.size());
              for (size_t p = 0; p < t.size(); ++p)
                truth[3 * p] = truth[3 * p + 1] = truth[3 * p + 2] = t[p];
            }
            double sum = 0.0, n = 0.0, px_in = 0.0, px = 0.0;
            for (size_t p = 0; 3 * p < truth.size(); ++p) {
              if (std::isnan(truth[3 * p])) continue;
              double worst = 0.0;
              for (size_t k = 3 * p; k < 3 * p + 3; ++k) {
                const double e = std::fabs(double(img.radiance[k]) - truth[k]);
                sum += e;
                worst = std::max(worst, e);
              }
              n += 3.0;
              px_in += worst <= target;
              px += 1.0;
            }
            const double actual = sum / std::max(n, 1.0);
            // PB_STUDY_RUNS=1: each run's stop pass, predicted mean error and its upper limit
            // against the actual (which holds the reference's own error, section 15).
            if (std::getenv("PB_STUDY_RUNS"))
              std::printf("  seed %d: %llu passes, predicted %.5f (upper %.5f), actual %.5f\n",
                          seed, (unsigned long long)report.work.passes, summary.predicted_error,
                          summary.predicted_error_upper, actual);
            within += actual <= target;
            ratio += target / actual / n_seeds;
            pixels_within += px_in / std::max(px, 1.0) / n_seeds;
            passes += double(report.work.passes) / n_seeds;
            seconds += report.seconds / n_seeds;
          }
          std::printf("| %s | %s | %.0f%% | %.4g | %d / %d | %.2f | %.3f | %.0f | %.2f |\n",
                      sc.name, rule_name, 100.0 * confidence, target, within, n_seeds, ratio,
                      pixels_within, passes, seconds);
          std::fflush(stdout);
        }
    }
  }
  std::printf("\n");
}

// The error model's prediction against the actual mean error at fixed pass counts, over seeds:
// mean actual, mean predicted, the actual's spread across seeds and the predicted spread.
void calibration_table(int seeds) {
  std::printf("### Mean-error prediction (%s, 32x32)\n\n",
              g_method == Method::PPM ? "PPM" : "SPPM");
  std::printf(
      "| scene | passes | actual | predicted | actual sd | predicted sd | measured K "
      "|\n|---|---|---|---|---|---|---|\n");
  const std::pair<const char*, DirectMode> scenes[] = {{"plane", DirectMode::Photons},
                                                       {"box", DirectMode::NextEvent}};
  const char* only_scene = std::getenv("PB_STUDY_SCENE");
  auto wanted = [&](const char* name) { return !only_scene || std::string(only_scene) == name; };
  for (const auto& [name, direct] : scenes)
    for (uint64_t passes : {16, 64, 256, 1024}) {
      if (!wanted(name)) continue;
      std::vector<double> actual, predicted, sd;
      double k = 0.0;
      for (int seed = 1; seed <= seeds; ++seed) {
        RenderOptions o = study_options(analytic::by_name(name).file, 32, passes);
        o.direct = direct;
        o.photons_per_pass = 10000;
        o.seed = uint64_t(seed) * 7919u;
        o.confidence = normal_cdf_one();  // z = 1: upper - predicted = one sd
        Renderer r(load_gltf(o.scene), o);
        while (r.passes() < passes) r.step();
        const std::vector<double> truth = analytic::pixel_truth(r, analytic::by_name(name).exact);
        FilmImage img;
        const FilmSummary sum = r.develop(&img);
        double e = 0.0;
        size_t n = 0;
        for (size_t p = 0; p < truth.size(); ++p)
          for (int c = 0; c < 3; ++c, ++n)
            e += std::isnan(truth[p]) ? 0.0 : std::fabs(img.radiance[3 * p + c] - truth[p]);
        actual.push_back(e / double(n));
        predicted.push_back(sum.predicted_error);
        sd.push_back(sum.predicted_error_upper - sum.predicted_error);
        k += sum.correlated_pixels / double(seeds);
      }
      auto mean = [](const std::vector<double>& v) {
        double m = 0.0;
        for (double x : v) m += x;
        return m / double(v.size());
      };
      const double ma = mean(actual);
      double var = 0.0, dvar = 0.0, dm = 0.0;
      for (size_t k = 0; k < actual.size(); ++k)
        dm += (actual[k] - predicted[k]) / double(actual.size());
      for (size_t k = 0; k < actual.size(); ++k) {
        var += (actual[k] - ma) * (actual[k] - ma);
        const double d = actual[k] - predicted[k] - dm;
        dvar += d * d;
      }
      std::printf("| %s | %llu | %.5f | %.5f | %.5f | %.5f | %.1f | diff sd %.5f |\n", name,
                  (unsigned long long)passes, ma, mean(predicted),
                  std::sqrt(var / double(actual.size() - 1)), mean(sd), k,
                  std::sqrt(dvar / double(actual.size() - 1)));
      std::fflush(stdout);
    }
  // The Cornell box (SPPM only) against its reference, as in the rules table (64x64, 2500
  // photons per pass), at the pass counts its mean-error stops reached.
  if (g_method == Method::SPPM && wanted("cornell")) {
    const reference::Truth truth =
        reference::load(std::string(PHOTONBOUND_REFERENCES) + "/cornell_64x64_sppm_reference.exr");
    std::vector<uint64_t> pass_counts{46, 198, 880};
    if (const char* env = std::getenv("PB_STUDY_PASSES")) pass_counts = {uint64_t(std::atoll(env))};
    for (uint64_t passes : pass_counts) {
      double ma = 0.0, mp = 0.0, msd = 0.0, ss = 0.0, k = 0.0;
      std::vector<double> actual;
      for (int seed = 1; seed <= seeds; ++seed) {
        RenderOptions o = study_options("cornell.gltf", 64, passes);
        o.photons_per_pass = 2500;
        o.seed = uint64_t(seed) * 7919u;
        o.confidence = normal_cdf_one();
        Renderer r(load_gltf(o.scene), o);
        while (r.passes() < passes) r.step();
        FilmImage img;
        const FilmSummary sum = r.develop(&img);
        double e = 0.0;
        for (size_t k = 0; k < img.radiance.size(); ++k)
          e += std::fabs(double(img.radiance[k]) - truth.value[k]);
        actual.push_back(e / double(img.radiance.size()));
        mp += sum.predicted_error / seeds;
        msd += (sum.predicted_error_upper - sum.predicted_error) / seeds;
        k += sum.correlated_pixels / seeds;
      }
      for (double a : actual) ma += a / seeds;
      for (double a : actual) ss += (a - ma) * (a - ma);
      std::printf("| cornell | %llu | %.5f | %.5f | %.5f | %.5f | %.1f |\n",
                  (unsigned long long)passes, ma, mp, std::sqrt(ss / double(seeds - 1)), msd, k);
      std::fflush(stdout);
    }
  }
  std::printf("\n");
}

// The errors' correlation between pixels, measured: sum over offsets up to 8 pixels of the
// correlation of e / sigma (and of |e|), against correlated_pixels().
void correlation_table() {
  const std::pair<const char*, DirectMode> scenes[] = {{"plane", DirectMode::Photons},
                                                       {"box", DirectMode::NextEvent}};
  for (const auto& [name, direct] : scenes)
    for (uint64_t passes : {16, 256}) {
      RenderOptions o = study_options(analytic::by_name(name).file, 64, passes);
      o.direct = direct;
      o.photons_per_pass = 10000;
      Renderer r(load_gltf(o.scene), o);
      while (r.passes() < passes) r.step();
      const std::vector<double> truth = analytic::pixel_truth(r, analytic::by_name(name).exact);
      FilmImage img;
      const double measured_k = r.develop(&img).correlated_pixels;
      const int w = r.camera_pass().width, h = r.camera_pass().height;
      std::vector<double> z(size_t(w * h)), a(size_t(w * h));
      double ma = 0.0;
      for (int p = 0; p < w * h; ++p) {
        const double sd = std::sqrt(std::max(1e-30, double(img.variance[3 * p])));
        z[p] = (img.radiance[3 * p] - truth[p]) / sd;
        a[p] = std::fabs(z[p]);
        ma += a[p] / (w * h);
      }
      double sz = 0.0, sa = 0.0, z0 = 0.0, a0 = 0.0;
      for (int dy = -8; dy <= 8; ++dy)
        for (int dx = -8; dx <= 8; ++dx) {
          double cz = 0.0, ca = 0.0;
          int n = 0;
          for (int y = 8; y < h - 8; ++y)
            for (int x = 8; x < w - 8; ++x) {
              const int p = y * w + x, q = (y + dy) * w + (x + dx);
              cz += z[p] * z[q];
              ca += (a[p] - ma) * (a[q] - ma);
              ++n;
            }
          sz += cz / n;
          sa += ca / n;
          if (dx == 0 && dy == 0) z0 = cz / n, a0 = ca / n;
        }
      double mr2 = 0.0;
      for (const PointState& st : r.states()) mr2 += st.r2 / double(r.states().size());
      std::printf(
          "%s %llu passes: sum corr(e) %.1f, sum corr(|e|) %.1f, model K %.1f, measured K %.1f "
          "(R/f %.2f)\n",
          name, (unsigned long long)passes, sz / z0, sa / a0,
          correlated_pixels(std::sqrt(mr2), r.camera_pass().median_footprint), measured_k,
          std::sqrt(mr2) / r.camera_pass().median_footprint);
    }
}

}  // namespace

// Issue 14's large starting radius: does the samples' own drift with R^2 (the regression slope
// C_XR / C_RR) see what the Laplacian slope a misses? Plane, PPM, 32x32, 64 passes, 4 seeds
// pooled, red channel, 90%: coverage of today's bound; of the bound widened by the two slopes'
// difference times mean R^2 where it exceeds 2 of its sd (the share flagged); of the larger of
// today's bound and the bound with the regression's bias and the slope's noise.
void slope_experiment() {
  for (double radius : {0.1, 0.3, 1.0, 3.0, 10.0}) {
    size_t n = 0, cov0 = 0, cov1 = 0, cov2 = 0, flagged = 0;
    double e_sum = 0, b0 = 0, b1 = 0, b2 = 0;
    for (int seed = 1; seed <= 4; ++seed) {
      RenderOptions o = study_options("plane_point.gltf", 32, 64);
      o.direct = DirectMode::Photons;
      o.radius = radius;
      o.seed = uint64_t(seed) * 7919u;
      Renderer r(load_gltf(o.scene), o);
      while (r.passes() < 64) r.step();
      const std::vector<double> truth = analytic::pixel_truth(r, analytic::plane_point);
      FilmImage img;
      r.develop(&img);
      const double i = double(r.passes());
      const BoundQuantile q(i - 1.0, 0.9);
      for (size_t p = 0; p < truth.size(); ++p) {
        if (std::isnan(truth[p])) continue;
        const PointState& st = r.states()[p];  // one point per pixel on the plane
        const PointEstimate e = estimate(st, r.passes(), double(o.photons_per_pass));
        const double a = e.bias.x / st.mean_r2;
        const double slope = st.c_xr.x / st.c_rr;
        const double resid =
            std::max(0.0, (st.c_xx.x - st.c_xr.x * st.c_xr.x / st.c_rr) / (i - 2.0));
        const double sd_slope = std::sqrt(resid / st.c_rr);
        const double err = img.radiance[3 * p] - truth[p];
        const double bound = img.bound[3 * p];
        // The two slopes' disagreement, in bias units.
        const double d = (slope - a) * st.mean_r2, sd_d = sd_slope * st.mean_r2;
        const double sd = std::sqrt(e.variance.x);
        const bool flag = std::fabs(d) > 2.0 * sd_d;
        const double w1 = bound + (flag ? std::fabs(d) : 0.0);
        // empirical-slope bias: quantile with bias slope*mean_r2 and sd including the slope's
        const double w2 = std::max(bound, q(slope * st.mean_r2, std::sqrt(sd * sd + sd_d * sd_d)));
        ++n;
        flagged += flag;
        e_sum += std::fabs(err);
        b0 += bound;
        b1 += w1;
        b2 += w2;
        cov0 += std::fabs(err) <= bound;
        cov1 += std::fabs(err) <= w1;
        cov2 += std::fabs(err) <= w2;
      }
    }
    std::printf(
        "radius %.1f: error %.4f | bound %.4f cov %.3f | flag-widen %.4f cov %.3f (flagged %.2f) | "
        "max(emp) %.4f cov %.3f\n",
        radius, e_sum / n, b0 / n, double(cov0) / n, b1 / n, double(cov1) / n, double(flagged) / n,
        b2 / n, double(cov2) / n);
    std::fflush(stdout);
  }
}

// The model check's statistics over a render's states (PointEstimate::slope_z).
struct SlopeShares {
  double share2 = 0, share3 = 0, z2 = 0, zmax = 0, count = 0;
  double scale3 = 0, scale_z2 = 0, scale_count = 0;  // the two-scale check (section 11c)
  void add(const Renderer& r) {
    for (const PointState& st : r.states()) {
      const PointEstimate e = estimate(st, r.passes(), double(r.options().photons_per_pass));
      if (e.scale_z != 0.0) {
        scale3 += std::fabs(e.scale_z) > kSlopeZ;
        scale_z2 += e.scale_z * e.scale_z;
        scale_count += 1;
      }
      for (int c = 0; c < 3; ++c) {
        const double z = e.slope_z[c];
        if (z == 0.0) continue;
        share2 += std::fabs(z) > 2.0;
        share3 += std::fabs(z) > kSlopeZ;
        z2 += z * z;
        zmax = std::max(zmax, z * z);
        count += 1;
      }
    }
  }
};

// The second-order model's own check (issue 14, large starting radii): per state and channel,
// z = (b - a) / sd, b = C_XR / C_RR the samples' regression slope on R^2 and a the Laplacian's;
// the share of |z| > 2 and > 3 and the mean of z^2 over the image, against the coverage at 90%.
void modelcheck_experiment() {
  std::printf(
      "| scene | method | radius x default | passes | share z>2 | share z>3 | mean z^2 | "
      "two-scale share z>3 | two-scale mean z^2 | error | bound | coverage 90%% |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  const std::pair<const char*, DirectMode> cases[] = {{"plane", DirectMode::Photons},
                                                      {"box", DirectMode::NextEvent},
                                                      {"block", DirectMode::NextEvent}};
  const char* only = std::getenv("PB_STUDY_SCENE");
  for (Method method : {Method::PPM, Method::SPPM})
    for (const auto& [name, mode] : cases) {
      if (only && std::string(only) != name) continue;
      const analytic::Case sc = analytic::by_name(name);
      for (double mult : {1.0, 3.0, 10.0, 30.0}) {
        for (uint64_t passes : {4u, 16u, 64u, 256u}) {
          SlopeShares shares;
          double err = 0, bnd = 0, cov = 0;
          for (int seed = 1; seed <= 2; ++seed) {
            RenderOptions o = study_options(sc.file, 32, passes);
            o.method = method;
            o.direct = mode;
            o.seed = uint64_t(seed) * 7919u;
            const Scene scene = load_gltf(o.scene);
            {
              Renderer r0(scene, o);
              o.radius = mult * r0.initial_radius();
            }
            Renderer r(scene, o);
            while (r.passes() < passes) r.step();
            shares.add(r);
            // A refuted image has no known pixel (samples 0): its columns read 0, "unknown".
            const analytic::Accuracy acc = analytic::measure(r, sc.exact, 0.9);
            err += acc.mean_abs_error / 2;
            bnd += acc.mean_bound / 2;
            cov += acc.coverage / 2;
          }
          std::printf(
              "| %s | %s | %.0f | %llu | %.3f | %.3f | %.2f | %.3f | %.2f | %.4f | %.4f | %.3f |\n",
              name, method == Method::PPM ? "PPM" : "SPPM", mult, (unsigned long long)passes,
              shares.share2 / shares.count, shares.share3 / shares.count, shares.z2 / shares.count,
              shares.scale3 / shares.scale_count, shares.scale_z2 / shares.scale_count, err, bnd,
              cov);
          std::fflush(stdout);
        }
      }
    }
}

// The same statistic on the shipped scenes at their defaults (64x64): how often the model check
// would fire where the radius is the default one.
void modelnull_experiment() {
  std::printf(
      "| scene | method | passes | share z>2 | share z>3 | mean z^2 | max state z^2 share of sum "
      "| two-scale share z>3 | two-scale mean z^2 |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const char* file : {"cornell.gltf", "glass_slab.gltf", "spot.gltf", "glossy_plane.gltf",
                           "sun.gltf", "unlit.gltf", "closed_block.gltf", "furnace.gltf"})
    for (Method method : {Method::SPPM, Method::PPM}) {
      const char* only = std::getenv("PB_STUDY_SCENE");
      if (only && std::string(only) != file) continue;
      // PB_STUDY_SIZE and PB_STUDY_PHOTONS: sparse photons per state (a large image at few
      // photons per pass), where each state's Y and slope rest on a handful of photons.
      const char* size = std::getenv("PB_STUDY_SIZE");
      RenderOptions o = study_options(file, size ? std::atoi(size) : 64, 256);
      if (const char* photons = std::getenv("PB_STUDY_PHOTONS"))
        o.photons_per_pass = uint64_t(std::atoll(photons));
      o.method = method;
      Renderer r(load_gltf(o.scene), o);
      const char* longer = std::getenv("PB_STUDY_LONG");
      for (uint64_t passes : {4u, 16u, 64u, 256u, 1024u, 4096u}) {
        if (passes > 256u && !longer) break;
        while (r.passes() < passes) r.step();
        SlopeShares sh;
        sh.add(r);
        std::printf("| %s | %s | %llu | %.3f | %.3f | %.2f | %.3f | %.3f | %.2f |\n", file,
                    method == Method::PPM ? "PPM" : "SPPM", (unsigned long long)passes,
                    sh.share2 / sh.count, sh.share3 / sh.count, sh.z2 / sh.count, sh.zmax / sh.z2,
                    sh.scale3 / sh.scale_count, sh.scale_z2 / sh.scale_count);
        std::fflush(stdout);
      }
    }
}

// The model check on any file (PB_STUDY_FILE, PB_STUDY_SIZE, default 48): the share of
// state-channels with |z| > 3 by the state's photon count, to see where a refutation comes from.
double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

void modelfile_experiment() {
  const char* file = std::getenv("PB_STUDY_FILE");
  if (!file) return;
  const char* size = std::getenv("PB_STUDY_SIZE");
  RenderOptions o = study_options("cornell.gltf", size ? std::atoi(size) : 48, 64);
  o.scene = file;
  o.method = g_method;
  const char* seed = std::getenv("PB_STUDY_SEED");
  o.seed = seed ? uint64_t(std::atoll(seed)) : 4u;
  Renderer r(load_gltf(o.scene), o);
  std::printf(
      "| passes | photons | channels | share z>3 | mean z^2 | mean z | two-scale states | share "
      "z>3 | median bias / sd there |\n|---|---|---|---|---|---|---|---|---|\n");
  for (uint64_t passes : {4u, 16u, 64u}) {
    while (r.passes() < passes) r.step();
    const uint64_t edges[] = {0, 5, 10, 20, 50, 100, 1000, ~0ull};
    double n[8] = {}, d[8] = {}, z2[8] = {}, zs[8] = {}, sn[8] = {}, sd[8] = {};
    std::vector<double> ratios[8];  // |16/15 mean Y| / sum of the channels' noise sd, |z| > 3
    for (const PointState& st : r.states()) {
      const PointEstimate e = estimate(st, r.passes(), double(r.options().photons_per_pass));
      int b = 0;
      while (st.photons >= edges[b + 1]) ++b;
      if (e.scale_z != 0.0) {
        sn[b] += 1;
        sd[b] += std::fabs(e.scale_z) > kSlopeZ;
        if (std::fabs(e.scale_z) > kSlopeZ) {
          const double sigma =
              std::sqrt(e.variance.x) + std::sqrt(e.variance.y) + std::sqrt(e.variance.z);
          ratios[b].push_back(std::fabs(16.0 / 15.0 * st.scale_mean) / sigma);
        }
      }
      for (int c = 0; c < 3; ++c) {
        const double z = e.slope_z[c];
        if (z == 0.0) continue;
        n[b] += 1;
        d[b] += std::fabs(z) > kSlopeZ;
        z2[b] += z * z;
        zs[b] += z;
      }
    }
    for (int b = 0; b < 7; ++b)
      if (n[b] > 0 || sn[b] > 0)
        std::printf("| %llu | %llu+ | %.0f | %.3f | %.2f | %.2f | %.0f | %.3f | %.2f |\n",
                    (unsigned long long)passes, (unsigned long long)edges[b], n[b],
                    n[b] > 0 ? d[b] / n[b] : 0.0, n[b] > 0 ? z2[b] / n[b] : 0.0,
                    n[b] > 0 ? zs[b] / n[b] : 0.0, sn[b], sn[b] > 0 ? sd[b] / sn[b] : 0.0,
                    median_of(ratios[b]));
  }
}

// Where the Cornell box's mean-error prediction falls short (ESTIMATOR.md section 6c):
// `pixels sppm SEEDS` renders it PB_STUDY_PASSES passes (default 240) per seed and, per pixel,
// sets the actual error against the reference beside the pixel's own error model: by the
// harmonic mean of its paths per pass (--adaptive paths), the sums of the actual |e| and of
// the folded-normal mean from its Bias and Variance channels (unshrunk; with the reference's
// variance added), and of e^2 against B^2 + Var; then the 12 pixels whose mean e^2 most
// exceeds that, with the mean over the seeds of e, the Laplacian's B and the two scales' B4.
void pixel_diagnostic(int seeds) {
  const reference::Truth truth =
      reference::load(std::string(PHOTONBOUND_REFERENCES) + "/cornell_64x64_sppm_reference.exr");
  const char* env = std::getenv("PB_STUDY_PASSES");
  const uint64_t passes = env ? uint64_t(std::atoll(env)) : 240;
  const size_t pixels = truth.value.size() / 3;
  const double edges[] = {1.5, 3.0, 6.0, 1e9};
  struct Bin {
    double n = 0, actual = 0, predicted = 0, with_ref = 0, e2 = 0, model_e2 = 0, ref_e2 = 0;
  } bins[4];
  struct Pixel {
    double paths = 0, e = 0, e2 = 0, model_e2 = 0, bias = 0, fourth = 0;
  };
  std::vector<Pixel> px(pixels);
  const double nu = double(passes - 1), t_var = nu / (nu - 2.0), w = 1.0 / seeds;
  for (int seed = 1; seed <= seeds; ++seed) {
    RenderOptions o = study_options("cornell.gltf", 64, passes);
    o.photons_per_pass = 2500;
    o.seed = uint64_t(seed) * 7919u;
    Renderer r(load_gltf(o.scene), o);
    while (r.passes() < passes) r.step();
    FilmImage img;
    r.develop(&img);
    const RenderState st = r.snapshot();
    for (size_t p = 0; p < pixels; ++p) {
      const double inv = st.path_history.empty() ? 0.0 : st.path_history[3 * p];
      const double k = inv > 0.0 ? double(passes) / inv : 1.0;
      const PointEstimate est = estimate(r.states()[p], passes, double(o.photons_per_pass));
      Bin& b = bins[std::find_if(edges, edges + 3, [&](double e) { return k <= e; }) - edges];
      b.n += w;
      px[p].paths += k * w;
      px[p].bias += est.bias.x * w;
      px[p].fourth += est.fourth.x * w;
      for (int c = 0; c < 3; ++c) {
        const size_t i = 3 * p + c;
        const double e = double(img.radiance[i]) - truth.value[i], v = img.variance[i];
        const double bias = img.bias[i], model_e2 = bias * bias + v;
        b.actual += std::fabs(e) * w;
        b.predicted += expected_abs_error(bias, std::sqrt(v * t_var)) * w;
        b.with_ref += expected_abs_error(bias, std::sqrt(v * t_var + truth.variance[i])) * w;
        b.e2 += e * e * w;
        b.model_e2 += model_e2 * w;
        b.ref_e2 += truth.variance[i] * w;
        px[p].e2 += e * e * w;
        px[p].model_e2 += (model_e2 + truth.variance[i]) * w;
        if (c == 0) px[p].e += e * w;
      }
    }
  }
  std::printf(
      "| paths | pixels | actual / predicted | with the reference's variance | e^2 / model | "
      "with the reference's |\n|---|---|---|---|---|---|\n");
  for (const Bin& b : bins)
    if (b.n > 0)
      std::printf("| <= %g | %.0f | %.3f | %.3f | %.3f | %.3f |\n", edges[&b - bins], b.n,
                  b.actual / b.predicted, b.actual / b.with_ref, b.e2 / b.model_e2,
                  b.e2 / (b.model_e2 + b.ref_e2));
  std::vector<size_t> order(pixels);
  for (size_t p = 0; p < pixels; ++p) order[p] = p;
  auto excess = [&](size_t p) { return px[p].e2 - px[p].model_e2; };
  std::partial_sort(order.begin(), order.begin() + 12, order.end(),
                    [&](size_t a, size_t b) { return excess(a) > excess(b); });
  std::printf(
      "\n| pixel | paths | mean e (R) | B | B4 | excess e^2 |\n|---|---|---|---|---|---|\n");
  for (size_t j = 0; j < 12; ++j) {
    const Pixel& q = px[order[j]];
    std::printf("| %zu, %zu | %.2f | %.4f | %.4f | %.4f | %.4f |\n", order[j] % 64, order[j] / 64,
                q.paths, q.e, q.bias, q.fourth, excess(order[j]));
  }
}

int main(int argc, char** argv) {
  const std::string which = argc > 1 ? argv[1] : "all";
  if (argc > 2 && std::string(argv[2]) == "sppm") g_method = Method::SPPM;
  if (which == "all" || which == "coverage") coverage_table();
  if (which == "all" || which == "termination") termination_table();
  if (which == "all" || which == "stopping") stopping_table();
  if (which == "correlation") correlation_table();
  if (which == "slope") slope_experiment();
  if (which == "modelcheck") modelcheck_experiment();
  if (which == "modelnull") modelnull_experiment();
  if (which == "modelfile") modelfile_experiment();
  if (which == "all" || which == "edges") edges_table();
  if (which == "all" || which == "cornell") cornell_table(argc > 3 ? std::atoi(argv[3]) : 4);
  if (which == "pixels") pixel_diagnostic(argc > 3 ? std::atoi(argv[3]) : 16);
  if (which == "calibration") calibration_table(argc > 3 ? std::atoi(argv[3]) : 20);
  if (which == "all" || which == "rules") {
    const int seeds = argc > 3 ? std::atoi(argv[3]) : 20;
    rules_table(seeds, argc > 4 ? std::atoi(argv[4]) : seeds);
  }
  return 0;
}
