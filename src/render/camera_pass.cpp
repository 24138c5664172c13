#include "render/camera_pass.h"

#include "bsdf/bsdf.h"
#include "util/parallel.h"

#include <algorithm>
#include <cstddef>

namespace pb {

namespace {

struct PathVertex {
  vec3 origin, dir, weight;
  vec3 origin_normal;  // surface the ray leaves (0 for the camera)
  float origin_error;  // its position error bound (Surface::error)
  float length;        // path length so far, for the footprint
  int depth;           // specular bounces so far
  int layers;          // BLEND surfaces passed through so far
};

// BLEND surfaces a pixel's ray may pass through (kept apart from the specular depth: a tree's
// crown of foliage cards is many layers deep).
constexpr int kMaxBlendLayers = 256;

struct PixelOutput {
  std::vector<VisiblePoint> points;
  std::vector<float> footprints;  // one per point
  std::vector<PointBsdf> glossy;  // point = index into points
  dvec3 emission{0.0};
};

// Follows every branch of one pixel's camera path. The tree has at most 2^max_depth leaves;
// an explicit stack keeps it iterative.
void trace_pixel(const World& world, const PinholeCamera& camera, int max_depth, int x, int y,
                 PixelOutput& out) {
  PathVertex stack[64];
  int top = 0;
  stack[top++] = {
      camera.origin(), camera.direction(x, y), vec3(1.0f), vec3(0.0f), 0.0f, 0.0f, 0, 0};
  while (top > 0) {
    const PathVertex v = stack[--top];
    Hit hit;
    const bool found = v.depth == 0
                           ? world.camera_hit(v.origin, v.dir, hit)
                           : world.trace(v.origin, v.origin_normal, v.origin_error, v.dir, hit);
    if (!found) {  // the environment (black without one): exact for this ray
      out.emission += dvec3(v.weight * world.lights().environment_radiance(v.dir));
      continue;
    }
    const Surface s = world.surface(hit);
    const vec3 wo = -v.dir;
    // Inside an absorbing volume the segment's transmittance weighs what it reaches.
    vec3 weight = v.weight * world.transmittance(s, wo, v.origin);
    const float length = v.length + hit.t;
    // A BLEND surface of coverage a splits the ray deterministically, as a dielectric does
    // (ESTIMATOR.md section 5: PPM's points are fixed, a random choice would be frozen): the
    // surface with weight a, and the ray going on through it with 1 - a (docs/materials.md
    // "Alpha"). The key-less trace met it (Accel::intersect).
    if (s.material->blended()) {
      const float a = world.coverage(hit, s);
      const vec3 through = weight * (1.0f - a);
      // At depth 0 the ray goes on as the camera's (World::camera_hit, from beyond the card).
      const vec3 from = v.depth == 0 ? World::spawn(s, v.dir) : s.position;
      if (max_component(through) > 0.0f && v.layers < kMaxBlendLayers && top < 64)
        stack[top++] = {from, v.dir, through, s.ng, s.error, length, v.depth, v.layers + 1};
      weight *= a;
      if (!(max_component(weight) > 0.0f)) continue;
    }
    // Emission seen along the chain is exact for this ray (front side unless double-sided), and
    // so is an unlit surface's painted colour (either side; it holds no visible point).
    if (s.material->emits()) out.emission += dvec3(weight * world.emitted(s, wo));
    if (s.material->unlit) out.emission += dvec3(weight * s.painted);
    if (!s.bsdf.is_delta()) {
      const bool front = glm::dot(wo, s.ng) > 0.0f;
      VisiblePoint p;
      p.position = world.spawn(s, wo);  // lifted off the surface: shadow rays start here
      p.normal = front ? s.ng : -s.ng;
      p.shading = front ? s.ns : -s.ns;
      const bool lambertian = s.bsdf.is_lambertian();
      p.f = lambertian ? weight * s.bsdf.diffuse_f() : weight;
      p.triangle = world.triangle_index(hit);
      if (max_component(p.f) > 0.0f) {
        if (!lambertian) out.glossy.push_back({uint32_t(out.points.size()), wo, s.bsdf});
        out.points.push_back(p);
        out.footprints.push_back(length * camera.pixel_angle());
      }
      if (!s.bsdf.has_delta()) continue;
    }
    if (v.depth >= max_depth) continue;  // the chain is cut
    SpecularBranch branches[kMaxDeltaBranches];
    const int n = s.bsdf.delta_branches(wo, Transport::Radiance, branches);
    for (int k = 0; k < n; ++k) {
      const vec3 w = weight * branches[k].weight;
      if (max_component(w) <= 0.0f || top >= 64) continue;
      stack[top++] = {s.position, branches[k].dir, w, s.ng, s.error, length, v.depth + 1, v.layers};
    }
  }
}

}  // namespace

CameraPassResult run_camera_pass(const World& world, const PinholeCamera& camera, int max_depth) {
  CameraPassResult r;
  r.width = camera.width();
  r.height = camera.height();
  const size_t pixels = size_t(r.width) * size_t(r.height);
  r.emission.assign(pixels, dvec3(0.0));

  // One output per row, joined in row order: the point order is independent of threads.
  std::vector<std::vector<VisiblePoint>> rows(size_t(r.height));
  std::vector<std::vector<float>> row_footprints(size_t(r.height));
  std::vector<std::vector<PointBsdf>> row_glossy(size_t(r.height));
  r.pixel_begin.assign(pixels + 1, 0);
  parallel_for(size_t(r.height), 1, [&](size_t begin, size_t end) {
    PixelOutput out;
    for (size_t y = begin; y < end; ++y) {
      out.points.clear();
      out.footprints.clear();
      out.glossy.clear();
      for (int x = 0; x < r.width; ++x) {
        const size_t pixel = y * size_t(r.width) + size_t(x);
        const size_t before = out.points.size();
        out.emission = dvec3(0.0);
        trace_pixel(world, camera, max_depth, x, int(y), out);
        r.emission[pixel] = out.emission;
        r.pixel_begin[pixel + 1] = uint32_t(out.points.size() - before);  // counts for now
      }
      rows[y] = out.points;
      row_footprints[y] = out.footprints;
      row_glossy[y] = out.glossy;
    }
  });

  size_t total = 0;
  for (const auto& row : rows) total += row.size();
  r.points.reserve(total);
  std::vector<float> footprints;
  footprints.reserve(total);
  for (size_t y = 0; y < rows.size(); ++y) {
    for (PointBsdf g : row_glossy[y]) {  // row-local indices become global ones
      g.point += uint32_t(r.points.size());
      r.glossy.push_back(g);
    }
    r.points.insert(r.points.end(), rows[y].begin(), rows[y].end());
    footprints.insert(footprints.end(), row_footprints[y].begin(), row_footprints[y].end());
    std::vector<VisiblePoint>().swap(rows[y]);
  }
  for (size_t p = 0; p < pixels; ++p) r.pixel_begin[p + 1] += r.pixel_begin[p];
  if (!footprints.empty()) {
    std::nth_element(footprints.begin(), footprints.begin() + footprints.size() / 2,
                     footprints.end());
    r.median_footprint = footprints[footprints.size() / 2];
  }
  return r;
}

float median_footprint(const World& world, const PinholeCamera& camera, int max_depth, int stride) {
  const size_t rows = size_t((camera.height() + stride - 1) / stride);
  std::vector<std::vector<float>> row_footprints(rows);
  parallel_for(rows, 1, [&](size_t begin, size_t end) {
    PixelOutput out;
    for (size_t r = begin; r < end; ++r) {
      out.footprints.clear();
      const int y = std::min(int(r) * stride + stride / 2, camera.height() - 1);
      for (int x = std::min(stride / 2, camera.width() - 1); x < camera.width(); x += stride)
        trace_pixel(world, camera, max_depth, x, y, out);
      row_footprints[r] = out.footprints;
    }
  });
  std::vector<float> all;
  for (const auto& row : row_footprints) all.insert(all.end(), row.begin(), row.end());
  if (all.empty()) return 0.0f;
  std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
  return all[all.size() / 2];
}

StridedColours colours_of(std::span<const VisiblePoint> points) {
  return {reinterpret_cast<const unsigned char*>(points.data()) + offsetof(VisiblePoint, f),
          sizeof(VisiblePoint), points.size()};
}

PixelLayout layout_of(const CameraPassResult& pass) {
  PixelLayout l;
  l.width = pass.width;
  l.height = pass.height;
  l.pixel_begin = pass.pixel_begin;
  l.emission = pass.emission;
  l.point_f = colours_of(pass.points);
  return l;
}

FilmSummary develop(const CameraPassResult& pass, const std::vector<PointState>& states,
                    uint64_t passes, const FilmSettings& settings, FilmImage* image) {
  return develop(layout_of(pass), states, passes, settings, image);
}

}  // namespace pb
