#include "scene/camera.h"

#include <cmath>

namespace pb {

PinholeCamera::PinholeCamera(const Camera& camera, int width, int height)
    : camera_(camera),
      width_(width),
      height_(height),
      tan_half_(std::tan(0.5f * camera.yfov)),
      aspect_(float(width) / float(height)) {}

vec3 PinholeCamera::direction(float px, float py) const {
  const float sx = (2.0f * px / float(width_) - 1.0f) * tan_half_ * aspect_;
  const float sy = (1.0f - 2.0f * py / float(height_)) * tan_half_;
  return glm::normalize(camera_.forward + sx * camera_.right + sy * camera_.up);
}

}  // namespace pb
