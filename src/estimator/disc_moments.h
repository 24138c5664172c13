// What the estimator needs of the surface a gather disc lies on (ESTIMATOR.md section 11); the
// boundary index (world/boundary.h) computes it per visible point.
#pragma once

namespace pb {

// Moments of the unit-mass kernel kappa and of its Laplacian over the part S of the unit disc
// (u = (x - p) / R) that lies on reachable surface. The full disc has mass 1, second moment
// 2 k2 = 5/24 (of |u|^2), Laplacian mass 0 and Laplacian second moment 4.
struct DiscMoments {
  double mass = 1.0;           // c = integral over S of kappa
  double second = 5.0 / 24.0;  // integral over S of |u|^2 kappa
  double lap_mass = 0.0;       // integral over S of lap kappa
  double lap_second = 4.0;     // integral over S of |u|^2 lap kappa
  bool full = true;            // S is the whole disc (the exact values above)
};

}  // namespace pb
