#include "plain.h"

#include "photonbound/kernel.h"
#include "photonbound/pass_stages.h"

#include <algorithm>
#include <cmath>

namespace bench {

void gather_plain(const pb::MeasurementPoint& point, double r2, const pb::HashGrid& grid,
                  const std::vector<pb::PhotonHit>& hits, pb::dvec3& phi_out, uint64_t& count_out) {
  const float radius = pb::search_radius(r2);
  const double inv_r2 = 1.0 / r2;
  pb::dvec3 phi(0.0);
  uint64_t count = 0;
  grid.query(point.position, radius, [&](uint32_t k, float dist2) {
    const pb::PhotonHit& h = hits[k];
    const float cos_g = glm::dot(h.wi, point.normal);
    if (cos_g <= 0.0f || glm::dot(h.normal, point.normal) <= 0.0f) return;
    const float cos_s = glm::dot(h.wi, point.shading);
    ++count;
    if (cos_s <= 0.0f) return;
    const pb::dvec3 flux = pb::dvec3(h.flux) * double(cos_s / cos_g);
    const double t = std::min(1.0, std::sqrt(double(dist2) * inv_r2));
    phi += pb::kernel::weight(t) * flux;
  });
  phi_out = pb::dvec3(point.f) * phi;
  count_out = count;
}

void accumulate_plain(PlainState& s, const pb::dvec3& phi, uint64_t count, const pb::dvec3& direct,
                      double alpha, double min_r2) {
  const double r2_pass = s.r2;
  s.direct_sum += direct;
  s.photons += count;
  // PPM update (HOJ08), as in accumulate_pass().
  const double m = double(count);
  double shrink = 1.0;
  if (s.n + m > 0.0) {
    shrink = (s.n + alpha * m) / (s.n + m);
    s.n += alpha * m;
  }
  s.r2 = std::max(r2_pass * shrink, min_r2);
  s.tau = (s.tau + phi) * (s.r2 / r2_pass);
}

}  // namespace bench
