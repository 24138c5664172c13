// A pass cut short (Ctrl-C, the end of --time; issue 36) is discarded whole: the render after a
// cut is bit for bit the render that stopped after its last whole pass (Renderer::step,
// Driver::run). Where Ctrl-C or the clock cuts a running pass is up to the clock, so these tests
// cut with a cutoff reached at a given poll (the polls before it let their batches run): in the
// middle of the photon batches, and in the middle of the first fold block's gather (the methods'
// step, given the photons and the grid); and a --time render, wherever its cut lands, against a
// --passes render.
#include "render/pass_stages.h"
#include "render/ppm.h"
#include "render/sppm.h"
#include "render_fixture.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>

namespace pb {
namespace {

// Bit for bit, the whole render state (states, SPPM's side state, counters, photon power).
void expect_same(const RenderState& a, const RenderState& b, const char* what) {
  EXPECT_EQ(a.work.passes, b.work.passes) << what;
  EXPECT_EQ(a.work.photons, b.work.photons) << what;
  EXPECT_EQ(a.work.rays, b.work.rays) << what;
  EXPECT_EQ(a.max_photon_power, b.max_photon_power) << what;
  EXPECT_EQ(a.visible, b.visible) << what;
  EXPECT_EQ(a.min_mass, b.min_mass) << what;
  EXPECT_EQ(a.glossy_f, b.glossy_f) << what;
  ASSERT_EQ(a.states.size(), b.states.size()) << what;
  EXPECT_EQ(std::memcmp(a.states.data(), b.states.data(), a.states.size() * sizeof(PointState)), 0)
      << what;
}

void expect_same_image(const Renderer& a, const Renderer& b, const char* what) {
  const ExrImage x = a.image(RunInfo{}), y = b.image(RunInfo{});
  ASSERT_EQ(x.pixels.size(), y.pixels.size()) << what;
  EXPECT_EQ(std::memcmp(x.pixels.data(), y.pixels.data(), x.pixels.size() * sizeof(float)), 0)
      << what;
}

// Reached from the (after + 1)-th poll on; `polls` counts them (polled from several threads).
Cutoff after_polls(std::atomic<int>& polls, int after) {
  return {[&polls, after] { return polls.fetch_add(1) >= after; }};
}

RenderOptions options_for(Method m, int size) {
  RenderOptions o = test::quick_options("cornell.gltf", size, 100);
  o.method = m;
  o.photons_per_pass = 20000;
  return o;
}

// A cutoff reached after 5 of a pass's 10 batches of photons (PhotonTracer::kChunk each): the
// pass is discarded (step returns false) and changes nothing; the next pass is the one an uncut
// render makes third, bit for bit.
TEST(CutPass, APassCutInItsPhotonBatchesChangesNothing) {
  for (Method m : {Method::PPM, Method::SPPM}) {
    RenderOptions o = options_for(m, 24);
    o.photons_per_pass = 10 * PhotonTracer::kChunk;
    const Scene scene = load_gltf(o.scene);
    Renderer cut(scene, o), whole(scene, o);
    for (int k = 0; k < 2; ++k) {
      ASSERT_TRUE(cut.step());
      ASSERT_TRUE(whole.step());
    }
    const RenderState before = cut.snapshot();
    std::atomic<int> polls{0};
    const Cutoff halfway = after_polls(polls, 5);
    std::vector<PointState> copy;
    EXPECT_FALSE(cut.step(&copy, &halfway));
    EXPECT_GT(polls.load(), 5);
    EXPECT_EQ(cut.passes(), 2u);
    expect_same(cut.snapshot(), before, "after the cut");
    ASSERT_TRUE(cut.step());
    ASSERT_TRUE(whole.step());
    expect_same(cut.snapshot(), whole.snapshot(), "the pass after the cut");
    expect_same_image(cut, whole, "the pass after the cut");
  }
}

// The method's part of a pass (camera paths, gather, next-event, fold), the photons traced and
// the grid built, given a cutoff reached after 8 of the first fold block's chunks of points
// (kStageChunk each) have gathered: nothing reaches the states or SPPM's side state. 160x160
// SPPM pixels are two fold blocks (kFoldBlock).
template <class Method>
void check_method_cut(const RenderOptions& o, Method& method, const Renderer& r) {
  const World& world = r.world();
  std::vector<PointState> states(method.state_count());
  for (PointState& s : states) s.r2 = r.initial_radius() * r.initial_radius();
  std::vector<float> radii(states.size(), search_radius(states[0].r2));
  PhotonTracer tracer(world, false);
  std::vector<PhotonHit> hits;
  ASSERT_FALSE(tracer.run(o.seed, 1, 0, o.photons_per_pass, hits).cut);
  std::vector<vec3> positions;
  HashGrid grid;
  build_photon_grid(hits, radii, positions, grid);
  EstimatorParams params;
  params.alpha = o.alpha;
  params.photons_per_pass = double(o.photons_per_pass);
  std::atomic<int> polls{0};
  const Cutoff partway = after_polls(polls, 8);
  PassInputs in{world, grid, hits, params, &r.boundary(), o.seed, 1, true, &partway};
  RenderState side_before, side_after;
  method.save(side_before);
  const std::vector<PointState> states_before = states;
  const std::vector<float> radii_before = radii;
  ASSERT_GT(states.size(), 16 * kStageChunk);
  EXPECT_FALSE(method.step(in, states, radii, nullptr));
  EXPECT_GT(polls.load(), 8);
  method.save(side_after);
  EXPECT_EQ(std::memcmp(states.data(), states_before.data(), states.size() * sizeof(PointState)),
            0);
  EXPECT_EQ(radii, radii_before);
  EXPECT_EQ(side_after.visible, side_before.visible);
  EXPECT_EQ(side_after.min_mass, side_before.min_mass);
  EXPECT_EQ(side_after.glossy_f, side_before.glossy_f);
  // Not cut, the same call gathers: the states change (the cut above is what kept them).
  const Cutoff never;
  in.cutoff = &never;
  EXPECT_TRUE(method.step(in, states, radii, nullptr));
  EXPECT_NE(std::memcmp(states.data(), states_before.data(), states.size() * sizeof(PointState)),
            0);
}

TEST(CutPass, AMethodStepCutBeforeItsFirstFoldChangesNothing) {
  {
    const RenderOptions o = options_for(Method::SPPM, 160);
    const Renderer r(load_gltf(o.scene), o);
    SppmMethod sppm(r.world(), r.camera(), CameraPathSettings{o.max_depth, 0.0f});
    ASSERT_GT(sppm.state_count(), kFoldBlock);
    check_method_cut(o, sppm, r);
  }
  {
    const RenderOptions o = options_for(Method::PPM, 80);
    const Renderer r(load_gltf(o.scene), o);
    PpmMethod ppm(r.world(), r.camera(), o.max_depth);
    ppm.prepare(r.boundary(), r.initial_radius());
    check_method_cut(o, ppm, r);
  }
}

// --time ends the render in the middle of a pass (its passes here take far longer than the
// time between two polls): whatever pass the end of the time cut, the render is the one that
// stopped after its last whole pass, as --passes with that count renders it (no pass at all
// is a fresh renderer's state).
TEST(CutPass, ATimeLimitedRenderIsThePassesRenderOfItsWholePasses) {
  for (Method m : {Method::PPM, Method::SPPM}) {
    RenderOptions o = options_for(m, 32);
    o.passes.reset();
    o.time_seconds = 1.5;
    o.photons_per_pass = 400000;
    const Scene scene = load_gltf(o.scene);
    Renderer timed(scene, o);
    const RenderReport report = test::run_to_stop(timed);
    EXPECT_EQ(stop_text(report.stop), "time");
    EXPECT_EQ(report.work.passes, timed.passes());
    Renderer counted(scene, o);
    for (uint64_t k = 0; k < timed.passes(); ++k) ASSERT_TRUE(counted.step());
    expect_same(timed.snapshot(), counted.snapshot(), "--time against --passes");
    expect_same_image(timed, counted, "--time against --passes");
  }
}

}  // namespace
}  // namespace pb
