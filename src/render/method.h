// The interface both methods implement (PPM: ppm.h, SPPM: sppm.h), so that the renderer runs a
// pass, saves and restores a render and develops its film without asking which method it runs.
// The renderer owns what both share (the states, their radii, the photons and their grid); a
// method owns its visible points and the side state of its pixels.
#pragma once

#include "estimator/estimator.h"
#include "estimator/film.h"
#include "render/camera_pass.h"
#include "render/pass_stages.h"
#include "world/boundary.h"

#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

namespace pb {

// A saved render that does not fit this one (Renderer::restore); the state file's format is
// app/checkpoint.h's.
class StateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The work done so far, part of every state.
struct WorkCounters {
  uint64_t passes = 0;
  uint64_t photons = 0;  // emitted, all passes
  uint64_t rays = 0;     // photon-pass rays, all passes
};

// Everything a state file holds of the render itself.
struct RenderState {
  WorkCounters work;
  double initial_radius = 0.0;
  std::vector<PointState> states;  // PPM: one per visible point; SPPM: one per pixel
  std::vector<uint32_t> visible;   // SPPM: passes with a visible point, per pixel
  std::vector<float> min_mass;     // SPPM: smallest kernel mass of a visible point, per pixel
  double max_photon_power = 0.0;   // largest channel of a photon's power seen (section 12)
  std::vector<float> glossy_f;     // SPPM: largest f / c a glossy visible point had, per pixel
  // --adaptive photons: the photon guide's running histogram and the passes it has learnt
  // (render/photon_guide.h); empty without.
  std::vector<double> guide;
  uint64_t guide_learnt = 0;
  // --adaptive paths: per pixel, its PathHistory (render/path_allocation.h) as three floats;
  // empty without.
  std::vector<float> path_history;
};

// One array of the method's side state with an item per state (a distributed render brings
// the items of every rank's states to rank 0, renderer.h collect()).
struct SideArray {
  void* data = nullptr;
  size_t item_bytes = 0;
};

class PhotonMethod {
 public:
  virtual ~PhotonMethod() = default;

  // PPM: the visible points. SPPM: the image size and the median footprint only.
  virtual const CameraPassResult& camera_pass() const = 0;
  // The states the method keeps: one per visible point (PPM) or pixel (SPPM).
  size_t state_count() const { return state_count_; }
  // Once the initial radius is known: what the method precomputes against the boundary index.
  virtual void prepare(const BoundaryIndex& boundary, double initial_radius) = 0;

  // Stages 0 and 3-5 of pass in.pass (pass_stages.h) over every state, block by block; the
  // renderer has traced the photons and built the grid (stages 1-2). `copy` (sized to the
  // states) receives the new states. False when in.cutoff was reached during the first block's
  // gather: nothing was changed (no state, no side state), and the pass is to be discarded.
  virtual bool step(const PassInputs& in, std::span<PointState> states, std::span<float> radii,
                    PointState* copy) = 0;

  // The method's side state into a snapshot, and back (StateError when it does not fit).
  virtual void save(RenderState& s) const = 0;
  virtual void restore(const RenderState& s) = 0;
  // The side state's per-state arrays (none by default).
  virtual std::vector<SideArray> side_arrays() { return {}; }
  // Which of `states` make up each pixel (estimator/film.h), with the method's side state of a
  // snapshot (`saved`) or, without one, its current side state. The renderer adds the photon
  // cap and the footprint, which do not depend on the method.
  virtual PixelLayout layout(const std::vector<PointState>& states,
                             const RenderState* saved) const = 0;

 protected:
  size_t state_count_ = 0;
};

}  // namespace pb
