// Ray offsets from the hit's floating-point error bound (ray_offset.h), at every scene scale: no
// ray finds the surface it leaves, no shadow ray finds the light it aims at, and a 1-unit object
// over grounds of 1e2 to 1e6 units keeps its radiance (with offsets of 1e-5 of the scene's
// diagonal it self-shadowed: issue 16 measured mean radiance 0 over a 1e5 ground).
#include "render_fixture.h"
#include "scene_builder.h"

#include "util/ray_offset.h"

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

#include <cstdio>

namespace pb {
namespace {

// A random rotation (uniform quaternion, Shoemake 1992) applied to v.
vec3 rotate(const vec3& v, Rng& rng) {
  const float u1 = rng.next_float(), u2 = 2 * kPi * rng.next_float(),
              u3 = 2 * kPi * rng.next_float();
  const float a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const glm::quat q(a * std::cos(u2), b * std::sin(u3), b * std::cos(u3), a * std::sin(u2));
  return q * v;
}

// Barycentrics spread over the triangle and concentrated near its corners and edges, where the
// error bound is tightest relative to the farthest vertex.
void barycentrics(Rng& rng, float& u, float& v) {
  const float r = rng.next_float();
  if (r < 0.4f) {
    const float s = std::sqrt(rng.next_float());
    u = 1 - s;
    v = rng.next_float() * s;
  } else {
    const float near = 1e-4f * rng.next_float();
    const int corner = int(rng.next_float() * 3);
    u = corner == 1 ? 1 - near : near * rng.next_float();
    v = corner == 2 ? 1 - near - u : near * rng.next_float();
  }
}

// A direction on the side `sign` of n: uniform in the hemisphere, or within 1e-3 of grazing.
vec3 leaving(const vec3& n, float sign, Rng& rng) {
  vec3 t, b;
  orthonormal_basis(n, t, b);
  const float cos = rng.next_float() < 0.5f ? rng.next_float() : 1e-3f * rng.next_float() + 1e-6f;
  const float sin = std::sqrt(1 - cos * cos), phi = 2 * kPi * rng.next_float();
  return glm::normalize(sign * cos * n + sin * (std::cos(phi) * t + std::sin(phi) * b));
}

struct Tri {
  vec3 p0, p1, p2;
};

// Triangles of edge 1e-2 to 1e6 placed up to 1e6 from the origin, skinny (1:10) and square,
// tilted at random or lying in a coordinate plane like a ground.
std::vector<Tri> triangles() {
  std::vector<Tri> out;
  Rng rng(7, 0, 0, Stream::Test);
  for (float size : {1e-2f, 1.0f, 1e3f, 1e6f})
    for (float far : {0.0f, 1e2f, 1e4f, 1e6f})
      for (int k = 0; k < 12; ++k) {
        if (far > 1e4f * size) continue;  // below float resolution there
        const float aspect = k % 3 == 0 ? 0.1f : 1.0f;
        vec3 e1(size, 0, 0), e2(0.3f * size, 0, aspect * size);
        const bool ground = k % 4 == 1;
        if (!ground) {
          e1 = rotate(e1, rng);
          e2 = rotate(e2, rng);
        }
        vec3 c = far * (ground ? vec3(rng.next_float(), 0, rng.next_float())
                               : rotate(vec3(1, 0, 0), rng));
        // Every third one with a corner at the origin: there the error of the point is tiny
        // while Embree's, computed from the far vertex 0, is not.
        if (far == 0.0f && k % 3 == 2) c = -(0.7f * e1 - 0.3f * e2);
        out.push_back(
            {c - 0.3f * e1 - 0.3f * e2, c + 0.7f * e1 - 0.3f * e2, c - 0.3f * e1 + 0.7f * e2});
      }
  return out;
}

Scene one_triangle(const Tri& t) {
  test::SceneBuilder b;
  Mesh m;
  m.positions = {t.p0, t.p1, t.p2};
  m.indices = {0, 1, 2};
  m.material = b.material(vec3(0.5f));
  b.add(std::move(m));
  b.point_light(vec3(0, 1e7f, 0), vec3(1));
  return std::move(b.scene);
}

// A ray spawned from any point of a triangle toward either side, down to grazing angles, never
// hits that triangle (it is alone in the scene, so any hit is a self-hit). With PBR's bound
// weighted by the barycentrics instead of surface_error's, 354 of these 62,400 rays hit their
// own triangle, all from triangles with a corner at the origin.
TEST(Offsets, NoRayHitsTheSurfaceItLeaves) {
  size_t rays = 0, self_hits = 0;
  for (const Tri& t : triangles()) {
    const World world(one_triangle(t));
    Rng rng(11, 0, rays, Stream::Test);
    for (int k = 0; k < 400; ++k) {
      Hit h;
      barycentrics(rng, h.u, h.v);
      const Surface s = world.surface(h);
      const vec3 dir = leaving(s.ng, k % 2 ? 1.0f : -1.0f, rng);
      Hit hit;
      self_hits += world.trace(s.position, s.ng, s.error, dir, hit);
      ++rays;
    }
  }
  std::printf("%zu rays from %zu triangles, %zu self-hits\n", rays, triangles().size(), self_hits);
  EXPECT_EQ(self_hits, 0u);
  EXPECT_GT(rays, 50000u);
}

// Shadow rays from a receiving triangle to points sampled on an emissive triangle facing it
// (area and solid-angle sampling, near and far, small and huge, near the origin and far from
// it) are never blocked: only the two triangles exist, and a segment between points on their
// front sides crosses neither plane.
TEST(Offsets, ShadowRaysReachTheLightTheyAimAt) {
  size_t rays = 0, blocked = 0, samples = 0;
  Rng rng(13, 0, 0, Stream::Test);
  for (float size : {1e-2f, 1.0f, 1e3f, 1e5f})
    for (float far : {0.0f, 1e3f, 1e6f})
      for (float gap : {0.01f, 1.0f, 30.0f}) {
        if (far > 1e4f * size) continue;
        const vec3 c = far * rotate(vec3(1, 0, 0), rng), up = rotate(vec3(0, 1, 0), rng);
        vec3 u, v;
        orthonormal_basis(up, u, v);
        test::SceneBuilder b;
        b.quad(c, size * u, size * v, b.material(vec3(0.5f)));  // faces up
        b.quad(c + gap * size * up, size * v, size * u,
               b.material(vec3(0), vec3(1)));  // faces down
        const World world(std::move(b.scene));
        for (int k = 0; k < 500; ++k) {
          Hit h;
          h.prim = uint32_t(k % 2);
          barycentrics(rng, h.u, h.v);
          const Surface s = world.surface(h);
          const vec3 origin = World::spawn(s, s.ng);
          DirectSample d;
          if (!world.lights().sample_direct(origin, s.ng, rng, d)) continue;
          ++samples;
          if (glm::dot(d.wi, s.ng) <= 0.0f) continue;
          blocked += world.occluded(origin, d.wi, d.distance, d.margin);
          ++rays;
        }
      }
  std::printf("%zu shadow rays (%zu samples), %zu blocked\n", rays, samples, blocked);
  EXPECT_EQ(blocked, 0u);
  EXPECT_GT(rays, 10000u);
}

// The offset of a surface point depends on its own triangle only: the same cube has the same
// error bounds beside a 10-unit and a 1e6-unit ground.
TEST(Offsets, DoNotDependOnTheSceneSize) {
  auto cube_errors = [](float ground) {
    test::SceneBuilder b;
    b.quad(vec3(0), vec3(ground, 0, 0), vec3(0, 0, -ground), b.material(vec3(0.5f)));
    b.box(vec3(-0.5f, 0, -0.5f), vec3(0.5f, 1, 0.5f), b.material(vec3(0.8f)));
    b.point_light(vec3(1, 4, 2), vec3(10));
    const World world(std::move(b.scene));
    std::vector<float> e;
    for (uint32_t m = 1; m < world.scene().meshes.size(); ++m) {
      Hit h;
      h.mesh = m;
      h.u = h.v = 0.25f;
      e.push_back(world.surface(h).error);
    }
    return e;
  };
  const std::vector<float> small = cube_errors(10.0f), huge = cube_errors(1e6f);
  EXPECT_EQ(small, huge);
  for (float e : small) EXPECT_LT(e, 1e-5f);
}

// A unit cube on a ground of half-size G, lit by a point light, seen close up: the mean radiance,
// and its next-event part, of the pixels wholly on the cube for G = 1e2 ... 1e6 against the same
// render over a ground of 10 with the same fixed radius (alpha 1). The radius is max(0.05, the
// floor of 1e-6 x the scene's size, renderer.h radius_floor), which reaches 2.8 at G = 1e6 and
// changes the cube's photon part whatever the offsets; rendering the reference with it leaves
// the offsets as the one difference. Beyond a few units the ground adds almost nothing (its
// irradiance falls like 1/d^3), so the means agree within the noise; offsets of 1e-5 x the
// scene's size self-shadowed the cube (issue 16: mean radiance 0 at G = 1e5; measured on
// ca86105: 0 at 1e5 and 1e6, the photon part 4% low at 1e4).
struct CubeMeans {
  double total = 0.0, direct = 0.0;
};

CubeMeans cube_mean(float ground, Method method, double radius) {
  test::SceneBuilder b;
  b.quad(vec3(0), vec3(ground, 0, 0), vec3(0, 0, -ground), b.material(vec3(0.5f)));
  b.box(vec3(-0.5f, 0, -0.5f), vec3(0.5f, 1, 0.5f), b.material(vec3(0.8f)));
  b.point_light(vec3(1.5f, 4, 2), vec3(30));
  b.camera(vec3(1.8f, 1.6f, 2.2f), vec3(0, 0.45f, 0), 0.6f);
  RenderOptions o = test::quick_options("unused.gltf", 32, 8);
  o.method = method;
  o.photons_per_pass = 20000;
  o.radius = radius;
  o.alpha = 1.0;  // radii fixed: the floor differs with G and would stop only the huge one
  Renderer r(std::move(b.scene), o);
  for (int k = 0; k < 8; ++k) r.step();
  FilmImage img;
  r.develop(&img);
  const PinholeCamera cam = choose_camera(r.world().scene(), o);
  auto on_cube = [&](float px, float py) {
    Hit hit;
    return r.world().accel().intersect(cam.origin(), cam.direction(px, py), 0, INFINITY, hit) &&
           hit.mesh != 0;  // mesh 0 is the ground
  };
  CubeMeans m;
  size_t n = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      // Pixels wholly on the cube (centre and corners): an SPPM pixel on the silhouette also
      // averages the ground behind the cube, which is larger with G.
      const float fx = float(x), fy = float(y);
      if (!(on_cube(fx + 0.5f, fy + 0.5f) && on_cube(fx, fy) && on_cube(fx + 1, fy) &&
            on_cube(fx, fy + 1) && on_cube(fx + 1, fy + 1)))
        continue;
      const size_t p = size_t(y) * 32 + size_t(x);
      m.total += img.radiance[3 * p];
      // The next-event part: each state's mean sample less its photon part (ESTIMATOR.md
      // section 3's identity), summed over the pixel's states.
      const PixelLayout l = r.layout();
      const uint32_t b = l.pixel_begin.empty() ? uint32_t(p) : l.pixel_begin[p];
      const uint32_t e = l.pixel_begin.empty() ? uint32_t(p + 1) : l.pixel_begin[p + 1];
      for (uint32_t k = b; k < e; ++k) {
        const PointState& s = r.states()[k];
        m.direct += s.mean_x.x - photon_radiance(s, r.passes(), double(o.photons_per_pass)).x;
      }
      ++n;
    }
  EXPECT_GT(n, 250u);
  m.total /= double(n);
  m.direct /= double(n);
  return m;
}

TEST(Offsets, SmallObjectOverHugeGroundKeepsItsRadiance) {
  for (Method method : {Method::PPM, Method::SPPM}) {
    for (float g : {1e2f, 1e3f, 1e4f, 1e5f, 1e6f}) {
      // The radius floor at this ground (renderer.h radius_floor): 1e-6 x the bounds' diagonal.
      const double radius = std::max(0.05, 1e-6 * std::sqrt(8.0 * double(g) * g + 1.0));
      const CubeMeans ref = cube_mean(10.0f, method, radius), m = cube_mean(g, method, radius);
      std::printf(
          "%s ground %g, radius %.3g: cube mean radiance %.5f, next-event part %.5f "
          "(ground 10: %.5f, %.5f)\n",
          method == Method::PPM ? "ppm" : "sppm", double(g), radius, m.total, m.direct, ref.total,
          ref.direct);
      // The next-event part is where self-shadowing shows first: to rounding.
      EXPECT_NEAR(m.direct, ref.direct, 1e-3 * ref.direct) << "ground " << g;
      // The whole radiance: the photon part's noise in these 8 passes is ~0.5% of the mean.
      EXPECT_NEAR(m.total, ref.total, 0.02 * ref.total) << "ground " << g;
    }
  }
}

}  // namespace
}  // namespace pb
