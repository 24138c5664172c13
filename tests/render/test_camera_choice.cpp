// The camera a render looks through (camera_choice.h): the default view frames the bounds of a file
// without camera, --look-from / --look-at / --up / --fov override any camera, and --camera with
// a wrong name lists the cameras there are.
#include "scene_builder.h"

#include "render/camera_choice.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace pb {
namespace {

Scene boxes(const vec3& lo, const vec3& hi) {
  test::SceneBuilder b;
  b.box(lo, hi, b.material(vec3(0.5f)));
  return std::move(b.scene);
}

RenderOptions sized(int w, int h) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  return o;
}

// Image position (pixels; (0, 0) the top-left corner) of world point p, and whether it is in
// front of the camera: the inverse of PinholeCamera::direction.
bool project(const PinholeCamera& cam, const vec3& p, float& px, float& py) {
  const Camera& c = cam.camera();
  const vec3 d = p - c.position;
  const float z = glm::dot(d, c.forward);
  if (!(z > 0.0f)) return false;
  const float tan_half = std::tan(0.5f * c.yfov), aspect = float(cam.width()) / float(cam.height());
  px = (glm::dot(d, c.right) / z / (tan_half * aspect) + 1.0f) * 0.5f * float(cam.width());
  py = (1.0f - glm::dot(d, c.up) / z / tan_half) * 0.5f * float(cam.height());
  return true;
}

// Every corner of the bounds projects inside the image, and the bounds are not lost in it: the
// farthest corner from the image centre is at least half way to the edge of the narrower side
// (a corner of a box lies on its bounding sphere, which the view fits to 1 / 1.05 of the
// narrower half-angle).
TEST(View, DefaultViewFramesTheBounds) {
  const std::pair<vec3, vec3> cases[] = {
      {vec3(-1), vec3(1)},                                             // a cube at the origin
      {vec3(1e4f, 2e4f, -3e4f), vec3(1e4f + 3, 2e4f + 1, -3e4f + 2)},  // far off, elongated
      {vec3(-500, 0, -500), vec3(500, 1e-3f, 500)},                    // a flat ground
      {vec3(-0.01f, 0, -0.01f), vec3(0.01f, 2, 0.01f)},                // a thin pole, upright
      {vec3(-3e-4f, -1e-4f, -2e-4f), vec3(3e-4f, 1e-4f, 2e-4f)},       // tiny
  };
  for (const auto& [lo, hi] : cases)
    for (const auto& [w, h] : {std::pair{64, 64}, std::pair{128, 48}, std::pair{40, 100}}) {
      SCOPED_TRACE(testing::Message()
                   << "bounds " << lo.x << ".." << hi.x << ", " << w << "x" << h);
      const Scene s = boxes(lo, hi);
      const RenderOptions o = sized(w, h);
      ASSERT_TRUE(uses_default_view(s, o));
      const PinholeCamera cam = choose_camera(s, o);
      float reach = 0.0f;
      for (int k = 0; k < 8; ++k) {
        const vec3 p(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        float px, py;
        ASSERT_TRUE(project(cam, p, px, py));
        EXPECT_GE(px, 0.0f);
        EXPECT_LE(px, float(w));
        EXPECT_GE(py, 0.0f);
        EXPECT_LE(py, float(h));
        const float half = 0.5f * float(std::min(w, h));
        reach = std::max({reach, std::fabs(px - 0.5f * float(w)) / half,
                          std::fabs(py - 0.5f * float(h)) / half});
      }
      std::printf("bounds %g..%g at %dx%d: the farthest corner reaches %.2f of the half-side\n",
                  double(lo.x), double(hi.x), w, h, double(reach));
      EXPECT_GE(reach, 0.5f);
      // From +Z and above (model-viewer's default orbit), looking at the centre.
      const vec3 f = cam.direction(0.5f * float(w), 0.5f * float(h));
      EXPECT_NEAR(f.y, -std::sin(float(kDefaultElevationDegrees) * kPi / 180.0f), 1e-3f);
      EXPECT_LT(f.z, 0.0f);
      EXPECT_NEAR(f.x, 0.0f, 1e-4f);
    }
}

// The default field of view is 45 degrees vertically; --fov replaces it.
TEST(View, FieldOfView) {
  const Scene s = boxes(vec3(-1), vec3(1));
  RenderOptions o = sized(64, 64);
  auto yfov = [&](const PinholeCamera& cam) {
    const vec3 top = cam.direction(32.0f, 0.0f), mid = cam.direction(32.0f, 32.0f);
    return 2.0 * std::acos(double(glm::dot(top, mid))) * 180.0 / kPiD;
  };
  EXPECT_NEAR(yfov(choose_camera(s, o)), kDefaultFovDegrees, 1e-3);
  o.fov = 20.0;
  EXPECT_NEAR(yfov(choose_camera(s, o)), 20.0, 1e-3);
}

// --look-from, --look-at and --up replace a file camera's position, direction and up.
TEST(View, OverridesReplaceTheFileCamera) {
  test::SceneBuilder b;
  b.box(vec3(-1), vec3(1), b.material(vec3(0.5f)));
  b.camera(vec3(0, 0, 5), vec3(0), 0.8f);
  const Scene s = std::move(b.scene);
  RenderOptions o = sized(32, 32);
  const PinholeCamera file = choose_camera(s, o);
  EXPECT_FALSE(uses_default_view(s, o));
  EXPECT_EQ(file.origin(), vec3(0, 0, 5));

  auto near = [](const vec3& a, const vec3& b) { return glm::length(a - b) < 1e-5f; };
  o.look_from = std::array<double, 3>{4, 0, 0};  // alone: looks at the bounds' centre
  Camera c = choose_camera(s, o).camera();
  EXPECT_EQ(c.position, vec3(4, 0, 0));
  EXPECT_TRUE(near(c.forward, vec3(-1, 0, 0)));
  EXPECT_TRUE(near(c.up, vec3(0, 1, 0)));
  o.look_at = std::array<double, 3>{4, 0, -3};
  c = choose_camera(s, o).camera();
  EXPECT_TRUE(near(c.forward, vec3(0, 0, -1)));
  o.up = std::array<double, 3>{1, 0, 1};  // made orthogonal to the view direction: +X
  c = choose_camera(s, o).camera();
  EXPECT_TRUE(near(c.up, vec3(1, 0, 0)));
  EXPECT_TRUE(near(c.right, vec3(0, -1, 0)));
  o.fov = 10.0;
  EXPECT_NEAR(choose_camera(s, o).camera().yfov, 10.0 * kPiD / 180.0, 1e-6);

  // Straight down without --up: the image's top goes toward -Z instead of failing.
  RenderOptions down = sized(32, 32);
  down.look_from = std::array<double, 3>{0, 10, 0};
  down.look_at = std::array<double, 3>{0, 0, 0};
  c = choose_camera(s, down).camera();
  EXPECT_TRUE(near(c.forward, vec3(0, -1, 0)));
  EXPECT_TRUE(near(c.up, vec3(0, 0, -1)));
}

TEST(View, DegenerateViewsAreUsageErrors) {
  const Scene s = boxes(vec3(-1), vec3(1));
  RenderOptions o = sized(8, 8);
  o.look_from = std::array<double, 3>{1, 2, 3};
  o.look_at = std::array<double, 3>{1, 2, 3};
  EXPECT_THROW(choose_camera(s, o), UsageError);
  o.look_at = std::array<double, 3>{1, 0, 3};
  o.up = std::array<double, 3>{0, -2, 0};
  try {
    choose_camera(s, o);
    ADD_FAILURE() << "an up along the view direction was accepted";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "--up: lies along the view direction");
  }
}

TEST(View, AWrongCameraNameListsTheCameras) {
  test::SceneBuilder b;
  b.box(vec3(-1), vec3(1), b.material(vec3(0.5f)));
  b.camera(vec3(0, 0, 5), vec3(0), 0.8f);
  b.camera(vec3(0, 5, 5), vec3(0), 0.8f);
  b.scene.cameras[1].name = "camera 1";
  RenderOptions o = sized(8, 8);
  o.camera = "top";
  try {
    choose_camera(b.scene, o);
    ADD_FAILURE() << "accepted";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--camera: built.gltf has no perspective camera named 'top' (its cameras: 'camera', "
              "'camera 1')");
  }
  b.scene.cameras.clear();
  try {
    choose_camera(b.scene, o);
    ADD_FAILURE() << "accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("(it has none)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pb
