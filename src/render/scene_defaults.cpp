#include "render/scene_defaults.h"

#include "estimator/channels.h"
#include "lights/lights.h"
#include "render/camera_choice.h"
#include "util/file_io.h"
#include "util/rng.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace pb {

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// --environment as a 1 x 1 map or a map file, times the scale.
Environment read_environment(const RenderOptions& o, uint64_t& hash) {
  Environment env;
  const float scale = float(o.environment_scale);
  const std::string& text = o.environment;
  if (environment_is_map(text)) {
    const RgbImage img = read_rgb_image(text, ReadLimit{memory_budget(o)});
    env.source = text;
    env.width = img.width;
    env.height = img.height;
    env.radiance.resize(size_t(img.width) * size_t(img.height));
    for (size_t p = 0; p < env.radiance.size(); ++p) {
      const vec3 v(img.rgb[3 * p], img.rgb[3 * p + 1], img.rgb[3 * p + 2]);
      if (!(is_finite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f))
        throw ImageError(text + ": pixel (" + std::to_string(p % size_t(img.width)) + ", " +
                         std::to_string(p / size_t(img.width)) +
                         ") is negative or not finite; an environment map holds radiance");
      env.radiance[p] = v * scale;
    }
    // The map is part of what the render is of: resume compares it like the scene's buffers.
    hash = mix64(hash ^ checksum(img.rgb.data(), img.rgb.size() * sizeof(float)));
    return env;
  }
  const std::array<double, 3> c = environment_colour(text);
  const vec3 rgb = vec3(float(c[0]), float(c[1]), float(c[2]));
  env.source = "--environment " + text;
  env.radiance = {rgb * scale};
  return env;
}

}  // namespace

std::vector<std::string> complete_scene(Scene& scene, const RenderOptions& o) {
  std::vector<std::string> notes;
  if (!scene.environment) {
    if (!o.environment.empty()) {
      scene.environment = read_environment(o, scene.content_hash);
    } else if (!has_light(scene)) {
      Environment sky;
      sky.source = "the default sky";
      sky.radiance = {vec3(kDefaultSkyRadiance * float(o.environment_scale))};
      scene.environment = std::move(sky);
      notes.push_back(scene.source +
                      " has no light: lit by the default sky, a uniform environment "
                      "of radiance " +
                      number(kDefaultSkyRadiance * o.environment_scale) +
                      " (--environment changes it)");
    }
  }
  if (!has_light(scene))
    throw SceneError(scene.source + ": no light: the scene has none and " +
                     scene.environment->source + " is black");
  const double power = total_emitted_power(scene);
  if (!(power <= double(std::numeric_limits<float>::max())))
    throw SceneError(scene.source + ": the lights and " + scene.environment->source + " emit " +
                     number(power) +
                     " W in total, beyond the float range (3.4e+38) photon power is carried in");
  if (uses_default_view(scene, o))
    notes.push_back(scene.source + " has no camera: the default view frames its bounds (from +Z, " +
                    number(kDefaultElevationDegrees) + " degrees above, " +
                    number(o.fov.value_or(kDefaultFovDegrees)) +
                    " degrees field of view; --look-from, --look-at, --up and --fov change it)");
  return notes;
}

// Lit only by the emission of its materials, with no punctual light and no environment: a model
// made to be shown under a viewer's environment (glTF sample models with emissive details, the
// DamagedHelmet among them) then renders as a few glowing parts on black, and the image's mean
// can stay above kDarkRadiance. Emission is light, so the default sky is not added (an enclosed
// or emitter-lit scene must not gain light its author did not put there); the warning says what
// the user can add instead.
namespace {

std::optional<std::string> mostly_dark_warning(const ExrView& image, const int rgb[3],
                                               const Scene& scene) {
  if (scene.environment) return std::nullopt;
  for (const PunctualLight& l : scene.lights)
    if (max_component(l.intensity) > 0.0f) return std::nullopt;
  const size_t pixels = image.planes.empty() ? 0 : size_t(image.width) * size_t(image.height);
  size_t dark = 0;
  for (size_t p = 0; p < pixels; ++p) {
    float brightest = 0.0f;
    for (int c = 0; c < 3; ++c) brightest = std::max(brightest, image.at(size_t(rgb[c]), p));
    dark += double(brightest) < kDarkRadiance;
  }
  const double share = pixels ? double(dark) / double(pixels) : 0.0;
  if (share <= kMostlyDarkShare) return std::nullopt;
  return "the image is mostly black (" + number(std::round(100.0 * share)) +
         "% of the pixels): its only light is the emission of its materials, with no punctual "
         "light and no environment; a model meant to be seen lit from around, as glTF viewers "
         "show it, needs --environment (--environment 1 is the default sky)";
}

}  // namespace

std::optional<std::string> dark_image_warning(const ExrView& image, const Scene& scene) {
  int rgb[3];
  for (int c = 0; c < 3; ++c) rgb[c] = image.channel_index(channel_name(Channel::Radiance, c));
  if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) return std::nullopt;
  const size_t pixels = image.planes.empty() ? 0 : size_t(image.width) * size_t(image.height);
  double sum = 0.0;
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) sum += double(image.at(size_t(rgb[c]), p));
  const double mean = pixels ? sum / double(3 * pixels) : 0.0;
  if (mean >= kDarkRadiance) return mostly_dark_warning(image, rgb, scene);
  std::string w = std::string(mean > 0.0 ? "the image is nearly black" : "the image is black") +
                  " (mean radiance " + number(mean) + "): no light reaches what the camera sees";
  w += scene.environment ? "" : " and the scene has no environment (--environment)";
  w += "; check that the lights are not enclosed or behind what they should light (emitters are "
       "one-sided), that the camera is not inside an object, and the lights' units (W/sr; "
       "directional W/m^2)";
  if (mean > 0.0) w += "; photonbound preview --exposure brightens a dark but correct image";
  return w;
}

}  // namespace pb
