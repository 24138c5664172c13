// SPPM's camera stage (ESTIMATOR.md section 10): every pass, one camera path per pixel through
// a uniformly jittered point of the pixel (box filter: the pixel estimates the average radiance
// over its area), keyed by (seed, pass, pixel). At a mirror or dielectric the path continues
// along one branch, chosen in proportion to its throughput and divided by that probability;
// the visible point is the first non-delta hit. Where a surface has both (a smooth coat over a
// diffuse base) the path stops there with Bsdf::delta_probability's complement, and both
// choices are divided by their probability. At a GGX lobe of roughness below
// follow_roughness (has_lobe_below, lobe_split.h) the path chooses, with lobe_probability, to
// follow the lobe (one next-event sample there with the lobe's f, then a direction drawn from
// the lobe; the emitters and environment the next ray finds directly are not counted again)
// or to stop with the diffuse base alone: a sharp lobe gathers almost no photons in its cone,
// so a visible point there has a noise and a sparse-photon bound (section 12) that fall
// slowly, while the surfaces it reflects are seen through it as through a mirror (pbrt-v4's
// SPPM follows glossy surfaces the same way). A visible point whose kernel disc lies almost
// wholly off reachable surface (mass below kValidKernelMass, ESTIMATOR.md section 11: a crevice,
// or a surface far smaller than the radius) has no sound photon estimate, so the path does not
// stop there: it takes the vertex's direct light and continues with one direction drawn from
// the non-delta part, as a path tracer would, and gathers at the next surface instead.
#pragma once

#include "estimator/estimator.h"
#include "render/camera_pass.h"
#include "scene/camera.h"
#include "world/boundary.h"
#include "world/world.h"

#include <cstdint>
#include <optional>
#include <span>

namespace pb {

struct CameraPathInputs {
  const World& world;
  const PinholeCamera& camera;
  int max_depth = 8;  // delta bounces (and followed lobes) a path may take
  // GGX lobes below this roughness are followed (--follow-roughness); 0: none. Needs the
  // next-event direct light, which counts the followed vertex's direct light.
  float follow_roughness = 0.0f;
  uint64_t seed = 0, pass = 0;
  // The next-event stage counts the visible points' direct light (--direct next-event): a
  // path continuing past a point with an invalid disc takes that point's sample itself.
  bool next_event = true;
  // Where surfaces end for the gather; null: every disc is whole (no vertex is passed over).
  const BoundaryIndex* boundary = nullptr;
};

// For pixels [first, first + points.size()) in row-major order: points[k] = pixel first + k's
// visible point this pass, its f the path throughput times the BRDF (f = 0 when the path ends
// without one: background, an emitter or a black surface, or the depth limit), and out[k] the
// pixel's owner values of the pass, whose direct part holds the emission the path saw on its way. A
// visible point on a non-Lambertian surface keeps the throughput alone in f, and its PointBsdf
// (point = k) goes to the front of `glossy` (room for points.size()), in pixel order. radii[k] is
// pixel first + k's search radius this pass; out[k].disc its visible point's disc moments. Returns
// the count of glossy points.
// The random-number key of a pixel's camera path number `path` in a pass (--adaptive paths,
// ESTIMATOR.md section 15): path 0 is keyed by the pixel alone, as before paths existed.
inline uint64_t path_item(uint64_t pixel, uint32_t path) { return pixel + (uint64_t(path) << 40); }

// One camera path of `pixel` (path number path_index): its visible point (f = 0: none) and
// owner values as trace_visible_points below gives them; the PointBsdf of a non-Lambertian
// point (its `point` member left 0).
// Where out.disc is not whole, `region` holds the region it integrates (the gather's).
std::optional<PointBsdf> trace_visible_point(const CameraPathInputs& in, size_t pixel,
                                             uint32_t path_index, float radius, VisiblePoint& point,
                                             OwnerValues& out, DiscRegion& region);

// `regions` receives (cleared first) the regions of the points whose discs are not whole.
// The camera rays of neighbouring pixels are traced as packets (World::camera_hits); every path
// is trace_visible_point's, bit for bit.
size_t trace_visible_points(const CameraPathInputs& in, size_t first, std::span<const float> radii,
                            std::span<VisiblePoint> points, std::span<PointBsdf> glossy,
                            std::span<OwnerValues> out, RegionTable& regions);

// The share of the camera's pixel-centre rays (on a grid of at most 128 x 128 of them) whose
// first hit passed through the back of a single-sided face (World::camera_hit): what glTF's
// back-face culling leaves out of the view, for a note to the user.
double culled_view_share(const World& world, const PinholeCamera& camera);

}  // namespace pb
