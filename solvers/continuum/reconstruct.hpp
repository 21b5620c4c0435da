#pragma once
// Limited MUSCL reconstruction: the face value of a cell is its average plus half a limited
// slope. Every limiter here (not `none`) keeps face values between the neighbouring averages,
// so positive fields (n, T, p, c) stay positive at faces.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "continuum/operator.hpp"
#include "continuum/simd_pair.hpp"

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

/// The same limiters for two cells at once (simd_pair.hpp): per lane the values above.
template <Limiter L> inline Pair limited_slope(Pair backward, Pair forward) {
  using namespace pair_detail;
  const Pair zero = {0.0, 0.0};
  if constexpr (L == Limiter::minmod) {
    const Pair smallest = magnitude(backward) < magnitude(forward) ? backward : forward;
    return backward * forward <= 0.0 ? zero : smallest;
  } else if constexpr (L == Limiter::mc) {
    const Pair central = 0.5 * (backward + forward);
    const Pair bound = 2.0 * smaller(magnitude(backward), magnitude(forward));
    const Pair slope = with_sign_of(smaller(magnitude(central), bound), central);
    return backward * forward <= 0.0 ? zero : slope;
  } else if constexpr (L == Limiter::none) {
    return 0.5 * (backward + forward);
  } else {
    const Pair product = backward * forward;
    return product <= 0.0 ? zero : 2.0 * product / (backward + forward);
  }
}

/// Values at the low (minus) and high (plus) faces of the middle cell.
template <Limiter L>
inline void reconstruct(double left, double middle, double right, double& minus, double& plus) {
  const double half_slope = 0.5 * limited_slope<L>(middle - left, right - middle);
  minus = middle - half_slope;
  plus = middle + half_slope;
}

/// reconstruct() for the adjacent cells x[0] and x[1] at once, their neighbours s away
/// (s = 1: a contiguous run; s = a stride: two pencils side by side); the faces of x[0] go to
/// minus[0], plus[0], those of x[1] to minus[1], plus[1].
template <Limiter L>
inline void reconstruct_pair(const double* x, std::ptrdiff_t s, double* minus, double* plus) {
  const Pair left = load_lanes<Pair>(x - s), middle = load_lanes<Pair>(x);
  const Pair half_slope = 0.5 * limited_slope<L>(middle - left, load_lanes<Pair>(x + s) - middle);
  store_lanes(minus, middle - half_slope);
  store_lanes(plus, middle + half_slope);
}

/// reconstruct() for cells 0 .. count - 1 of a contiguous run x (x[-1] and x[count] exist),
/// two cells at a time.
template <Limiter L>
inline void reconstruct_run(const double* x, int count, double* minus, double* plus) {
  int q = 0;
  for (; q + 2 <= count; q += 2) reconstruct_pair<L>(x + q, 1, minus + q, plus + q);
  for (; q < count; ++q) reconstruct<L>(x[q - 1], x[q], x[q + 1], minus[q], plus[q]);
}

}  // namespace shaker::continuum
