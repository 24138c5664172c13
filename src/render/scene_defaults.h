// What a render adds to a loaded scene before it is prepared (docs/gltf.md "Cameras and the default
// view", "Environment light and the default sky"): the environment light of --environment, or the
// default sky when the file has no light at all; and the lines that tell the user what was assumed.
#pragma once

#include "io/image_io.h"
#include "options/options.h"
#include "scene/scene.h"

#include <optional>
#include <string>
#include <vector>

namespace pb {

// The default sky of a scene without any light: a uniform environment of radiance 1 (times
// --environment-scale). A convex Lambertian surface of reflectance rho then shows exactly rho,
// so the image reads as the materials' colours with the occlusion between objects, like a glTF
// viewer's neutral environment.
inline constexpr float kDefaultSkyRadiance = 1.0f;

// Adds --environment (a colour, or a map read through image_io) or the default sky to `scene`,
// mixing a map's pixels into scene.content_hash (resume then refuses an edited map). Returns the
// notes to print, one line each: the default sky, the default view. Calling it again changes
// nothing. Throws SceneError (naming the file) when the scene is left without light, or its
// lights' power overflows float; ImageError when the map cannot be read or has negative or
// non-finite pixels.
std::vector<std::string> complete_scene(Scene& scene, const RenderOptions& options);

// Radiance below which a pixel shows black in an 8-bit sRGB preview at exposure 0
// (12.92 x 1.5e-4 x 255 < 0.5).
inline constexpr double kDarkRadiance = 1.5e-4;

// The share of pixels below kDarkRadiance (every channel) above which an image lit only by its
// materials' emission is called mostly black.
inline constexpr double kMostlyDarkShare = 0.75;

// A warning for a finished image that is black or nearly so (mean radiance over pixels and RGB
// below kDarkRadiance), or, lit only by emissive materials (no punctual light, no environment),
// mostly black (more than kMostlyDarkShare of its pixels below kDarkRadiance), saying what might
// be missing; none otherwise.
std::optional<std::string> dark_image_warning(const ExrView& image, const Scene& scene);

}  // namespace pb
