// Stochastic PPM (Hachisuka, Jensen 2009; ESTIMATOR.md section 10): every pass traces one
// camera path per pixel through a jittered point of it (camera_paths.h) and gathers at the
// visible point it finds; the state, radius and statistics are per pixel.
#pragma once

#include "render/camera_paths.h"
#include "render/method.h"
#include "world/world.h"

#include <vector>

namespace pb {

// What the camera paths of every pass take from the options.
struct CameraPathSettings {
  int max_depth = 8;
  float follow_roughness = 0.0f;  // 0 without next-event direct light (camera_paths.h)
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
  PixelLayout layout(const std::vector<PointState>& states,
                     const RenderState* saved) const override;

 private:
  // Stage 0's side of a chunk's visible points for the film (ESTIMATOR.md section 12): counts
  // each pixel's passes with a visible point, keeps the smallest kernel mass of its visible
  // points and the largest f a glossy visible point of it may have (throughput x Bsdf::max_f).
  void record_visible(size_t first, std::span<const VisiblePoint> points,
                      std::span<const OwnerValues> owner, std::span<const PointBsdf> glossy,
                      std::span<const PointState> states);

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
};

}  // namespace pb
