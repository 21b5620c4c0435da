#pragma once
// Two adjacent cells at once: a GCC vector of two doubles (element-wise IEEE arithmetic, one
// SSE2 instruction per operation). Kernels written for it compute per lane exactly what their
// scalar form computes (selects in place of early returns, the same operations otherwise), so
// their results are bit for bit those of a cell-by-cell loop.
#include <type_traits>

namespace shaker::continuum {

using Pair = double __attribute__((vector_size(2 * sizeof(double))));
using PairMask = long long __attribute__((vector_size(2 * sizeof(double))));

namespace pair_detail {
inline constexpr PairMask sign_bit = {static_cast<long long>(0x8000000000000000ULL),
                                      static_cast<long long>(0x8000000000000000ULL)};
inline Pair magnitude(Pair x) { return (Pair)((PairMask)x & ~sign_bit); }
inline Pair with_sign_of(Pair x, Pair sign) {
  return (Pair)(((PairMask)x & ~sign_bit) | ((PairMask)sign & sign_bit));
}
/// std::min(a, b) and std::max(a, b) per lane, for a double or a Pair.
template <class S> inline S smaller(S a, S b) { return b < a ? b : a; }
template <class S> inline S larger(S a, S b) { return a < b ? b : a; }
}  // namespace pair_detail

/// Whether any lane of a comparison's result is set (a double's comparison: the bool itself).
template <class Mask> inline bool any_lane(Mask mask) {
  if constexpr (std::is_same_v<Mask, bool>)
    return mask;
  else
    return (mask[0] | mask[1]) != 0;
}

/// Loads one value (double) or two adjacent ones (Pair); stores where a mask or flag is set.
template <class S> inline S load_lanes(const double* x) {
  if constexpr (std::is_same_v<S, double>) {
    return *x;
  } else {
    S v;
    __builtin_memcpy(&v, x, sizeof v);
    return v;
  }
}
inline void store_lanes_where(bool keep, double* to, double value) {
  if (keep) *to = value;
}
template <class Mask> inline void store_lanes_where(Mask keep, double* to, Pair value) {
  const Pair kept = keep ? value : load_lanes<Pair>(to);
  __builtin_memcpy(to, &kept, sizeof kept);
}

inline void store_lanes(double* to, double value) { *to = value; }
inline void store_lanes(double* to, Pair value) { __builtin_memcpy(to, &value, sizeof value); }

}  // namespace shaker::continuum
