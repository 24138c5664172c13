// Camera pass: one ray through each pixel centre, split deterministically at mirrors and
// dielectrics (ESTIMATOR.md section 5), ending in visible points on non-delta surfaces (a
// smooth coat over a diffuse base gives both: a point and the coat's mirror branch).
#pragma once

#include "estimator/estimator.h"
#include "estimator/film.h"
#include "scene/camera.h"
#include "world/world.h"

#include <cstdint>
#include <span>
#include <vector>

namespace pb {

struct VisiblePoint {
  // On the surface, lifted off it by its rounding error bound to the side the camera path
  // arrived from (World::spawn): next-event shadow rays start here, and the lift (~1e-7 of the
  // coordinates) is far below any gather radius.
  vec3 position{0.0f};
  vec3 normal{0.0f};   // geometric normal, on the side the camera path arrived from
  vec3 shading{0.0f};  // shading normal, same side
  // W_k f: the camera path's throughput W_k (Fresnel and tint factors) times the Lambertian
  // f = rho / pi. Folding W_k into the point's estimate makes every per-point quantity (X_j, B,
  // S^2) already weighted, so a pixel is the plain sum of its points (ESTIMATOR.md section 5
  // with W_k moved inside), and the point needs one colour instead of two.
  // On a non-Lambertian surface f is W_k alone, and the point's PointBsdf holds the rest.
  vec3 f{0.0f};
  uint32_t triangle = 0;  // World::triangle_index of the hit: the boundary index's key
};
static_assert(sizeof(VisiblePoint) == 52, "the per-point memory budget counts on 52 bytes");

// What a visible point on a non-Lambertian surface needs beside its VisiblePoint: the
// direction toward the camera and the Bsdf, so that the gather evaluates f(wo, wi) per photon
// and next-event estimation per light sample. Lambertian points (the common case) need none:
// PPM keeps these in a side table sorted by point index (CameraPassResult::glossy), so only
// glossy points pay for them; SPPM in a per-block scratch array.
struct PointBsdf {
  uint32_t point = 0;  // index of the VisiblePoint it belongs to (see where it is kept)
  vec3 wo{0.0f};       // unit, toward the camera
  Bsdf bsdf;
};

struct CameraPassResult {
  int width = 0, height = 0;
  std::vector<VisiblePoint> points;   // grouped by pixel, in pixel order
  std::vector<PointBsdf> glossy;      // the non-Lambertian points', sorted by point index
  std::vector<uint32_t> pixel_begin;  // points of pixel p: [pixel_begin[p], pixel_begin[p+1])
  std::vector<dvec3> emission;        // Le seen along exact specular chains, per pixel
  // Median over the points of the pixel footprint at the point (camera path length x pixel
  // angle): what the default initial radius is made from. 0 without points.
  float median_footprint = 0.0f;
};

// max_depth: the most specular bounces a camera path may take before it is cut.
CameraPassResult run_camera_pass(const World& world, const PinholeCamera& camera, int max_depth);

// The median pixel footprint over the visible points of the pixel-centre paths of every
// stride-th pixel in each direction (SPPM's default radius, without keeping the points); 0 when
// no path reaches a diffuse surface.
float median_footprint(const World& world, const PinholeCamera& camera, int max_depth, int stride);

// The points' W_k f as the film reads them (estimator/film.h, StridedColours).
StridedColours colours_of(std::span<const VisiblePoint> points);

// PPM's layout for the film (estimator/film.h): the points grouped by pixel, their colours and
// the emission the camera rays see exactly.
PixelLayout layout_of(const CameraPassResult& pass);
// develop() over PPM's layout (layout_of(pass)).
FilmSummary develop(const CameraPassResult& pass, const std::vector<PointState>& states,
                    uint64_t passes, const FilmSettings& settings, FilmImage* image);

}  // namespace pb
