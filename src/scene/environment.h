// The environment light's radiance lookup and importance sampling over an equirectangular map
// (scene.h Environment), for photons, next-event estimation and camera rays that miss.
#pragma once

#include "scene/scene.h"

#include <vector>

namespace pb {

class EnvironmentLight {
 public:
  // Keeps a pointer to env's pixels: env must outlive it (World owns the Scene it points into).
  explicit EnvironmentLight(const Environment& env);

  // Radiance arriving from direction dir (unit, pointing from the scene toward the environment):
  // the map's pixel that contains dir, so that lookup and sampling agree exactly.
  vec3 radiance(const vec3& dir) const;

  // A direction toward the environment, from four uniform numbers: a pixel in proportion to its
  // mean radiance (over RGB) times its solid angle, then a direction uniform in that pixel's
  // solid angle (uniform azimuth and cos theta; pbrt-v3's InfiniteAreaLight samples a pixel by
  // radiance x sin theta instead, whose pdf varies within the pixel). pdf: solid-angle density,
  // constant within a pixel; 0 when the map is black.
  vec3 sample(float u0, float u1, float u2, float u3, float& pdf) const;
  float pdf(const vec3& dir) const;

  // Integral of the radiance over the sphere, per channel (W/m^2 per unit of radiance x sr).
  vec3 integral() const { return integral_; }
  // The largest channel of radiance / pdf over the directions sample() draws: what one photon
  // of the environment carries at most, per unit of pi r^2 (Lights::max_photon_flux).
  float max_radiance_over_pdf() const { return max_over_pdf_; }
  bool uniform() const { return width_ == 1 && height_ == 1; }

 private:
  // (x, y) of the pixel containing dir.
  void pixel_of(const vec3& dir, int& x, int& y) const;
  float cos_theta(int row) const;  // cos of the polar angle of the top edge of `row`

  const vec3* pixels_;
  int width_, height_;
  // Pixel weights w = mean radiance x solid angle: rows by their sum (row_cdf_, height + 1
  // entries from 0 to 1), columns within a row (column_cdf_, width + 1 entries per row, float to
  // keep a 4k map's tables at 4 bytes a pixel). Sampling and pdf() read the same tables.
  std::vector<double> row_cdf_;
  std::vector<float> column_cdf_;
  vec3 integral_{0.0f};
  float max_over_pdf_ = 0.0f;
};

}  // namespace pb
