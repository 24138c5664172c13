#include "scene/environment.h"

#include <algorithm>
#include <cmath>

namespace pb {

EnvironmentLight::EnvironmentLight(const Environment& env)
    : pixels_(env.radiance.data()), width_(env.width), height_(env.height) {
  const size_t w = size_t(width_), h = size_t(height_);
  row_cdf_.assign(h + 1, 0.0);
  column_cdf_.assign(h * (w + 1), 0.0f);
  std::vector<double> row(w + 1);
  dvec3 integral(0.0);
  for (size_t y = 0; y < h; ++y) {
    // Solid angle of a pixel of this row: (2 pi / W) (cos theta_top - cos theta_bottom).
    const double omega =
        2.0 * kPiD / double(w) * (double(cos_theta(int(y))) - cos_theta(int(y) + 1));
    row[0] = 0.0;
    for (size_t x = 0; x < w; ++x) {
      const dvec3 l(pixels_[y * w + x]);
      integral += l * omega;
      row[x + 1] = row[x] + (l.x + l.y + l.z) / 3.0 * omega;
    }
    row_cdf_[y + 1] = row_cdf_[y] + row[w];
    float* c = column_cdf_.data() + y * (w + 1);
    for (size_t x = 0; x <= w; ++x) c[x] = row[w] > 0.0 ? float(row[x] / row[w]) : 0.0f;
    if (row[w] > 0.0) c[w] = 1.0f;
  }
  const double total = row_cdf_[h];
  for (double& v : row_cdf_) v = total > 0.0 ? v / total : 0.0;
  if (total > 0.0) row_cdf_[h] = 1.0;
  integral_ = vec3(integral);
  // radiance / pdf in a pixel: L omega / P(pixel), with P from the same tables sample() uses.
  for (size_t y = 0; y < h; ++y) {
    const double omega =
        2.0 * kPiD / double(w) * (double(cos_theta(int(y))) - cos_theta(int(y) + 1));
    const float* c = column_cdf_.data() + y * (w + 1);
    for (size_t x = 0; x < w; ++x) {
      const double p = (row_cdf_[y + 1] - row_cdf_[y]) * double(c[x + 1] - c[x]);
      if (p > 0.0)
        max_over_pdf_ =
            std::max(max_over_pdf_, float(double(max_component(pixels_[y * w + x])) * omega / p));
    }
  }
}

float EnvironmentLight::cos_theta(int row) const {
  // Exact at the poles and the equator of an even height, so that the rows' solid angles sum to
  // 4 pi to rounding.
  if (row <= 0) return 1.0f;
  if (row >= height_) return -1.0f;
  return float(std::cos(kPiD * double(row) / double(height_)));
}

void EnvironmentLight::pixel_of(const vec3& dir, int& x, int& y) const {
  // d = (-sin theta sin phi, cos theta, sin theta cos phi) (scene.h Environment).
  const float theta = std::acos(std::clamp(dir.y, -1.0f, 1.0f));
  float phi = std::atan2(-dir.x, dir.z);
  if (phi < 0.0f) phi += 2.0f * kPi;
  y = std::clamp(int(theta / kPi * float(height_)), 0, height_ - 1);
  x = std::clamp(int(phi / (2.0f * kPi) * float(width_)), 0, width_ - 1);
  // The row's edges are cos_theta() values: a direction on the wrong side of one by rounding of
  // acos belongs to the neighbour, whose pdf sampling used.
  if (dir.y > cos_theta(y) && y > 0) --y;
  if (dir.y < cos_theta(y + 1) && y + 1 < height_) ++y;
}

vec3 EnvironmentLight::radiance(const vec3& dir) const {
  if (uniform()) return pixels_[0];
  int x, y;
  pixel_of(dir, x, y);
  return pixels_[size_t(y) * size_t(width_) + size_t(x)];
}

vec3 EnvironmentLight::sample(float u0, float u1, float u2, float u3, float& pdf) const {
  pdf = 0.0f;
  if (!(row_cdf_.back() > 0.0)) return vec3(0.0f, 1.0f, 0.0f);
  const size_t w = size_t(width_);
  // The interval [cdf[k], cdf[k + 1]) holding u; empty intervals are never chosen.
  const auto y = size_t(std::upper_bound(row_cdf_.begin() + 1, row_cdf_.end() - 1, double(u0)) -
                        row_cdf_.begin() - 1);
  const float* c = column_cdf_.data() + y * (w + 1);
  const auto x = size_t(std::upper_bound(c + 1, c + w, u1) - c - 1);
  const double p_pixel = (row_cdf_[y + 1] - row_cdf_[y]) * double(c[x + 1] - c[x]);
  const float top = cos_theta(int(y)), bottom = cos_theta(int(y) + 1);
  const double omega = 2.0 * kPiD / double(w) * (double(top) - bottom);
  if (!(p_pixel > 0.0 && omega > 0.0)) return vec3(0.0f, 1.0f, 0.0f);
  const float phi = 2.0f * kPi * (float(x) + u2) / float(w);
  const float cos = std::clamp(top - u3 * (top - bottom), -1.0f, 1.0f);
  const float sin = std::sqrt(std::max(0.0f, 1.0f - cos * cos));
  pdf = float(p_pixel / omega);
  return vec3(-sin * std::sin(phi), cos, sin * std::cos(phi));
}

float EnvironmentLight::pdf(const vec3& dir) const {
  if (!(row_cdf_.back() > 0.0)) return 0.0f;
  int x, y;
  pixel_of(dir, x, y);
  const size_t w = size_t(width_);
  const float* c = column_cdf_.data() + size_t(y) * (w + 1);
  const double p_pixel = (row_cdf_[size_t(y) + 1] - row_cdf_[size_t(y)]) * double(c[x + 1] - c[x]);
  const double omega = 2.0 * kPiD / double(w) * (double(cos_theta(y)) - cos_theta(y + 1));
  return omega > 0.0 ? float(p_pixel / omega) : 0.0f;
}

}  // namespace pb
