// Expectations shared by the decode tests: the world transform of gltf_fixture.h's mesh_trs(),
// loading, one-line errors, and comparing a loaded mesh with the grid it was made from.
#pragma once

#include "gltf_fixture.h"
#include "process_fixture.h"

#include "gltf/gltf_loader.h"

#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <array>

namespace pb::test {

// T * R * S of mesh_trs(), in double.
inline glm::dmat4 trs_matrix() {
  const json t = mesh_trs();
  const auto v = [&](const char* k, int i) { return t[k][size_t(i)].get<double>(); };
  const double x = v("rotation", 0), y = v("rotation", 1), z = v("rotation", 2),
               w = v("rotation", 3);
  const glm::dmat3 r(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
                     2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                     2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y));
  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) m[c] = glm::dvec4(r[c] * v("scale", c), 0.0);
  m[3] = glm::dvec4(v("translation", 0), v("translation", 1), v("translation", 2), 1.0);
  return m;
}
inline glm::dvec3 world_point(const glm::dvec3& p) {
  return glm::dvec3(trs_matrix() * glm::dvec4(p, 1.0));
}
inline glm::dvec3 world_normal(const glm::dvec3& n) {
  return glm::normalize(glm::transpose(glm::inverse(glm::dmat3(trs_matrix()))) * n);
}
// The largest factor by which the normal transform can stretch an error: max / min scale.
constexpr double kNormalGain = 2.0 / 0.5;
constexpr double kPositionGain = 2.0;  // the largest scale of mesh_trs()

class DecodeTest : public TempDirTest {
 protected:
  // A copy of the one mesh a test scene holds (so that it outlives a temporary Scene).
  static Mesh only_mesh(const Scene& s) {
    EXPECT_EQ(s.meshes.size(), 1u);
    return s.meshes.at(0);
  }
  void expect_error(const std::string& file, const std::string& phrase) {
    try {
      load_gltf(file);
      ADD_FAILURE() << "expected a SceneError containing \"" << phrase << "\"";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(file + ": ", 0), 0u) << m;
      EXPECT_NE(m.find(phrase), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
};

struct Tolerance {
  double position = 1e-5, normal = 1e-5, uv0 = 1e-6, uv1 = 1e-6;
};

// Compares a loaded mesh with the grid: every loaded vertex is matched to the grid vertex nearest
// in world space (identity when `same_order`), which must be within the tolerances in position,
// normal and both texture coordinate sets; the triangles must be the grid's, each with the same
// winding (a rotation of its corners allowed when the order may change).
inline void expect_grid(const Mesh& m, const Grid& g, const Tolerance& tol, bool same_order) {
  ASSERT_EQ(m.positions.size(), g.vertices());
  ASSERT_EQ(m.normals.size(), g.vertices());
  ASSERT_EQ(m.texcoords[0].size(), g.vertices());
  ASSERT_EQ(m.texcoords[1].size(), g.vertices());
  const auto p3 = [](const std::vector<float>& v, size_t k) {
    return glm::dvec3(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
  };
  std::vector<glm::dvec3> want(g.vertices());
  for (size_t k = 0; k < want.size(); ++k) want[k] = world_point(p3(g.positions, k));
  std::vector<uint32_t> map(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const glm::dvec3 p(m.positions[i]);
    size_t best = i;
    if (!same_order)
      for (size_t k = 0; k < want.size(); ++k)
        if (glm::length(p - want[k]) < glm::length(p - want[best])) best = k;
    map[i] = uint32_t(best);
    ASSERT_LE(glm::length(p - want[best]), tol.position) << "vertex " << i;
    EXPECT_LE(glm::length(glm::dvec3(m.normals[i]) - world_normal(p3(g.normals, best))), tol.normal)
        << "vertex " << i;
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(m.texcoords[0][i][c], g.uv0[2 * best + size_t(c)], tol.uv0) << "vertex " << i;
      EXPECT_NEAR(m.texcoords[1][i][c], g.uv1[2 * best + size_t(c)], tol.uv1) << "vertex " << i;
    }
  }
  // Triangles as their corners rotated to put the smallest first (the winding kept): in order
  // when the order is kept (meshoptimizer's index codec may still rotate corners), as sets
  // otherwise.
  auto canonical = [](std::array<uint32_t, 3> t) {
    while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
    return t;
  };
  std::vector<std::array<uint32_t, 3>> grid, loaded;
  for (size_t t = 0; t < g.indices.size(); t += 3)
    grid.push_back(canonical({g.indices[t], g.indices[t + 1], g.indices[t + 2]}));
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3)
    loaded.push_back(canonical({map[m.indices[t]], map[m.indices[t + 1]], map[m.indices[t + 2]]}));
  EXPECT_EQ(m.indices.size(), g.indices.size());
  if (!same_order) {
    std::sort(grid.begin(), grid.end());
    std::sort(loaded.begin(), loaded.end());
  }
  EXPECT_EQ(loaded, grid);
}

}  // namespace pb::test
