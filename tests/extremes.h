// Shared helpers of the extremes suite (test_extremes.cpp, test_slow_extremes.cpp): variants of the
// shipped scenes written into a temporary directory by editing their glTF text, renders kept
// alive with their scene, and the sanity checks every extreme case asserts (finite channels, +inf
// bounds exactly where a point never received a photon, positive radii at or above the floor).
#pragma once

#include "analytic.h"
#include "pass_sample.h"
#include "render_fixture.h"

#include "estimator/estimator.h"
#include "estimator/film.h"
#include "estimator/kernel.h"
#include "options/options.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

namespace pb::extremes {

namespace fs = std::filesystem;

// A directory under the system temporary directory, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    path_ = fs::temp_directory_path() /
            ("photonbound_extremes_" + name + "_" + std::to_string(std::random_device{}()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

 private:
  fs::path path_;
};

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Edits of a glTF document's JSON text. The shipped scenes are generated (tools/make_scenes.py),
// so the members edited here are known to exist; a missing one fails the test loudly.
class GltfText {
 public:
  explicit GltfText(std::string text) : t_(std::move(text)) {}
  static GltfText shipped(const std::string& name) {
    return GltfText(read_text(test::scene_path(name)));
  }
  const std::string& text() const { return t_; }

  // Replaces the elements of the array member `key` (the first after `anchor`).
  GltfText& set_array(const std::string& anchor, const std::string& key,
                      const std::string& elements) {
    const size_t open = array_open(anchor_pos(anchor), key);
    const size_t close = matching(open);
    t_.replace(open + 1, close - open - 1, elements);
    return *this;
  }
  // Replaces the number of member `key` (the first after `anchor`).
  GltfText& set_number(const std::string& anchor, const std::string& key, double v) {
    const size_t k = find(("\"" + key + "\""), anchor_pos(anchor));
    const size_t colon = find(":", k);
    const size_t begin = t_.find_first_not_of(" \n\t", colon + 1);
    const size_t end = t_.find_first_of(",}]\n ", begin);
    t_.replace(begin, end - begin, number_text(v));
    return *this;
  }
  // Appends an element to the array member `key` (the first after `anchor`) and returns the
  // index it gets.
  int append(const std::string& anchor, const std::string& key, const std::string& element) {
    return append_at(anchor_pos(anchor), key, element);
  }
  // Puts the whole scene under one new root node with a uniform scale s.
  GltfText& scale_scene(double s) {
    const size_t roots_open = array_open(find("\"scenes\""), "nodes");
    const std::string roots = t_.substr(roots_open + 1, matching(roots_open) - roots_open - 1);
    const std::string n = number_text(s);
    const int root = append_at(top_level_nodes(), "nodes",
                               "{\"name\":\"extremes_scale\",\"scale\":[" + n + "," + n + "," + n +
                                   "],\"children\":[" + roots + "]}");
    return set_array("\"scenes\"", "nodes", std::to_string(root));
  }
  // Adds a node at the root of scene 0 and returns its index.
  int add_root_node(const std::string& node) {
    const int index = append_at(top_level_nodes(), "nodes", node);
    append("\"scenes\"", "nodes", std::to_string(index));
    return index;
  }

 private:
  size_t find(const std::string& what, size_t from = 0) const {
    const size_t p = t_.find(what, from);
    if (p == std::string::npos) throw std::runtime_error("glTF text: '" + what + "' not found");
    return p;
  }
  size_t anchor_pos(const std::string& anchor) const { return anchor.empty() ? 0 : find(anchor); }
  size_t array_open(size_t from, const std::string& key) const {
    const size_t k = find("\"" + key + "\"", from);
    const size_t open = find("[", k);
    return open;
  }
  // The bracket closing the one at `open` (no brackets occur inside the scenes' strings).
  size_t matching(size_t open) const {
    int depth = 0;
    for (size_t i = open; i < t_.size(); ++i) {
      if (t_[i] == '[' || t_[i] == '{') ++depth;
      if (t_[i] == ']' || t_[i] == '}') {
        if (--depth == 0) return i;
      }
    }
    throw std::runtime_error("glTF text: unbalanced brackets");
  }
  // Number of elements of the array [open, close].
  int items(size_t open, size_t close) const {
    int depth = 0, count = 0;
    bool content = false;
    for (size_t i = open + 1; i < close; ++i) {
      const char c = t_[i];
      if (c == '[' || c == '{') ++depth;
      if (c == ']' || c == '}') --depth;
      if (depth == 0 && c == ',') ++count;
      if (c != ' ' && c != '\n' && c != '\t') content = true;
    }
    return content ? count + 1 : 0;
  }
  int append_at(size_t from, const std::string& key, const std::string& element) {
    const size_t open = array_open(from, key);
    const size_t close = matching(open);
    const int count = items(open, close);
    t_.insert(close, (count ? "," : "") + element);
    return count;
  }
  // The top-level "nodes" member is the first one after the "scenes" array.
  size_t top_level_nodes() const { return matching(array_open(find("\"scenes\""), "scenes")); }

  std::string t_;
};

// A scene loaded and a renderer on it (the renderer refers to the scene).
struct Render {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<Renderer> r;
  Render(const std::string& path, const RenderOptions& o)
      : scene(std::make_unique<Scene>(load_gltf(path))), r(std::make_unique<Renderer>(*scene, o)) {}
  void passes(uint64_t n) {
    while (r->passes() < n) r->step();
  }
  // The floor of R^2, computed exactly as the renderer does.
  double min_r2() const {
    const double r_min = 1e-6 * double(r->world().scene_size());
    return r_min * r_min;
  }
};

// Options for an extremes render: photons only (so that the plane has photons to estimate),
// one thread count independent image, no progress.
inline RenderOptions options(const std::string& scene_path, int size, uint64_t photons) {
  RenderOptions o;
  o.method = Method::PPM;  // the suite inspects visible points
  o.scene = scene_path;
  o.output = "unused.exr";
  o.width = o.height = size;
  o.passes = 1;
  o.photons_per_pass = photons;
  o.direct = DirectMode::Photons;
  o.progress = ProgressMode::Never;
  return o;
}

// What check_film found.
struct FilmCounts {
  size_t pixels = 0, with_points = 0, unknown = 0, variance_overflow = 0;
};

// Develops the render and asserts the channel contract of docs/usage.md "Output": radiance, bias,
// photons and radius finite; bound and noise finite and >= 0 where known, +inf on all three
// channels exactly before the second pass (from then on a point with few or no photons has the
// sparse-photon bound of ESTIMATOR.md section 12) and where the bias model is refuted; radius > 0
// where the pixel has points. The Variance channel is float32: with allow_variance_overflow a
// channel may be +inf where the double variance exceeds FLT_MAX (the noise channel stays finite).
inline FilmCounts check_film(const Renderer& r, const FilmSettings& s, FilmImage* out = nullptr,
                             FilmSummary* summary_out = nullptr,
                             bool allow_variance_overflow = false) {
  FilmImage img;
  const PixelLayout layout = r.layout();
  const FilmSummary summary = develop(layout, r.states(), r.passes(), s, &img);
  const CameraPassResult& eye = r.camera_pass();
  FilmCounts c;
  c.pixels = size_t(eye.width) * size_t(eye.height);
  for (size_t p = 0; p < c.pixels; ++p) {
    const uint32_t b = eye.pixel_begin[p], e = eye.pixel_begin[p + 1];
    // A refuted bias model (ESTIMATOR.md sections 11b, 11c) leaves every pixel with points
    // unknown.
    bool unknown = b != e && (r.passes() < 2 || summary.model_refuted);
    for (uint32_t k = b; k < e; ++k) unknown = unknown || layout.mass[k] < kValidKernelMass;
    c.with_points += b != e;
    c.unknown += unknown;
    for (int ch = 0; ch < 3; ++ch) {
      const size_t i = 3 * p + size_t(ch);
      EXPECT_TRUE(std::isfinite(img.radiance[i]))
          << "pixel " << p << " radiance " << img.radiance[i];
      EXPECT_TRUE(std::isfinite(img.bias[i])) << "pixel " << p << " bias " << img.bias[i];
      if (unknown) {
        EXPECT_EQ(img.bound[i], INFINITY) << "pixel " << p << " is unknown";
        EXPECT_EQ(img.noise[i], INFINITY) << "pixel " << p << " is unknown";
      } else {
        EXPECT_TRUE(std::isfinite(img.bound[i]) && img.bound[i] >= 0.0f)
            << "pixel " << p << " bound " << img.bound[i];
        EXPECT_TRUE(std::isfinite(img.noise[i]) && img.noise[i] >= 0.0f)
            << "pixel " << p << " noise " << img.noise[i];
      }
      if (std::isinf(img.variance[i]) && allow_variance_overflow && !unknown &&
          std::isfinite(img.noise[i])) {
        ++c.variance_overflow;
      } else {
        EXPECT_TRUE(std::isfinite(img.variance[i]) && img.variance[i] >= 0.0f)
            << "pixel " << p << " variance " << img.variance[i];
      }
    }
    EXPECT_TRUE(std::isfinite(img.photons[p]) && img.photons[p] >= 0.0f);
    if (b != e)
      EXPECT_TRUE(std::isfinite(img.radius[p]) && img.radius[p] > 0.0f)
          << "pixel " << p << " radius " << img.radius[p];
    else
      EXPECT_EQ(img.radius[p], 0.0f);
  }
  EXPECT_EQ(summary.unknown_pixels, c.unknown);
  if (out) *out = std::move(img);
  if (summary_out) *summary_out = summary;
  return c;
}

// Every point's statistics finite, its radius positive and at or above the floor.
inline void check_states(const Render& run) {
  const double floor = run.min_r2();
  for (size_t k = 0; k < run.r->states().size(); ++k) {
    const PointState& s = run.r->states()[k];
    ASSERT_TRUE(std::isfinite(s.r2) && s.r2 > 0.0 && s.r2 >= floor)
        << "point " << k << " R^2 " << s.r2;
    ASSERT_TRUE(std::isfinite(s.n) && s.n >= 0.0) << "point " << k << " N " << s.n;
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(std::isfinite(s.tau[c]) && std::isfinite(s.tau_lap[c])) << "point " << k;
      ASSERT_TRUE(std::isfinite(s.c_xx[c]) && std::isfinite(s.c_xr[c])) << "point " << k;
    }
  }
}

// The mean bound over known pixel-channels at the given confidence.
inline double mean_bound(const Renderer& r, double confidence) {
  FilmSettings s = r.film_settings();
  s.confidence = confidence;
  return develop(r.camera_pass(), r.states(), r.passes(), s, nullptr).mean_bound;
}

// A synthetic visible point on a uniform photon density, driven through the estimator of
// estimator.h: in pass j, Poisson(mu0 R_j^2 / R_0^2) photons land in the point's disc, uniformly
// (t = sqrt(u)), each of power pi / mu0 with f = 1 and M_e = 1, R_0 = 1. The exact radiance is 1
// and the true bias 0 (ESTIMATOR.md section 3: E[w] = 1 over the disc). mu0 << 1 makes a point
// that receives a photon only once in 1 / mu0 passes (a rare caustic path).
struct UniformPoint {
  PointState state;
  uint64_t passes = 0;
  uint64_t last_photon_pass = 0;  // 0 = none yet
  UniformPoint() { state.r2 = 1.0; }
  void step(std::mt19937_64& rng, double mu0, const EstimatorParams& params) {
    PassSample g;
    const double mu = mu0 * state.r2;
    const uint64_t m = mu > 0.0 ? std::poisson_distribution<uint64_t>(mu)(rng) : 0;
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    for (uint64_t k = 0; k < m; ++k) {
      const double t = std::sqrt(u01(rng));
      const double phi = kPiD / mu0;
      g.phi += dvec3(kernel::weight(t) * phi);
      g.phi_lap_r2 += dvec3(kernel::laplacian_weight_r2(t) * phi);
    }
    g.count = m;
    ++passes;
    if (m) last_photon_pass = passes;
    accumulate_pass(state, g, params, passes);
  }
};

// The bound a one-point pixel reports (film.cpp: the exact quantile of |B + noise|).
inline double point_bound(const PointEstimate& e, const BoundQuantile& q) {
  return q(e.bias.x, std::sqrt(e.variance.x));
}

// Coverage of the rare-arrival synthetic (UniformPoint with mu0 << 1): `points` independent
// points, checked at each pass count of `checks` (ascending) at 50% and 90%. Prints one line per
// check and confidence and asserts, at every check:
//  - unknown (+inf) exactly where no photon arrived: the fraction matches exp(-mu0 i) (the radius
//    cannot shrink before the first photon) within 4 sigma;
//  - no point is reported as converged: every known bound is at least t_{i-1,(1+c)/2} L / sqrt(k)
//    for a point that received k photons, the relative precision k photons can give, however long
//    the streak of empty passes since the last one;
//  - coverage among known points does not collapse: >= min_coverage_90 at 90%, >= 0.45 at 50%.
struct RareRow {
  uint64_t passes;
  double confidence, unknown, coverage, coverage_k5, streak_coverage;
  long known, known_k5, streak;
};
inline std::vector<RareRow> rare_arrivals(int points, double mu0,
                                          const std::vector<uint64_t>& checks,
                                          double min_coverage_90, uint64_t seed) {
  EstimatorParams params;
  params.alpha = 0.7;
  params.photons_per_pass = 1.0;
  params.min_r2 = 1e-12;
  std::mt19937_64 rng(seed);
  std::vector<UniformPoint> pts{size_t(points)};
  std::vector<RareRow> rows;
  for (uint64_t check : checks) {
    while (pts[0].passes < check)
      for (UniformPoint& p : pts) p.step(rng, mu0, params);
    for (double conf : {0.5, 0.9}) {
      const BoundQuantile q(double(check - 1), conf);
      long unknown = 0, known = 0, covered = 0, known5 = 0, covered5 = 0, streak = 0,
           streak_covered = 0;
      for (const UniformPoint& p : pts) {
        const PointEstimate e = estimate(p.state, check, 1.0);
        EXPECT_EQ(e.known, p.state.photons >= kMinPhotonsForBound);
        if (!e.known) {
          ++unknown;
          continue;
        }
        const double b = point_bound(e, q);
        const double k = double(p.state.photons);
        EXPECT_TRUE(std::isfinite(b));
        EXPECT_GE(b, 0.999 * q.two_sided_t() * e.radiance.x / std::sqrt(k))
            << "a point with " << k << " photons, the last " << check - p.last_photon_pass
            << " passes ago, reports a bound tighter than its photons allow";
        const bool c = std::fabs(e.radiance.x - 1.0) <= b;
        ++known;
        covered += c;
        if (k >= 5) {
          ++known5;
          covered5 += c;
        }
        if (check - p.last_photon_pass >= 1000) {
          ++streak;
          streak_covered += c;
        }
      }
      RareRow row{check,
                  conf,
                  double(unknown) / points,
                  double(covered) / double(std::max(known, 1L)),
                  double(covered5) / double(std::max(known5, 1L)),
                  double(streak_covered) / double(std::max(streak, 1L)),
                  known,
                  known5,
                  streak};
      std::printf(
          "rare arrivals (mu0 %g), %6llu passes, %2.0f%%: unknown %.3f (exp(-mu0 i) %.3f), "
          "coverage of known %.3f (%ld), of those with >= 5 photons %.3f (%ld), of those 1000+ "
          "passes since their last photon %.3f (%ld)\n",
          mu0, (unsigned long long)check, 100 * conf, row.unknown, std::exp(-mu0 * double(check)),
          row.coverage, known, row.coverage_k5, known5, row.streak_coverage, streak);
      // Unknown = fewer than kMinPhotonsForBound photons. The arrival rate only falls as the
      // radius shrinks, so the count is stochastically below Poisson(mu0 i): the unknown fraction
      // is at least the Poisson probability of fewer than that many, and at least exp(-mu0 i).
      const double m = mu0 * double(check);
      double p_few = 0.0, term = std::exp(-m);
      for (uint64_t k = 0; k < kMinPhotonsForBound; ++k, term *= m / double(k)) p_few += term;
      EXPECT_GE(row.unknown, p_few - 4.0 * std::sqrt(p_few * (1.0 - p_few) / points) - 1e-9);
      if (known >= 50) EXPECT_GE(row.coverage, conf > 0.7 ? min_coverage_90 : 0.45);
      rows.push_back(row);
    }
  }
  return rows;
}

// One photon in pass j0, then only empty passes: the point never reports a bound at all (fewer
// than kMinPhotonsForBound photons), so an empty streak can never make it look converged.
inline void single_photon_then_zeros(uint64_t j0, double t, const std::vector<uint64_t>& checks) {
  EstimatorParams params;
  params.alpha = 0.7;
  params.photons_per_pass = 1.0;
  PointState s;
  s.r2 = 1.0;
  size_t next = 0;
  for (uint64_t j = 1; j <= checks.back(); ++j) {
    PassSample g;
    if (j == j0) {
      g.count = 1;
      g.phi = dvec3(kernel::weight(t) * 1000.0);
      g.phi_lap_r2 = dvec3(kernel::laplacian_weight_r2(t) * 1000.0);
    }
    accumulate_pass(s, g, params, j);
    while (next < checks.size() && checks[next] < j) ++next;
    if (next == checks.size() || checks[next] != j) continue;
    EXPECT_FALSE(estimate(s, j, 1.0).known)
        << "photon at pass " << j0 << " t " << t << ", pass " << j;
  }
}

// Renders the plane with one photon per pass and checks after every pass that each point's
// N and R^2 changed exactly as ESTIMATOR.md section 3 says (N += alpha M_j, R^2 *= (N + alpha
// M_j) / (N + M_j), floored), that R^2 strictly falls whenever a photon arrived above the floor
// (no freeze), and that photons are counted in 64 bits.
inline void one_photon_per_pass(uint64_t passes) {
  static_assert(std::is_same_v<decltype(PointState::photons), uint64_t>);
  static_assert(std::is_same_v<decltype(WorkCounters::photons), uint64_t>);
  RenderOptions o = options(test::scene_path("plane_point.gltf"), 4, 1);
  o.passes = passes;
  o.adaptive_radius = false;  // HOJ08's update itself, checked exactly below
  Render run(o.scene, o);
  const double alpha = o.alpha, floor = run.min_r2();
  const size_t n = run.r->states().size();
  ASSERT_EQ(n, 16u);
  const double report_radius = std::sqrt(run.r->states()[0].r2);
  std::vector<PointState> prev = run.r->states();
  uint64_t arrivals = 0, shrinks = 0;
  for (uint64_t pass = 1; pass <= passes; ++pass) {
    run.r->step();
    for (size_t k = 0; k < n; ++k) {
      const PointState& s = run.r->states()[k];
      const PointState& b = prev[k];
      ASSERT_GE(s.photons, b.photons);
      const double m = double(s.photons - b.photons);
      ASSERT_EQ(s.n, b.n + alpha * m) << "pass " << pass << " point " << k;
      const double expected =
          m > 0 ? std::max(b.r2 * ((b.n + alpha * m) / (b.n + m)), floor) : b.r2;
      ASSERT_EQ(s.r2, expected) << "pass " << pass << " point " << k;
      ASSERT_GT(s.r2, 0.0);
      if (m > 0) {
        ++arrivals;
        if (b.r2 > floor) {
          ASSERT_LT(s.r2, b.r2) << "pass " << pass << " point " << k << ": R^2 froze";
          ++shrinks;
        }
      }
      prev[k] = s;
    }
  }
  check_states(run);
  FilmImage img;
  FilmSummary summary;
  const FilmCounts c = check_film(*run.r, run.r->film_settings(), &img, &summary);
  const analytic::Accuracy a = analytic::measure(*run.r, analytic::plane_point, 0.9);
  uint64_t min_photons = UINT64_MAX, max_photons = 0;
  double r_min = INFINITY, r_max = 0.0;
  for (const PointState& s : run.r->states()) {
    min_photons = std::min(min_photons, s.photons);
    max_photons = std::max(max_photons, s.photons);
    r_min = std::min(r_min, std::sqrt(s.r2));
    r_max = std::max(r_max, std::sqrt(s.r2));
  }
  EXPECT_EQ(c.unknown, 0u);
  std::printf(
      "1 photon per pass, %llu passes on 4x4: %llu arrivals, each shrinking R; photons "
      "per point %llu..%llu; R from %.4g to %.4g..%.4g; unknown %zu; mean error %.4g, "
      "mean bound %.4g, coverage at 90%% %.3f\n",
      (unsigned long long)passes, (unsigned long long)arrivals, (unsigned long long)min_photons,
      (unsigned long long)max_photons,
      run.r->camera_pass().points.empty() ? 0.0 : double(report_radius), r_min, r_max, c.unknown,
      a.mean_abs_error, a.mean_bound, a.coverage);
  EXPECT_EQ(arrivals, shrinks);                           // the floor is never reached here
  const RenderReport report = test::run_to_stop(*run.r);  // passes already done: no new pass
  EXPECT_EQ(report.work.passes, passes);
  EXPECT_EQ(report.work.photons, passes);
}

// PHOTONBOUND_FULL_EXTREMES=1 selects the full issue-sized runs (10^6 passes).
inline bool full_extremes() {
  const char* v = std::getenv("PHOTONBOUND_FULL_EXTREMES");
  return v && std::string(v) == "1";
}

}  // namespace pb::extremes
