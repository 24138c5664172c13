// The photon guide (render/photon_guide.h, ESTIMATOR.md section 14): guided emission carries the
// power of power-proportional emission into every region, the mixture keeps every cell at its
// uniform share, and the learning sums do not depend on the threads.
#include "lights/lights.h"
#include "render/photon_guide.h"
#include "sample_mean.h"
#include "util/parallel.h"
#include "util/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace pb {
namespace {

// A point light above an emissive quad: emitters of two kinds (three emitters, so three bins of
// the emitter choice), whose direction the guide warps in a punctual light's first pair and in
// a triangle's second.
Scene two_emitters() {
  Scene s;
  Mesh m;
  m.positions = {vec3(0, 0, 0), vec3(2, 0, 0), vec3(2, 1, 0), vec3(0, 1, 0)};
  m.indices = {0, 1, 2, 0, 2, 3};
  s.meshes.push_back(m);
  Material mat = Material::lambertian(vec3(0.0f));
  mat.emission = vec3(1.0f, 0.5f, 0.25f);
  s.materials.push_back(mat);
  PunctualLight l;
  l.position = vec3(1, 0.5f, 2);
  l.intensity = vec3(3.0f);
  s.lights.push_back(l);
  return s;
}

using test::Mean;

// Regions of a photon's emission: which emitter (by where it starts) and which octant it
// leaves into.
int region(const EmittedPhoton& p) {
  const int octant = (p.dir.x > 0) + 2 * (p.dir.y > 0) + 4 * (p.dir.z > 0);
  return octant + 8 * (p.origin.z > 1.0f);
}

// A histogram that favours a few cells strongly: what a guide learns from a caustic.
std::vector<double> skewed(size_t cells) {
  std::vector<double> h(cells, 0.0);
  for (size_t c = 0; c < cells; c += 97) h[c] = 1.0 + double(c % 7);
  h[cells / 3] = 500.0;
  return h;
}

// The importance-sampling identity: for any q with every cell above 0, E[flux 1{region}] under
// the guide equals that of power-proportional emission. 400k photons each; 4 combined standard
// errors per region and channel (16 regions x 3 channels: a false failure about once in 300
// runs of independent seeds; these are fixed).
TEST(PhotonGuide, GuidedEmissionCarriesThePowerOfEveryRegion) {
  const Scene scene = two_emitters();
  const Lights lights(scene);
  EmissionGuide guide(lights.emitter_count());
  ASSERT_EQ(guide.cells(), 3u * 32u * 32u);  // the light and the quad's two triangles
  guide.learn(skewed(guide.cells()));
  ASSERT_TRUE(guide.guiding());
  constexpr int kPhotons = 400000;
  Mean plain[16][3], guided[16][3];
  size_t favoured = 0;
  for (int i = 0; i < kPhotons; ++i) {
    Rng a(21, 0, uint64_t(i), Stream::Test), b(22, 0, uint64_t(i), Stream::Test);
    const EmittedPhoton p = lights.sample_photon(a);
    PrimarySample u;
    for (float& x : u.u) x = b.next_float();
    float density = 0.0f;
    const uint32_t cell = guide.warp(b.next_float(), u, lights, density);
    favoured += cell == guide.cells() / 3;
    ASSERT_GE(density, float(EmissionGuide::kUniformShare) * 0.999f);
    EmittedPhoton g = lights.sample_photon(u);
    g.flux /= density;
    const int rp = region(p), rg = region(g);
    for (int r = 0; r < 16; ++r)
      for (int c = 0; c < 3; ++c) {
        plain[r][c].add(r == rp ? p.flux[c] : 0.0);
        guided[r][c].add(r == rg ? g.flux[c] : 0.0);
      }
  }
  for (int r = 0; r < 16; ++r)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(guided[r][c].mean(), plain[r][c].mean(),
                  4.0 * std::hypot(guided[r][c].se(), plain[r][c].se()) + 1e-9)
          << "region " << r << " channel " << c;
  // And the guide does move photons: the favoured cell holds 500 of the histogram's ~570, so
  // it draws (1 - m) 500 / total + m / cells of the photons (4 binomial sds).
  double total = 0.0;
  for (double v : skewed(guide.cells())) total += v;
  const double want = (1.0 - EmissionGuide::kUniformShare) * 500.0 / total +
                      EmissionGuide::kUniformShare / double(guide.cells());
  EXPECT_NEAR(double(favoured) / kPhotons, want, 4.0 * std::sqrt(want * (1 - want) / kPhotons));
}

// The mixture: the smallest density is the uniform share m, so no photon's flux grows by more
// than 1 / m; before anything is learnt every photon keeps its power (density 1) and its numbers.
TEST(PhotonGuide, TheMixtureBoundsEveryWeight) {
  const Scene scene = two_emitters();
  const Lights lights(scene);
  EmissionGuide guide(lights.emitter_count());
  EXPECT_FALSE(guide.guiding());
  EXPECT_DOUBLE_EQ(guide.max_weight(), 1.0);
  PrimarySample u;
  for (int k = 0; k < PrimarySample::kDims; ++k) u.u[k] = 0.1f * float(k + 1);
  const PrimarySample before = u;
  float density = 0.0f;
  guide.warp(0.5f, u, lights, density);
  EXPECT_EQ(density, 1.0f);
  for (int k = 0; k < PrimarySample::kDims; ++k) EXPECT_EQ(u.u[k], before.u[k]);

  std::vector<double> one(guide.cells(), 0.0);
  one[5] = 1.0;
  guide.learn(one);
  EXPECT_NEAR(guide.max_weight(), 1.0 / EmissionGuide::kUniformShare, 1e-5);
  // A pass that learnt nothing (no photon reached a point with error) changes nothing.
  guide.learn(std::vector<double>(guide.cells(), 0.0));
  EXPECT_EQ(guide.learnt(), 1u);
  // The running histogram is the mean of the passes' normalised sums at first.
  std::vector<double> other(guide.cells(), 0.0);
  other[7] = 3.0;
  guide.learn(other);
  EXPECT_DOUBLE_EQ(guide.histogram()[5], 0.5);
  EXPECT_DOUBLE_EQ(guide.histogram()[7], 0.5);
  EXPECT_THROW(guide.restore(std::vector<double>(3, 0.0), 1), std::invalid_argument);
}

// The learning sums: chunks add into thread-local scratch and are reduced in chunk order, so
// the sums are the same bits on 1, 2 and 3 threads.
TEST(GuideTally, SumsDoNotDependOnTheThreads) {
  constexpr size_t kCells = 4096, kChunks = 64;
  auto run = [&](int threads) {
    ThreadLimit limit(threads);
    GuideTally tally;
    tally.begin_pass(kCells, kChunks);
    parallel_for(kChunks, 1, [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) {
        GuideTally::Chunk chunk(tally, k);
        Rng rng(3, 0, k, Stream::Test);
        for (int i = 0; i < 5000; ++i)
          chunk.add(rng.next_u32() % 64 * 61 % kCells, double(rng.next_float()) * 1e-3 + 1e-9);
      }
    });
    tally.reduce_block(kChunks);
    return std::vector<double>(tally.sums().begin(), tally.sums().end());
  };
  const std::vector<double> one = run(1);
  EXPECT_EQ(one, run(2));
  EXPECT_EQ(one, run(3));
  double total = 0.0;
  for (double v : one) total += v;
  EXPECT_GT(total, 0.0);
}

}  // namespace
}  // namespace pb
