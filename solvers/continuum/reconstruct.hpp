#pragma once
// Limited MUSCL reconstruction: the face value of a cell is its average plus half a limited
// slope. Every limiter here (not `none`) keeps face values between the neighbouring averages,
// so positive fields (n, T, p, c) stay positive at faces.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>

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

/// The same limiters for adjacent cells at once (simd_pair.hpp): per lane the values above.
template <Limiter L, class V>
  requires(!std::is_same_v<V, double>)
inline V limited_slope(V backward, V forward) {
  using namespace pair_detail;
  const V zero = V{};
  if constexpr (L == Limiter::minmod) {
    const V smallest = magnitude(backward) < magnitude(forward) ? backward : forward;
    return backward * forward <= 0.0 ? zero : smallest;
  } else if constexpr (L == Limiter::mc) {
    const V central = 0.5 * (backward + forward);
    const V bound = 2.0 * smaller(magnitude(backward), magnitude(forward));
    const V slope = with_sign_of(smaller(magnitude(central), bound), central);
    return backward * forward <= 0.0 ? zero : slope;
  } else if constexpr (L == Limiter::none) {
    return 0.5 * (backward + forward);
  } else {
    const V product = backward * forward;
    return product <= 0.0 ? zero : 2.0 * product / (backward + forward);
  }
}

/// Values at the low (minus) and high (plus) faces of the cells x[0 .. n - 1] (S a double,
/// n = 1, or a vector of n), their neighbours s away (s = 1: a contiguous run; s = a stride:
/// pencils side by side); the faces of x[l] go to minus[l], plus[l].
template <Limiter L, class S>
inline void reconstruct_lanes(const double* x, std::ptrdiff_t s, double* minus, double* plus) {
  const S left = load_lanes<S>(x - s), middle = load_lanes<S>(x);
  const S half_slope = 0.5 * limited_slope<L>(middle - left, load_lanes<S>(x + s) - middle);
  store_lanes(minus, middle - half_slope);
  store_lanes(plus, middle + half_slope);
}

}  // namespace shaker::continuum
