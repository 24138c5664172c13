// The warnings and notes of a render, as the lines to print (each without its newline): what the
// options, the scene as the renderer sees it and the finished image say about the bounds.
// main.cpp prints them in order, on stderr.
#pragma once

#include "estimator/film.h"
#include "io/image_io.h"
#include "options/options.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pb {

class Renderer;

// --radius above this fraction of the scene size draws a warning (preflight_diagnostics).
inline constexpr double kRadiusWarnFraction = 0.05;
// The share of the view that back-face culling leaves out above which the render notes it.
inline constexpr double kCulledNoteShare = 0.01;

// Before the renderer is built: options that make the bounds unreliable or do nothing.
std::vector<std::string> option_diagnostics(const RenderOptions& options);
// Before the first pass: what the scene as the renderer built it means for the image and its
// bounds (glass PPM cannot follow, mirrors, culled faces, an opaque sky box, the boundary index
// given up, a radius of the scene's size).
std::vector<std::string> preflight_diagnostics(const RenderOptions& options,
                                               const Renderer& renderer);
// After the render of `passes` passes: none done, a dark image, a refuted bias model.
std::vector<std::string> result_diagnostics(const RenderOptions& options, const ExrView& image,
                                            const Scene& scene, const FilmSummary& summary,
                                            uint64_t passes);

}  // namespace pb
