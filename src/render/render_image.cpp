// Renderer::image: the EXR layout (channels.def) and its metadata.
#include "render/renderer.h"

#include "estimator/channels.h"
#include "util/parallel.h"

#include <vector>

namespace pb {

ExrView film_view(const FilmImage& film) {
  ExrView out;
  out.width = film.width;
  out.height = film.height;
  out.channels = channel_names();
  for (const ChannelGroup& g : kChannelGroups) {
    const size_t n = g.kind == ChannelKind::RGB ? 3 : 1;
    for (size_t k = 0; k < n; ++k) out.planes.push_back({film.plane(g.id).data() + k, n});
  }
  return out;
}

ExrImage Renderer::image(const RunInfo& run) const {
  FilmImage film;
  const FilmSummary summary = develop(&film);
  return packed(view(run, film, summary, work_, initial_radius_, states_.size()));
}

ExrImage Renderer::image(const RunInfo& run, const RenderState& state) const {
  FilmImage film;
  const FilmSummary summary = develop(state, &film);
  return packed(view(run, film, summary, state.work, state.initial_radius, state.states.size()));
}

ExrView Renderer::view(const RunInfo& run, const FilmImage& film, const FilmSummary& summary,
                       const WorkCounters& work, double initial_radius, size_t states) const {
  // The EXR is the render's end, or a checkpoint's: the next stop test is passes away.
  develop_memory_.release();
  ExrView out = film_view(film);
  out.metadata = describe(options_);
  out.metadata.insert(out.metadata.end(),
                      {
                          {"version", PHOTONBOUND_VERSION},
                          {"command_line", options_.command_line},
                          {"passes_done", std::to_string(work.passes)},
                          {"photons_emitted", std::to_string(work.photons)},
                          {"seconds", number_text(run.seconds)},
                          {"stop_reason", run.stop_reason},
                          {"initial_radius", number_text(initial_radius)},
                          {"mean_error_bound", number_text(summary.mean_bound)},
                          {"unknown_pixels", std::to_string(summary.unknown_pixels)},
                          {"estimator_states", std::to_string(states)},
                      });
  // The view rendered, in the file's coordinates: the values of --look-from, --look-at, --up
  // and --fov that reproduce it here or frame it in another renderer (the entries above say
  // only how it was chosen, e.g. "the camera's, or 45").
  const Camera& c = camera_.camera();
  const dvec3 origin = world_.scene().origin;
  auto triple = [](const dvec3& p) {
    return number_text(p.x) + "," + number_text(p.y) + "," + number_text(p.z);
  };
  out.metadata.insert(out.metadata.end(),
                      {
                          {"view_from", triple(dvec3(c.position) + origin)},
                          {"view_at", triple(dvec3(c.position + c.forward) + origin)},
                          {"view_up", triple(dvec3(c.up))},
                          {"view_fov", number_text(double(c.yfov) * 180.0 / kPiD)},
                      });
  return out;
}

}  // namespace pb
