#include "estimator/kernel.h"

#include "util/math.h"

namespace pb::kernel {

double unit_mass(double t) { return 3.5 / kPiD * profile(t); }

double unit_laplacian(double t) { return laplacian_weight_r2(t) / kPiD; }

}  // namespace pb::kernel
