// SPPM's camera paths through rough GGX lobes (--follow-roughness, camera_paths.h): a followed
// lobe must estimate the same image as photons gathered at the lobe, count its direct light
// once, and turn the sparse-photon bound of a sharp lobe (ESTIMATOR.md section 12) into the
// bound of the diffuse surfaces it reflects. PassOver.*: a camera path passes over a visible
// point whose disc lies almost wholly off reachable surface, so that no pixel stays unknown.
#include "render/renderer.h"

#include "analytic.h"
#include "render_fixture.h"
#include "scene_builder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace pb {
namespace {

// A closed room [-1, 1]^3 seen from inside, walls of reflectance 0.6 (the left one reddish),
// a floor of the given material, a point light and an emitting panel under the ceiling: the
// floor reflects the lit walls and the panel.
// With `strip`, a white strip 0.0005 wide and 1.2 long hangs 0.45 above the floor, in view and
// in the floor's reflection: at the default radius (about 0.2 here) its kernel discs have a mass
// of about 0.003 on it, below kValidKernelMass.
Scene room(const Material& floor, bool panel = true, bool strip = false) {
  test::SceneBuilder b;
  const uint32_t wall = b.material(vec3(0.6f)), red = b.material(vec3(0.7f, 0.2f, 0.2f));
  Material f = floor;
  f.name = "floor";
  b.scene.materials.push_back(f);
  const uint32_t fl = uint32_t(b.scene.materials.size() - 1);
  // quad(c, u, v): front side u x v, here toward the inside.
  b.quad(vec3(0, -1, 0), vec3(0, 0, 1), vec3(1, 0, 0), fl);    // floor, +y
  b.quad(vec3(0, 1, 0), vec3(1, 0, 0), vec3(0, 0, 1), wall);   // ceiling, -y
  b.quad(vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1), red);   // left, +x
  b.quad(vec3(1, 0, 0), vec3(0, 0, 1), vec3(0, 1, 0), wall);   // right, -x
  b.quad(vec3(0, 0, -1), vec3(1, 0, 0), vec3(0, 1, 0), wall);  // back, +z
  b.quad(vec3(0, 0, 1), vec3(0, 1, 0), vec3(1, 0, 0), wall);   // front, -z
  // An emitting panel just under the ceiling, facing down: the floor's lobe reflects it.
  if (panel) {
    const uint32_t lamp = b.material(vec3(0.0f), vec3(4.0f));
    b.quad(vec3(-0.3f, 0.98f, -0.4f), vec3(0.25f, 0, 0), vec3(0, 0, 0.25f), lamp);
  }
  if (strip) b.quad(vec3(0, -0.55f, -0.3f), vec3(0.6f, 0, 0), vec3(0, 0, 0.00025f), wall);
  b.point_light(vec3(0.3f, 0.7f, -0.2f), vec3(2.0f));
  b.camera(vec3(0, 0.2f, 0.95f), vec3(0, -1, -0.4f), 1.0f);
  return b.scene;
}

RenderOptions sppm(double follow, uint64_t passes) {
  RenderOptions o;
  o.method = Method::SPPM;
  o.width = o.height = 40;
  o.passes = passes;
  o.photons_per_pass = 20000;
  o.follow_roughness = follow;
  o.progress = ProgressMode::Never;
  return o;
}

struct Result {
  double mean = 0.0;       // over pixels and channels
  double mean_bias = 0.0;  // the mean of the signed bias estimates, the same way
  double mean_var = 0.0;   // variance of `mean` from the pixels' own variances
  FilmSummary summary;
  double max_bound = 0.0;
};

// Two estimates of one image: the difference of their bias-corrected image means over its
// standard deviation. Each image mean's variance is the sum of its pixels' variances of the
// mean times the correlated pixels K (FilmSummary): that is what the renderer predicts for it.
double agreement_z(const Result& a, const Result& b) {
  return ((a.mean - a.mean_bias) - (b.mean - b.mean_bias)) / std::sqrt(a.mean_var + b.mean_var);
}

Result render(const Scene& scene, const RenderOptions& o) {
  Renderer r(scene, o);
  test::run_to_stop(r);
  FilmImage img;
  Result out;
  out.summary = r.develop(&img);
  const double n = double(img.radiance.size());
  for (float v : img.radiance) out.mean += v / n;
  for (float v : img.bias) out.mean_bias += v / n;
  for (float v : img.variance) out.mean_var += v / (n * n);
  // Neighbouring pixels share photons: K of them move together (FilmSummary).
  out.mean_var *= out.summary.correlated_pixels;
  for (float v : img.bound) out.max_bound = std::max(out.max_bound, double(v));
  return out;
}

TEST(FollowLobe, FollowedAndGatheredLobesEstimateTheSameImage) {
  // A rough metal floor (roughness 0.45) and a glossy dielectric one (0.35), where photons
  // gathered at the lobe still converge, rendered both ways after 96 passes: the two image
  // means agree within 4 standard deviations of their difference (agreement_z). Measured z =
  // -0.01 and -0.31. Counting the light a followed lobe's ray finds directly on top of its
  // next-event sample (the panel's reflection twice) gave z = 37 and 5.7.
  for (const Material& floor :
       {Material::metal(vec3(0.9f, 0.8f, 0.6f), 0.45f), [] {
          Material m = Material::metal(vec3(0.5f, 0.6f, 0.7f), 0.35f);
          m.metallic = 0.0f;  // a glossy dielectric: the base is gathered, the lobe followed
          return m;
        }()}) {
    const Scene scene = room(floor);
    const Result gathered = render(scene, sppm(0.0, 96)), followed = render(scene, sppm(0.5, 96));
    const double z = agreement_z(followed, gathered);
    std::printf(
        "metallic %.0f: image mean %.5f gathered, %.5f followed, sd of the difference "
        "%.5f, z %.2f\n",
        floor.metallic, gathered.mean, followed.mean,
        std::sqrt(gathered.mean_var + followed.mean_var), z);
    EXPECT_LT(std::fabs(z), 4.0) << "metallic " << floor.metallic;
    EXPECT_EQ(followed.summary.unknown_pixels, 0u);
  }
}

TEST(FollowLobe, ASharpLobeIsBoundedByWhatItReflects) {
  // A polished metal floor (roughness 0.12, alpha 0.014: the lobe's peak f is about 20x a
  // white Lambertian's at normal incidence, and far more toward grazing): gathered at the lobe,
  // few of the photons in its disc arrive inside its cone and the bound falls slowly; followed,
  // the floor's pixels see the lit walls through the lobe and take the walls' bound. Measured
  // after 48 passes: mean bound 0.148 gathered, 0.030 followed (5.0x); the assertion asks for
  // 3x, and for the same image as above (|z| < 4).
  // Without the panel: its reflection in the lobe is next-event light through a peaked f
  // either way (with the panel the ratio is 2.5x).
  const Scene scene = room(Material::metal(vec3(0.4f, 0.5f, 0.6f), 0.12f), false);
  const Result gathered = render(scene, sppm(0.0, 48)), followed = render(scene, sppm(0.5, 48));
  std::printf("mean bound %.4g gathered, %.4g followed; image mean %.5f and %.5f, z %.2f\n",
              gathered.summary.mean_bound, followed.summary.mean_bound, gathered.mean,
              followed.mean, agreement_z(followed, gathered));
  EXPECT_LT(3.0 * followed.summary.mean_bound, gathered.summary.mean_bound);
  EXPECT_LT(std::fabs(agreement_z(followed, gathered)), 4.0);
  EXPECT_EQ(followed.summary.unknown_pixels, 0u);
}

TEST(PassOver, AStripFarNarrowerThanTheRadiusIsSeenThroughPaths) {
  // A visible point on the strip has almost all of its disc off the surface (mass about 0.003):
  // no photon estimate is sound there, and a pixel that had one stayed unknown for good (its
  // validity is the least mass over its passes). The camera path passes over such a point
  // (next-event light there, one direction drawn from its Bsdf, the gather where it lands), so
  // no pixel is unknown, whether the floor's lobe is gathered or followed onto the strip, and
  // both ways estimate the same image (|z| < 4, as above). Before the pass-over, 39 pixels
  // ended unknown gathered and 92 followed (measured at 32 passes).
  const Scene scene = room(Material::metal(vec3(0.9f, 0.8f, 0.6f), 0.3f), true, true);
  const Result gathered = render(scene, sppm(0.0, 32)), followed = render(scene, sppm(0.5, 32));
  const double z = agreement_z(followed, gathered);
  std::printf("strip: unknown %zu gathered, %zu followed; image mean %.5f and %.5f, z %.2f\n",
              size_t(gathered.summary.unknown_pixels), size_t(followed.summary.unknown_pixels),
              gathered.mean, followed.mean, z);
  EXPECT_EQ(gathered.summary.unknown_pixels, 0u);
  EXPECT_EQ(followed.summary.unknown_pixels, 0u);
  EXPECT_LT(std::fabs(z), 4.0);
}

TEST(PassOver, AtTheDepthLimitThePathGoesOnByRoulette) {
  // At --max-depth 0 every camera path ends at its first vertex, so a pixel that sees the strip
  // met its thin disc there. A pass-over at the limit used to keep that point, and the pixel
  // stayed unknown for good; it now goes on by Russian roulette (1/2, weight 2) to the surface
  // behind (ESTIMATOR.md section 10), so no pixel is unknown after 64 passes (the strip covers
  // about 1% of the pixels it crosses, so their jittered paths meet it in a few passes of 64).
  // Keeping the point, as before, leaves 12 pixels unknown here (measured).
  RenderOptions o = sppm(0.0, 64);
  o.max_depth = 0;
  Scene scene = room(Material::lambertian(vec3(0.5f)), true, true);
  // The camera sees the strip from above, its back: double-sided, so that the camera's first
  // ray does not pass through it (glTF's back-face culling, World::camera_hit).
  for (Material& m : scene.materials)
    if (!m.emits()) m.double_sided = true;
  const Result r = render(scene, o);
  std::printf("strip at --max-depth 0: unknown %zu of 1600\n", size_t(r.summary.unknown_pixels));
  EXPECT_EQ(r.summary.unknown_pixels, 0u);
  EXPECT_TRUE(std::isfinite(r.max_bound));
}

TEST(PassOver, ASharpLobeAtTheDepthLimitIsFollowedNotGathered) {
  // At --max-depth 0 every camera path's first vertex is at the limit. A metal floor of
  // roughness 0.1 gathered there with its whole Bsdf gives its pixels the lobe's peak f (about
  // 1/(pi alpha^2) = 3183 here) as the sparse-photon bound's f (ESTIMATOR.md section 12); split
  // off and followed by roulette, the floor's pixels gather where the lobe leads (the
  // Lambertian walls), so no pixel keeps a glossy cap f / c above 1 (the floor gathers nothing:
  // 0), where the peak over a disc of full mass would be 3183. The image stays an
  // estimate of the same light: within 4 sd of a render at --max-depth 8, whose only extra light
  // is what depth-1+ delta chains would add (there are none in this room).
  RenderOptions o = sppm(kDefaultFollowRoughness, 32);
  o.max_depth = 0;
  const Scene scene = room(Material::metal(vec3(0.9f, 0.8f, 0.6f), 0.1f));
  Renderer r(scene, o);
  for (uint64_t p = 0; p < 32; ++p) r.step();
  const PixelLayout l = r.layout();
  float largest = 0.0f;
  for (float f_over_c : l.glossy_f) largest = std::max(largest, f_over_c);
  std::printf("sharp lobe at --max-depth 0: largest glossy f / c %.3g\n", double(largest));
  EXPECT_LT(largest, 1.0f);
  const Result limited = render(scene, o);
  RenderOptions deep = o;
  deep.max_depth = 8;
  const Result full = render(scene, deep);
  const double z = agreement_z(limited, full);
  std::printf("  image mean %.5f (depth 0) and %.5f (depth 8), z %.2f\n", limited.mean, full.mean,
              z);
  EXPECT_LT(std::fabs(z), 4.0);
}

TEST(PassOver, AFollowedRenderStopsOnItsTarget) {
  // The same room at the default --follow-roughness: a pixel whose followed lobe reaches the
  // strip used to stay unknown for good, so --target-error alone could not end (it was refused
  // without --passes or --time). Now the target stops the render, with every bound finite,
  // long before the pass cap that keeps this test from hanging if it did not.
  RenderOptions o = sppm(kDefaultFollowRoughness, 3000);
  o.target_error = 0.02;
  Renderer r(room(Material::metal(vec3(0.9f, 0.8f, 0.6f), 0.3f), true, true), o);
  const RenderReport report = test::run_to_stop(r);
  std::printf("target 0.02: stopped after %llu passes (%s), %zu unknown pixels\n",
              (unsigned long long)report.work.passes, stop_text(report.stop).c_str(),
              size_t(report.summary.unknown_pixels));
  EXPECT_EQ(report.stop, StopReason::TargetError);
  EXPECT_EQ(report.summary.unknown_pixels, 0u);
  EXPECT_TRUE(std::isfinite(report.summary.predicted_error_upper));
}

TEST(FollowLobe, GlossyPlaneUnderNextEventLightKeepsItsCoverage) {
  // glossy_plane.gltf (roughness 0.4, metallic 0.5) under a point light with next-event direct
  // light, against its exact answer analytic::glossy_plane: every pixel's path follows the lobe
  // or stops at the base each pass, after the vertex's next-event sample with the whole Bsdf.
  // Only direct light exists, so a wrong weight or a direct light counted at the base point as
  // well shows as bias the bound does not cover (a first version that kept a Lambertian point
  // where the lobe's draw failed had mean error 0.14 and 50% coverage 0.08 after 256 passes).
  // Next-event bounds over-cover this scene with or without following (measured 0.80 / 0.99
  // and 0.71 / 0.98 at 50% / 90% after 16 and 64 passes: the point light's sample has no
  // noise), so the criterion is one-sided: at least nominal minus 3 points (4096 pixels).
  RenderOptions o = test::quick_options("glossy_plane.gltf", 64, 64);
  o.method = Method::SPPM;
  o.direct = DirectMode::NextEvent;
  o.follow_roughness = 0.5;
  for (const auto& r : analytic::coverage_run("glossy", o, {16, 64}, {0.5, 0.9})) {
    std::printf("%3llu passes, %.0f%%: coverage %.3f, mean error %.5f, mean bound %.5f\n",
                (unsigned long long)r.passes, 100.0 * r.confidence, r.accuracy.coverage,
                r.accuracy.mean_abs_error, r.accuracy.mean_bound);
    EXPECT_GE(r.accuracy.coverage, r.confidence - 0.03)
        << "after " << r.passes << " passes at " << r.confidence;
    EXPECT_LT(r.accuracy.mean_abs_error, 0.01) << "after " << r.passes;  // measured 0.0067, 0.0033
    EXPECT_GT(r.accuracy.samples, 4000u);
  }
}

}  // namespace
}  // namespace pb
