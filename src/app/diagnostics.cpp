#include "app/diagnostics.h"

#include "render/camera_paths.h"
#include "render/renderer.h"
#include "render/scene_defaults.h"

#include <iomanip>
#include <sstream>

namespace pb {

namespace {

// An environment outside a closed shell around the camera lights nothing it sees: a sky box or
// dome drawn for glTF viewers (which light it by the environment, without shadows) is opaque
// here. Said before the render, which would come out black.
void add_enclosure_warning(const RenderOptions& options, const Renderer& renderer,
                           std::vector<std::string>& lines) {
  const Scene& sc = renderer.world().scene();
  if (!sc.environment) return;
  const auto shell = renderer.world().camera_enclosure(renderer.camera().origin());
  if (!shell) return;
  std::string outer;
  for (const auto& [mesh, share] : shell->outermost) {
    std::ostringstream item;
    item << "'" << mesh << "' in " << std::setprecision(3) << 100.0 * share << "%";
    outer += (outer.empty() ? " (outermost: mesh " : ", ") + item.str();
  }
  if (!outer.empty()) outer += " of the directions)";
  std::ostringstream line;
  line << "photonbound: warning: " << options.scene
       << ": every ray from the camera meets a surface before the environment" << outer << ", so "
       << sc.environment->source
       << " cannot light what the camera sees; a sky box or dome made for viewers is opaque to "
          "light here: remove it from the file, or light the scene inside it";
  lines.push_back(line.str());
}

// PPM's points are fixed, so it cannot follow rough glass or diffuse transmission through a
// surface (bsdf.h BsdfParams::follows_transmission); which materials the mirror threshold turns
// into perfect mirrors (a choice, not a flaw).
void add_material_lines(const RenderOptions& options, const Renderer& renderer,
                        std::vector<std::string>& lines) {
  if (const std::string glass = renderer.world().followed_transmission_names();
      !glass.empty() && options.method == Method::PPM)
    lines.push_back("photonbound: warning: " + options.scene + ": " + glass +
                    ": rough and diffuse transmission are rendered by --method ppm as smooth "
                    "glass and as diffuse reflection (its fixed points cannot follow a path "
                    "through a surface); --method sppm renders them");
  if (const std::string note = renderer.world().mirror_note();
      !note.empty() && options.progress != ProgressMode::Never)
    lines.push_back("photonbound: note: " + options.scene + ": " + note);
}

// glTF's back-face culling (World::camera_hit) can leave out much of a view: say so, since a
// renderer that draws every face (a path tracer ignoring doubleSided) shows another picture.
void add_culling_note(const RenderOptions& options, const Renderer& renderer,
                      std::vector<std::string>& lines) {
  const double culled = culled_view_share(renderer.world(), renderer.camera());
  if (!(culled >= kCulledNoteShare && options.progress != ProgressMode::Never)) return;
  std::ostringstream line;
  line << "photonbound: note: " << options.scene << ": " << std::setprecision(3) << 100.0 * culled
       << std::setprecision(6)
       << "% of the view looks through the back of single-sided faces (doubleSided false), which "
          "glTF culls as its viewers do; a face meant to be seen from behind needs doubleSided "
          "true";
  lines.push_back(line.str());
}

}  // namespace

// ESTIMATOR.md section 8: options under which the bounds are unreliable or that do nothing.
std::vector<std::string> option_diagnostics(const RenderOptions& options) {
  std::vector<std::string> lines;
  // With error estimation the accumulated Laplacian converges only for alpha > 2/3, so the bias
  // part of the bound is unreliable below it.
  if (options.alpha <= 2.0 / 3.0) {
    std::ostringstream line;
    line << "photonbound: warning: --alpha " << options.alpha
         << " is at or below 2/3: the Laplacian (bias) estimate does not converge and the error "
            "bounds are unreliable";
    lines.push_back(line.str());
  }
  // The default is silent where following does not apply; a chosen value is not.
  if (options.follow_roughness > 0.0 && options.follow_roughness != kDefaultFollowRoughness &&
      (options.method == Method::PPM || options.direct != DirectMode::NextEvent))
    lines.push_back(
        "photonbound: warning: --follow-roughness does nothing here: it needs --method sppm with "
        "next-event direct light");
  // docs/error-bounds.md "The mean-error stop with the adaptive parts, earlier rows": with paths
  // and the Laplacian's bias alone the rule held for 11 of 20 runs at the Cornell box's tightest
  // target, not 18 (the contact shadows' fourth-order bias, ESTIMATOR.md section 6c).
  if (options.adaptive_paths && options.method == Method::SPPM && options.target_error &&
      options.stop_rule == StopRule::MeanError && options.bias_model == BiasModel::Laplacian)
    lines.push_back(
        "photonbound: warning: with --adaptive paths and --bias-model laplacian the mean-error "
        "stop is not calibrated at tight targets (docs/error-bounds.md): use --bias-model "
        "two-scale, the default");
  // PPM's visible points are fixed by its one camera pass: there are no paths to add.
  if (options.adaptive_paths && options.method == Method::PPM)
    lines.push_back(
        "photonbound: warning: --adaptive paths does nothing here: PPM traces its camera paths "
        "once (--method sppm traces them every pass)");
  return lines;
}

// ESTIMATOR.md sections 2 and 11: what the scene as rendered means for the image and its bounds.
std::vector<std::string> preflight_diagnostics(const RenderOptions& options,
                                               const Renderer& renderer) {
  std::vector<std::string> lines;
  add_material_lines(options, renderer, lines);
  add_culling_note(options, renderer, lines);
  add_enclosure_warning(options, renderer, lines);
  // The bias term models the radiance as smooth (second order) within the radius. A radius of
  // the scene's size breaks that (the extremes suite measured a bound of 0.128 against an error
  // of ~1 at R = scene size), so say so rather than report a bound that cannot be trusted.
  if (renderer.boundary().truncated())
    lines.push_back("photonbound: warning: " + options.scene +
                    ": too many boundary segments, or triangles piled at one place, within the "
                    "radius for the boundary correction (ESTIMATOR.md section 11); every disc "
                    "counts as whole, so bounds along edges may be too small (a higher "
                    "--resolution or a smaller --radius avoids this)");
  if (options.radius && *options.radius > kRadiusWarnFraction * renderer.world().scene_size()) {
    std::ostringstream line;
    line << "photonbound: warning: --radius " << *options.radius << " is " << std::setprecision(3)
         << 100.0 * *options.radius / renderer.world().scene_size() << std::setprecision(6)
         << "% of the scene size: the bias estimate assumes the radiance is smooth within the "
            "radius, so the error bounds may be far too small until the radii shrink";
    lines.push_back(line.str());
  }
  return lines;
}

// ESTIMATOR.md sections 11b and 11c: a refuted bias model leaves every photon bound unknown.
std::vector<std::string> result_diagnostics(const RenderOptions& options, const ExrView& image,
                                            const Scene& scene, const FilmSummary& summary,
                                            uint64_t passes) {
  std::vector<std::string> lines;
  // Ctrl-C or the end of --time during the first pass: that pass is discarded (Driver::run),
  // and an image without passes is black for want of photons, not of light.
  if (passes == 0) {
    lines.push_back("photonbound: warning: " + options.scene +
                    ": the render stopped before its first pass was whole, so the image holds "
                    "no light and every bound is unknown (a longer --time, or fewer "
                    "--photons-per-pass, gives it passes)");
    return lines;
  }
  if (const auto dark = dark_image_warning(image, scene))
    lines.push_back("photonbound: warning: " + options.scene + ": " + *dark);
  if (summary.model_refuted) {
    std::ostringstream line;
    line << "photonbound: warning: " << options.scene
         << ": every error bound with a photon part is unknown: the bias model fails at this "
            "radius (in "
         << std::setprecision(3) << 100.0 * summary.slope_disagreement
         << "% of the points' channels the samples' drift with the radius disagrees with the "
            "Laplacian, in "
         << 100.0 * summary.scale_disagreement << std::setprecision(6)
         << "% of the points the kernel at half the radius does); start with a smaller --radius";
    lines.push_back(line.str());
  }
  return lines;
}

}  // namespace pb
