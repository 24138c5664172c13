// Renderer::image: the EXR layout (README "Output") and its metadata.
#include "photonbound/renderer.h"

namespace pb {

ExrImage pack_channels(const FilmImage& film) {
  ExrImage out;
  out.width = film.width;
  out.height = film.height;
  // Each RGB quantity becomes three channels "<Name>.R/G/B"; radiance is plain R, G, B.
  const std::vector<std::pair<std::string, const std::vector<float>*>> rgb = {
      {"", &film.radiance},
      {"ErrorBound.", &film.bound},
      {"Bias.", &film.bias},
      {"Noise.", &film.noise},
      {"Variance.", &film.variance}};
  for (const auto& [prefix, data] : rgb)
    for (const char* c : {"R", "G", "B"}) out.channels.push_back(prefix + c);
  out.channels.push_back("Photons");
  out.channels.push_back("Radius");

  const size_t pixels = size_t(film.width) * size_t(film.height);
  const size_t nc = out.channels.size();
  out.pixels.resize(pixels * nc);
  for (size_t p = 0; p < pixels; ++p) {
    float* dst = &out.pixels[p * nc];
    size_t c = 0;
    for (const auto& entry : rgb)
      for (int k = 0; k < 3; ++k) dst[c++] = (*entry.second)[3 * p + k];
    dst[c++] = film.photons[p];
    dst[c++] = film.radius[p];
  }
  return out;
}

ExrImage Renderer::image(const RenderReport& report, const std::vector<PointState>& states) const {
  FilmImage film;
  const FilmSummary summary = develop(eye_, states, report.passes, film_settings(), &film);
  ExrImage out = pack_channels(film);
  out.metadata = describe(options_);
  out.metadata.insert(out.metadata.end(),
                      {
                          {"version", PHOTONBOUND_VERSION},
                          {"command_line", options_.command_line},
                          {"passes_done", std::to_string(report.passes)},
                          {"photons_emitted", std::to_string(report.photons)},
                          {"seconds", number_text(report.seconds)},
                          {"stop_reason", report.stop_reason},
                          {"initial_radius", number_text(report.initial_radius)},
                          {"mean_error_bound", number_text(summary.mean_bound)},
                          {"unknown_pixels", std::to_string(summary.unknown_pixels)},
                          {"measurement_points", std::to_string(eye_.points.size())},
                      });
  return out;
}

}  // namespace pb
