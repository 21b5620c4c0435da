#pragma once
// Exact bin averages of tanh fronts, shared by the synthetic-truth tests (test_front_fit.cpp,
// test_estimator_truth.cpp). Written independently of the library's front model, so that a
// test does not check the library against itself.
#include <cmath>

namespace shaker::testing {

/// ln cosh u; cosh overflows for |u| > 710, so it is written through |u|.
inline double log_cosh(double u) {
  const double a = std::abs(u);
  return a + std::log1p(std::exp(-2.0 * a)) - std::log(2.0);
}

/// The mean of a + b tanh((z - z0) / w) over the bin [zc - h/2, zc + h/2].
inline double bin_mean(double zc, double h, double a, double b, double z0, double w) {
  return a + b * (w / h) * (log_cosh((zc + 0.5 * h - z0) / w) - log_cosh((zc - 0.5 * h - z0) / w));
}

/// The mean over [lo, hi] of a step of height `jump` centred at z0 with half-width w,
/// jump (1 + tanh((z - z0) / w)) / 2: 0 far below z0, `jump` far above.
inline double step_mean(double lo, double hi, double jump, double z0, double w) {
  return bin_mean(0.5 * (lo + hi), hi - lo, 0.5 * jump, 0.5 * jump, z0, w);
}

}  // namespace shaker::testing
