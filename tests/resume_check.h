// Resuming a render from its state file (app/checkpoint.h) against the uninterrupted render.
#pragma once

#include "render_fixture.h"

#include "app/checkpoint.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace pb {

inline SavedRender saved_after(const RenderOptions& o, uint64_t passes) {
  const Scene scene = load_gltf(o.scene);
  Renderer r(scene, o);
  while (r.passes() < passes) r.step();
  return {o, scene.content_hash, r.snapshot(), DriverState{}};
}

// Continuing from a state file written after `at` passes gives the image of an uninterrupted
// render, bit for bit.
inline void expect_resume_bit_identical(const RenderOptions& o, const std::string& state_path,
                                        uint64_t at = 3) {
  const Scene scene = load_gltf(o.scene);
  Renderer straight(scene, o);
  const RenderReport full = test::run_to_stop(straight);

  save_state(state_path, saved_after(o, at));
  const SavedRender loaded = load_state(state_path);
  Renderer resumed(scene, o);
  resumed.restore(loaded.render);
  EXPECT_EQ(resumed.passes(), at);
  const RenderReport rest = test::run_to_stop(resumed, loaded.schedule);
  EXPECT_EQ(rest.work.passes, full.work.passes);
  EXPECT_EQ(rest.work.photons, full.work.photons);
  ASSERT_EQ(resumed.states().size(), straight.states().size());
  EXPECT_EQ(std::memcmp(resumed.states().data(), straight.states().data(),
                        straight.states().size() * sizeof(PointState)),
            0);
  const ExrImage a = straight.image(full.run()), b = resumed.image(rest.run());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)), 0);
}

}  // namespace pb
