// A pass in its steady state allocates nothing (issue "Stochastic progressive photon mapping":
// the camera pass of each pass parallel and allocation-free): every buffer of Renderer::step is
// sized by the first passes and reused. This binary replaces the global operator new to count
// the calls made while a pass runs (on every thread: the counter is atomic). Allocations inside
// oneTBB's own task pools go through its allocator, not operator new, and are not counted.
#include "render_fixture.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace pb {
namespace {

long allocations_in_one_pass(Method method, DirectMode direct, bool paths = false) {
  RenderOptions o = test::quick_options("cornell.gltf", 64, 8);
  o.method = method;
  o.direct = direct;
  o.adaptive_paths = paths;
  o.photons_per_pass = 20000;
  const Scene scene = load_gltf(o.scene);
  Renderer r(scene, o);
  // The first pass sizes the buffers: counted, so that the counter is seen to count.
  g_allocations = 0;
  g_counting = true;
  r.step();
  g_counting = false;
  EXPECT_GT(g_allocations.load(), 0) << "the first pass sizes its buffers";
  // Warm: the photon count of a pass varies, so the hit buffers may still grow for a few passes;
  // --adaptive paths sizes its scratch at its first allocation (kPathsMinPasses); the adaptive
  // radius spreads the radii over the first 20-odd passes, and the grid's levels grow with them.
  for (int k = 0; k < 40; ++k) r.step();
  long most = 0;
  for (int k = 0; k < 3; ++k) {
    g_allocations = 0;
    g_counting = true;
    r.step();
    g_counting = false;
    most = std::max(most, g_allocations.load());
  }
  return most;
}

TEST(Allocation, SppmPassAllocatesNothingOnceWarm) {
  EXPECT_EQ(allocations_in_one_pass(Method::SPPM, DirectMode::NextEvent), 0);
  EXPECT_EQ(allocations_in_one_pass(Method::SPPM, DirectMode::Photons), 0);
  EXPECT_EQ(allocations_in_one_pass(Method::SPPM, DirectMode::NextEvent, true), 0);
}

TEST(Allocation, PpmPassAllocatesNothingOnceWarm) {
  EXPECT_EQ(allocations_in_one_pass(Method::PPM, DirectMode::NextEvent), 0);
}

}  // namespace
}  // namespace pb
