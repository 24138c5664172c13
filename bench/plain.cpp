#include "plain.h"

namespace bench {

void accumulate_plain(PlainState& s, const pb::PassGather& g, double alpha, double min_r2) {
  s.direct_sum += g.direct;
  s.photons += g.count;
  const double applied = pb::ppm_radius_update(s.n, s.r2, double(g.count), alpha, min_r2);
  s.tau = (s.tau + g.phi) * applied;
}

}  // namespace bench
