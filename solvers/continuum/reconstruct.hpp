#pragma once
// Limited MUSCL reconstruction: the face value of a cell is its average plus half a limited
// slope. Every limiter here (not `none`) keeps face values between the neighbouring averages,
// so positive fields (n, T, p, c) stay positive at faces.
#include <algorithm>
#include <cmath>

#include "continuum/operator.hpp"

namespace shaker::continuum {

inline double minmod(double a, double b) {
  if (a * b <= 0.0) return 0.0;
  return std::abs(a) < std::abs(b) ? a : b;
}

/// Limited slope (per cell width) from the backward and forward differences.
template <Limiter L> inline double limited_slope(double backward, double forward) {
  if constexpr (L == Limiter::minmod) {
    return minmod(backward, forward);
  } else if constexpr (L == Limiter::mc) {
    if (backward * forward <= 0.0) return 0.0;
    const double central = 0.5 * (backward + forward);
    const double bound = 2.0 * std::min(std::abs(backward), std::abs(forward));
    return std::copysign(std::min(std::abs(central), bound), central);
  } else if constexpr (L == Limiter::none) {
    return 0.5 * (backward + forward);
  } else {
    const double product = backward * forward;
    return product <= 0.0 ? 0.0 : 2.0 * product / (backward + forward);
  }
}

/// Values at the low (minus) and high (plus) faces of the middle cell.
template <Limiter L>
inline void reconstruct(double left, double middle, double right, double& minus, double& plus) {
  const double half_slope = 0.5 * limited_slope<L>(middle - left, right - middle);
  minus = middle - half_slope;
  plus = middle + half_slope;
}

}  // namespace shaker::continuum
