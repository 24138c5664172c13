// Pinhole camera rays through pixel centres or any point of a pixel (pixel (0, 0) is the
// top-left corner).
#pragma once

#include "scene/scene.h"

namespace pb {

class PinholeCamera {
 public:
  PinholeCamera(const Camera& camera, int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  const vec3& origin() const { return camera_.position; }
  const Camera& camera() const { return camera_; }
  // Unit direction through the centre of pixel (x, y).
  vec3 direction(int x, int y) const { return direction(float(x) + 0.5f, float(y) + 0.5f); }
  // Unit direction through the image point (px, py) in pixel units: pixel (x, y) covers
  // [x, x + 1) x [y, y + 1).
  vec3 direction(float px, float py) const;
  // Angle subtended by one pixel at the image centre (radians): the pixel footprint at
  // distance d is about d * pixel_angle().
  float pixel_angle() const { return 2.0f * tan_half_ / float(height_); }

 private:
  Camera camera_;
  int width_, height_;
  float tan_half_;  // tan(yfov / 2)
  float aspect_;    // width / height of the image: pixels are square
};

}  // namespace pb
