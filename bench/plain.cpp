#include "plain.h"

namespace bench {

void accumulate_plain(PlainState& s, const pb::PassSums& g, const pb::dvec3& direct, double alpha,
                      double min_r2) {
  s.direct_sum += direct;
  s.photons += uint64_t(g.count);
  const double applied = pb::ppm_radius_update(s.n, s.r2, g.count, alpha, min_r2);
  s.tau = (s.tau + g.phi) * applied;
}

}  // namespace bench
