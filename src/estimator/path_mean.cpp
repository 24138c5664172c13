#include "estimator/path_mean.h"

#include "estimator/kernel.h"

#include <algorithm>

namespace pb {

void PathMean::add(const PassSums& g, const OwnerValues& o, double r2, double photons_per_pass) {
  raw_.phi += g.phi;
  raw_.phi_lap_r2 += g.phi_lap_r2;
  raw_.phi_half += g.phi_half;
  raw_.count += g.count;
  direct_ += o.direct;
  if (paths_ == 0) first_count_ = g.count;
  ++paths_;
  // The corrections of accumulate_pass (ESTIMATOR.md section 11), per path.
  full_ = full_ && o.disc.full;
  const auto [phi, lap, r2_bias] = corrected_sums(g, o.disc, r2);
  phi_ += phi;
  lap_ += lap;
  r2_bias_ += r2_bias;
  const dvec3 x = o.direct + phi / (kPiD * r2 * photons_per_pass);  // section 4's X_j
  x_ += x;
  x2_ += x * x;
}

double PathMean::spread() const {
  if (paths_ < 2) return 0.0;
  const dvec3 ss = glm::max(dvec3(0.0), x2_ - x_ * x_ / double(paths_));
  return ss.x + ss.y + ss.z;
}

void PathMean::finish(double r2, PassSums& g, OwnerValues& o) const {
  const double inv = 1.0 / double(std::max(paths_, 1));
  o = OwnerValues{};
  o.direct = direct_ * inv;
  o.first_count = first_count_;
  g.count = raw_.count * inv;
  if (full_) {  // linear in the sums: their mean, and the disc stays whole
    g.phi = raw_.phi * inv;
    g.phi_lap_r2 = raw_.phi_lap_r2 * inv;
    g.phi_half = raw_.phi_half * inv;
    return;
  }
  // A cut disc of mass 1, Laplacian mass 0 and Laplacian second moment 4 leaves phi and the
  // Laplacian sample as they are, and its second moment carries the mean R_b^2.
  g.phi = phi_ * inv;
  g.phi_lap_r2 = lap_ * inv * r2;
  g.phi_half = dvec3(0.0);
  o.disc.full = false;
  o.disc.mass = 1.0;
  o.disc.lap_mass = 0.0;
  o.disc.lap_second = 4.0;
  o.disc.second = 2.0 * kernel::kSecondMoment * (r2_bias_ * inv) / r2;
}

}  // namespace pb
