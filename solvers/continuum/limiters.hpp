#pragma once
// The slope limiters of the MUSCL reconstruction (reconstruction.hpp), continuum.limiter. Every
// limiter here but `none` keeps face values between the neighbouring averages, so positive
// fields (n, T, p, c) stay positive at faces; with positive face states the HLL and HLLC fluxes
// keep n and p positive under a Courant number of 1/2 (Perthame and Shu 1996; Batten et al.
// 1997), which is why no separate positivity limiter is needed.
#include <algorithm>
#include <cmath>
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
  if constexpr (L == Limiter::first_order) {
    return 0.0;
  } else if constexpr (L == Limiter::minmod) {
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
  if constexpr (L == Limiter::first_order) {
    return zero;
  } else if constexpr (L == Limiter::minmod) {
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

}  // namespace shaker::continuum
