// Stochastic PPM (Hachisuka, Jensen 2009; ESTIMATOR.md section 10): every pass traces one
// camera path per pixel through a jittered point of it (camera_paths.h) and gathers at the
// visible point it finds; the state, radius and statistics are per pixel.
#pragma once

#include "render/camera_paths.h"
#include "render/method.h"
#include "render/path_allocation.h"
#include "world/world.h"

#include <vector>

namespace pb {

// What the camera paths of every pass take from the options.
struct CameraPathSettings {
  int max_depth = 8;
  float follow_roughness = 0.0f;  // 0 without next-event direct light (camera_paths.h)
  bool adaptive_paths = false;    // --adaptive paths (ESTIMATOR.md section 15)
};

class SppmMethod final : public PhotonMethod {
 public:
  SppmMethod(const World& world, const PinholeCamera& camera, CameraPathSettings settings);

  const CameraPassResult& camera_pass() const override { return pass_; }
  void prepare(const BoundaryIndex&, double) override {}
  bool step(const PassInputs& in, std::span<PointState> states, std::span<float> radii,
            PointState* copy) override;
  void save(RenderState& s) const override;
  void restore(const RenderState& s) override;
  std::vector<SideArray> side_arrays() override {
    std::vector<SideArray> a{{visible_.data(), sizeof(uint32_t)},
                             {min_mass_.data(), sizeof(float)},
                             {glossy_f_.data(), sizeof(float)}};
    // --adaptive paths: each pixel's path history, kept by the rank that owns it.
    if (!history_.empty()) a.push_back({history_.data(), sizeof(PathHistory)});
    return a;
  }
  PixelLayout layout(const std::vector<PointState>& states,
                     const RenderState* saved) const override;

 private:
  // --adaptive paths (ESTIMATOR.md section 15): what a pixel's paths beyond the first add to
  // its side state, kept until the pass is known to go on.
  struct ExtraPaths {
    float primary_mass = 1.0f;  // the first path's kernel mass (its owner values are replaced)
    float mass = 1.0f;          // the smallest over the other paths' visible points
    float ratio = 0.0f;         // their largest glossy f / c
    float spread = 0.0f;        // PathMean::spread of the pass
    bool combined = false;      // the pixel had more than one path this pass
  };

  // Stage 0's side of a chunk's visible points for the film (ESTIMATOR.md section 12): counts
  // each pixel's passes with a visible point, keeps the smallest kernel mass of its visible
  // points and the largest f a glossy visible point of it may have (throughput x Bsdf::max_f).
  void record_visible(size_t first, std::span<const VisiblePoint> points,
                      std::span<const OwnerValues> owner, std::span<const PointBsdf> glossy,
                      std::span<const PointState> states, std::span<const ExtraPaths> extra);

  // Traces the paths 1 .. K - 1 of the chunk's pixels [at, at + m) (block offset b), gathers
  // and samples them, and replaces sums_ and owner_ by the mean over all K paths (PathMean).
  void extra_paths(const PassInputs& in, const CameraPathInputs& camera, size_t at, size_t b,
                   size_t m, std::span<const PointState> states, std::span<const float> radii);

  const PinholeCamera& camera_;
  CameraPathSettings settings_;
  CameraPassResult pass_;          // the image size and the median footprint of pixel-centre paths
  vec3 max_f_{0.0f};               // the largest BRDF a Lambertian visible point can have
  std::vector<uint32_t> visible_;  // passes with a visible point, per pixel
  std::vector<float> min_mass_;    // smallest kernel mass seen, per pixel
  std::vector<float> glossy_f_;    // largest glossy f / c seen, per pixel
  // One fold block's visible points, their Bsdfs where not Lambertian (each chunk's at the
  // front of its chunk's share), pass sums and owner values, reused every pass.
  std::vector<VisiblePoint> points_;
  std::vector<PointBsdf> glossy_;
  std::vector<PassSums> sums_;
  std::vector<OwnerValues> owner_;
  std::vector<uint32_t> glossy_count_;  // per chunk of the block: its glossy entries
  std::vector<RegionTable> regions_;    // per chunk of the block: its discs' regions
  // --adaptive paths: the camera paths of each pixel this pass (chosen before it from the
  // states), each pixel's history, and one block's extra paths' side state.
  std::vector<uint8_t> paths_;
  std::vector<PathHistory> history_;
  std::vector<ExtraPaths> extra_;
  PathScratch path_scratch_;
};

}  // namespace pb
