// PPM with HJJ10's fixed visible points (ESTIMATOR.md sections 3-5): one camera pass through
// the pixel centres at the start, and every pass gathers at the same points.
#pragma once

#include "render/method.h"
#include "world/world.h"

#include <vector>

namespace pb {

// Stages 3-5 of pass in.pass at `points`, block by block of sums.size() points: the disc moments
// (with `clearance`, per point; empty: ask the boundary index for every disc) and next-event
// samples into `owner`, the gather into `sums` within those discs, then fold into `states` and
// `radii`. `glossy` is the points' glossy side table (CameraPassResult::glossy); `copy` (sized to
// the points) receives the new states. `regions` (one per chunk of kStageChunk points of a
// block) keeps each chunk's discs' regions from the moments to the gather. False when in.cutoff
// was reached before the first fold (nothing changed).
bool ppm_pass(const PassInputs& in, std::span<const VisiblePoint> points,
              std::span<const PointBsdf> glossy, std::span<const float> clearance,
              std::span<PointState> states, std::span<float> radii, std::span<PassSums> sums,
              std::span<OwnerValues> owner, PointState* copy, std::span<RegionTable> regions);

class PpmMethod final : public PhotonMethod {
 public:
  PpmMethod(const World& world, const PinholeCamera& camera, int max_depth);

  const CameraPassResult& camera_pass() const override { return pass_; }
  void prepare(const BoundaryIndex& boundary, double initial_radius) override;
  bool step(const PassInputs& in, std::span<PointState> states, std::span<float> radii,
            PointState* copy) override;
  void save(RenderState&) const override {}
  void restore(const RenderState& s) override;
  PixelLayout layout(const std::vector<PointState>& states,
                     const RenderState* saved) const override;

 private:
  CameraPassResult pass_;
  const BoundaryIndex* boundary_ = nullptr;
  std::vector<float> clearance_;  // per point, BoundaryIndex::clearance at the initial radius
  // With glossy points: the points with f times Bsdf::max_f for the sparse-photon bound.
  std::vector<VisiblePoint> capped_points_;
  std::vector<PassSums> sums_;        // one fold block's (pass_stages.h)
  std::vector<OwnerValues> owner_;    // the same block's
  std::vector<RegionTable> regions_;  // per chunk of the block: its discs' regions
};

}  // namespace pb
