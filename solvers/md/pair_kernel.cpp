// The batched pair test of the predictions (see pair_contact_delays in event_prediction.hpp).
// Its own file because it is compiled with -fno-trapping-math (CMakeLists.txt): without it GCC
// will not turn the masked selects into vector code. That flag only drops the assumption that
// floating-point exceptions are observed; every value is rounded as in the scalar form.
#include <algorithm>
#include <cmath>

#include "md/event_prediction.hpp"

namespace shaker::md {

__attribute__((target_clones("avx2", "default"))) void pair_contact_delays(PairBatch& batch) {
  const int n = batch.count;
  const double* __restrict rx = batch.rx;
  const double* __restrict ry = batch.ry;
  const double* __restrict rz = batch.rz;
  const double* __restrict vx = batch.vx;
  const double* __restrict vy = batch.vy;
  const double* __restrict vz = batch.vz;
  double* __restrict out = batch.delay;
  for (int k = 0; k < n; ++k) {
    // The operations of pair_contact_delay in the same order (dot products left to right); an
    // overlapping pair (c <= 0) has a discriminant >= b^2 >= 0, so it is not masked out.
    const double b = rx[k] * vx[k] + ry[k] * vy[k] + rz[k] * vz[k];
    const double c = rx[k] * rx[k] + ry[k] * ry[k] + rz[k] * rz[k] - 1.0;
    const double v2 = vx[k] * vx[k] + vy[k] * vy[k] + vz[k] * vz[k];
    const double discriminant = b * b - v2 * c;
    const double root = c / (-b + std::sqrt(std::max(discriminant, 0.0)));
    const double dt = c <= 0.0 ? 0.0 : root;
    out[k] = (b < 0.0) & (discriminant >= 0.0) ? dt : never;
  }
}

}  // namespace shaker::md
