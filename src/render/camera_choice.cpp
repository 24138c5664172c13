#include "render/camera_choice.h"

#include <algorithm>
#include <cmath>

namespace pb {

namespace {

vec3 to_vec3(const std::array<double, 3>& v) { return vec3(float(v[0]), float(v[1]), float(v[2])); }

double radians(double degrees) { return degrees * kPiD / 180.0; }

// The camera's basis from a position, a view direction and an up hint (Gram-Schmidt); false
// when up lies along the direction.
bool orient(Camera& c, const dvec3& forward, const dvec3& up) {
  const dvec3 f = glm::normalize(forward);
  const dvec3 u = up - glm::dot(up, f) * f;
  if (!(glm::length(u) > 1e-6 * glm::length(up))) return false;
  c.forward = vec3(f);
  c.up = vec3(glm::normalize(u));
  c.right = glm::normalize(glm::cross(c.forward, c.up));
  return true;
}

std::string camera_list(const Scene& scene) {
  if (scene.cameras.empty()) return "it has none";
  std::string s = "its cameras: ";
  for (size_t k = 0; k < scene.cameras.size(); ++k)
    s += (k ? ", '" : "'") + scene.cameras[k].name + "'";
  return s;
}

}  // namespace

Camera default_view(const Bounds& b, double aspect, double yfov) {
  return default_view(b, aspect, yfov, 0.5f * (b.lo + b.hi));
}

Camera default_view(const Bounds& b, double aspect, double yfov, const vec3& target) {
  const dvec3 centre = 0.5 * (dvec3(b.lo) + dvec3(b.hi));
  const double radius = std::max(0.5 * glm::length(dvec3(b.hi) - dvec3(b.lo)), 1e-30);
  // The bounding sphere fills the narrower half-angle at radius / sin(half-angle).
  const double half = std::min(0.5 * yfov, std::atan(std::tan(0.5 * yfov) * aspect));
  const double e = radians(kDefaultElevationDegrees);
  const dvec3 back(0.0, std::sin(e), std::cos(e));  // from the target toward the camera
  // Looking at another point than the centre: farther by its distance from the centre, which
  // keeps the sphere inside the view cone about the new axis.
  const double distance =
      kDefaultDistanceFactor * radius / std::sin(half) + glm::length(dvec3(target) - centre);
  Camera c;
  c.name = "the default view";
  c.position = vec3(dvec3(target) + distance * back);
  c.yfov = float(yfov);
  orient(c, -back, dvec3(0.0, 1.0, 0.0));
  return c;
}

bool uses_default_view(const Scene& scene, const RenderOptions& o) {
  return scene.cameras.empty() && !o.look_from;
}

PinholeCamera choose_camera(const Scene& scene, const RenderOptions& o) {
  const Camera* file = nullptr;
  for (const Camera& c : scene.cameras) {
    if (o.camera.empty() || c.name == o.camera) {
      file = &c;
      break;
    }
  }
  if (!file && !o.camera.empty())
    throw UsageError("--camera: " + scene.source + " has no perspective camera named '" + o.camera +
                     "' (" + camera_list(scene) + ")");
  int w = 512, h = 512;
  const double aspect = file ? file->aspect.value_or(1.0f) : 1.0;
  if (o.width && o.height) {
    w = *o.width;
    h = *o.height;
  } else {
    h = std::clamp(int(std::lround(512.0 / aspect)), 1, 16384);
  }
  const double yfov = o.fov  ? radians(*o.fov)
                      : file ? double(file->yfov)
                             : radians(kDefaultFovDegrees);
  // --look-from and --look-at are points of the file's world; the scene may be stored about
  // another origin (Scene::origin).
  auto point = [&](const std::array<double, 3>& v) {
    return vec3(dvec3(v[0], v[1], v[2]) - scene.origin);
  };
  const vec3 centre = 0.5f * (scene.bounds.lo + scene.bounds.hi);
  Camera c = file ? *file
                  : default_view(scene.bounds, double(w) / double(h), yfov,
                                 o.look_at ? point(*o.look_at) : centre);
  c.yfov = float(yfov);
  if (o.look_from) c.position = point(*o.look_from);
  dvec3 forward(c.forward);
  if (o.look_at)
    forward = dvec3(point(*o.look_at)) - dvec3(c.position);
  else if (o.look_from)
    forward = dvec3(centre) - dvec3(c.position);
  if (!(glm::length(forward) > 0.0))
    throw UsageError(std::string(o.look_at ? "--look-at" : "--look-from") +
                     ": the view direction is zero (the camera is at the point it looks at)");
  if (o.up) {
    if (!orient(c, forward, dvec3(to_vec3(*o.up))))
      throw UsageError("--up: lies along the view direction");
  } else if (!orient(c, forward, dvec3(c.up)) && !orient(c, forward, dvec3(0, 1, 0))) {
    // The camera's up (the default view's is +Y), else +Y, else, looking straight along it, -Z
    // toward the image's top.
    orient(c, forward, dvec3(0, 0, -1));
  }
  return PinholeCamera(c, w, h);
}

}  // namespace pb
