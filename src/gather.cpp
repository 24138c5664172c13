#include "photonbound/gather.h"

#include "photonbound/kernel.h"

#include <algorithm>

namespace pb {

void gather_photons(const MeasurementPoint& point, double r2, const HashGrid& grid,
                    const std::vector<PhotonHit>& hits, PassGather& out) {
  const float radius = search_radius(r2);
  const double inv_r2 = 1.0 / r2;
  dvec3 phi(0.0), lap(0.0);
  uint64_t count = 0;
  grid.query(point.position, radius, [&](uint32_t k, float dist2) {
    const PhotonHit& h = hits[k];
    // Same side only (ESTIMATOR.md section 3): the photon must arrive from the half-space the
    // point is seen from, on a surface facing the same way (not the back of a thin wall).
    const float cos_g = glm::dot(h.wi, point.normal);
    if (cos_g <= 0.0f || glm::dot(h.normal, point.normal) <= 0.0f) return;
    const float cos_s = glm::dot(h.wi, point.shading);
    ++count;  // it could contribute, so it counts toward the radius reduction
    if (cos_s <= 0.0f) return;
    // Photon density is flux per area of the true surface; reflected radiance integrates
    // against the shading cosine, hence cos_s / cos_g.
    const dvec3 flux = dvec3(h.flux) * double(cos_s / cos_g);
    const double t = std::min(1.0, std::sqrt(double(dist2) * inv_r2));
    phi += kernel::weight(t) * flux;
    lap += kernel::laplacian_weight_r2(t) * flux;
  });
  const dvec3 f(point.f);
  out.phi += f * phi;
  out.phi_lap_r2 += f * lap;
  out.count += count;
}

dvec3 direct_light(const World& world, const MeasurementPoint& point, Rng& rng) {
  DirectSample s;
  if (!world.lights().sample_direct(point.position, rng, s)) return dvec3(0.0);
  const float cos_s = glm::dot(s.wi, point.shading);
  if (cos_s <= 0.0f || glm::dot(s.wi, point.normal) <= 0.0f) return dvec3(0.0);
  if (world.occluded(point.position, point.normal, s.wi, s.distance)) return dvec3(0.0);
  return dvec3(point.f * s.li * cos_s);
}

}  // namespace pb
