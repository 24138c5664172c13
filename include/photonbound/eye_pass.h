// Camera pass: one ray through each pixel centre, split deterministically at mirrors and
// dielectrics (ESTIMATOR.md section 5), ending in measurement points on Lambertian surfaces.
#pragma once

#include "photonbound/camera.h"
#include "photonbound/world.h"

#include <cstdint>
#include <vector>

namespace pb {

struct MeasurementPoint {
  vec3 position{0.0f};
  vec3 normal{0.0f};   // geometric normal, on the side the camera path arrived from
  vec3 shading{0.0f};  // shading normal, same side
  vec3 brdf{0.0f};     // Lambertian f = rho / pi
  vec3 weight{0.0f};   // W_k: throughput of the camera path (Fresnel and tint factors)
  uint32_t pixel = 0;
  float footprint = 0.0f;  // pixel footprint at the point (camera path length x pixel angle)
};

struct EyePassResult {
  int width = 0, height = 0;
  std::vector<MeasurementPoint> points;  // grouped by pixel, in pixel order
  std::vector<uint32_t> pixel_begin;     // points of pixel p: [pixel_begin[p], pixel_begin[p+1])
  std::vector<dvec3> emission;           // Le seen along exact specular chains, per pixel
  uint64_t truncated_paths = 0;          // specular chains cut by the depth limit
};

// max_depth: the most specular bounces a camera path may take before it is cut.
EyePassResult run_eye_pass(const World& world, const PinholeCamera& camera, int max_depth);

}  // namespace pb
