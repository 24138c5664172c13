// The camera a render looks through: the file's perspective camera (the first, or --camera
// NAME), or the default view of a file without one, with --look-from, --look-at, --up and --fov
// applied on top (docs/gltf.md "Cameras and the default view").
#pragma once

#include "options/options.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace pb {

// The default view frames the scene's bounds the way glTF viewers do: model-viewer's default
// orbit ("0deg 75deg 105%": from +Z, 15 degrees above the horizon, at 105% of the distance at
// which the bounding sphere just fills the narrower field of view), with the 45-degree vertical
// field of view of the Khronos glTF Sample Viewer and three.js's examples.
inline constexpr double kDefaultFovDegrees = 45.0;
inline constexpr double kDefaultElevationDegrees = 15.0;
inline constexpr double kDefaultDistanceFactor = 1.05;

// The default view of `bounds` for an image of aspect width / height, looking at `target`
// (the bounds' centre unless given) with vertical field of view yfov (radians).
Camera default_view(const Bounds& bounds, double aspect, double yfov);
Camera default_view(const Bounds& bounds, double aspect, double yfov, const vec3& target);

// True when the render uses the default view's position: the file has no perspective camera
// and --look-from is not given (main says so in one line).
bool uses_default_view(const Scene& scene, const RenderOptions& options);

// The camera and image size of a render. Throws UsageError when --camera names no camera of
// the file (the message lists those it has), or the view options give no direction (--look-at
// equal to the position, --up along the view direction).
PinholeCamera choose_camera(const Scene& scene, const RenderOptions& options);

}  // namespace pb
