// What a photon may carry after a bounce where the shading normal leans from the true one
// (the adjoint correction of photon_pass.cpp; ESTIMATOR.md section 12, whose sparse-photon
// bound takes the largest power any photon carried).
#include "render/photon_pass.h"
#include "render/renderer.h"
#include "scene_builder.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pb {
namespace {

using test::SceneBuilder;

// A smooth white mirror (metallic 1, roughness 0: a delta branch of weight 1) at y = 0 whose
// shading normal leans 65 degrees toward +x, a point light above it at (0.3, 1, 0), and a black
// ceiling at y = 1.2 that keeps every photon the mirror sends up (and ends it). Light reaches the
// mirror from -11 to 61 degrees off its true normal, toward +x. Below 40 degrees the reflection
// about the leaning normal would point below the mirror, and the branch reflects about the true
// normal instead; at 25 degrees that direction is perpendicular to the shading normal, where
// Veach's factor |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|) has a pole.
Scene leaning_mirror() {
  SceneBuilder b;
  b.scene.materials.push_back(Material::metal(vec3(1.0f), 0.0f));
  const uint32_t mirror = uint32_t(b.scene.materials.size() - 1);
  const uint32_t black = b.material(vec3(0.0f));
  b.quad(vec3(-0.5f, 0, 0), vec3(0, 0, 0.5f), vec3(1.0f, 0, 0), mirror);  // faces +y
  const float lean = 65.0f * kPi / 180.0f;
  b.scene.meshes.back().normals.assign(4, vec3(std::sin(lean), std::cos(lean), 0.0f));
  b.quad(vec3(0, 1.2f, 0), vec3(5, 0, 0), vec3(0, 0, 5), black);  // faces -y
  b.point_light(vec3(0.3f, 1.0f, 0.0f), vec3(1.0f));
  b.camera(vec3(0, 0.6f, 3), vec3(0), 0.8f);
  return b.scene;
}

TEST(PhotonWeights, AMirrorReflectingAboutItsTrueNormalCreatesNoPower) {
  RenderOptions o;
  o.width = o.height = 8;
  o.progress = ProgressMode::Never;
  const Renderer r(leaning_mirror(), o);
  PhotonTracer tracer(r.world(), false);
  std::vector<PhotonHit> hits;
  const PhotonPassStats stats = tracer.run(7, 1, 0, 200000, hits);
  const double emitted = r.world().lights().max_photon_flux();
  // Every stored photon came off the mirror once (the light's direct photons are first hits,
  // not stored; the ceiling ends every path). The mirror's weight is 1. Reflected about the
  // leaning normal (arrivals beyond 40 degrees, leaving at 130 degrees minus the arrival's), the
  // adjoint factor is |wi.ng| / |wo.ng| (|wi.ns| = |wo.ns|), below 1 here; about the true normal
  // it is 1 (ng is the normal that branch used). Before, that branch took |wo.ns| / |wi.ns|,
  // with its pole at 25 degrees: the largest photon carried 99,499 against an emitted 12.57.
  ASSERT_GT(hits.size(), 10000u);
  EXPECT_LE(stats.max_flux, emitted * (1.0 + 1e-5));
  // Both branches were taken, told apart by where they meet the ceiling: about the leaning
  // normal only from x < -0.54 (arrivals beyond 40 degrees) and out at 69 degrees or more, so
  // at x > 1.5; about the true normal back toward the light's side or within 11 degrees of
  // the normal, so at x < 0.8. (The roulette keeps a photon's power where its factor is below 1,
  // so the powers do not tell.)
  int about_ns = 0, about_ng = 0;
  for (const PhotonHit& h : hits) {
    about_ns += h.position.x > 1.5f;
    about_ng += h.position.x < 0.8f;
  }
  EXPECT_GT(about_ns, 300);  // 729 with this seed
  EXPECT_GT(about_ng, 1000);
}

}  // namespace
}  // namespace pb
