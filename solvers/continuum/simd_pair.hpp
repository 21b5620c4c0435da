#pragma once
// Adjacent cells at once: GCC vectors of doubles (element-wise IEEE arithmetic, one SIMD
// instruction per operation). Pair holds two (SSE2, every x86-64); Wide is the widest the
// build's target has (four with AVX, else a Pair). Kernels written for them compute per lane
// exactly what their scalar form computes (selects in place of early returns, the same
// operations otherwise; no contraction into fused multiply-adds, CMakeLists.txt), so their
// results are bit for bit those of a cell-by-cell loop, whatever the width.
#include <type_traits>

namespace shaker::continuum {

template <int N> struct DoubleLanes {
  typedef double type __attribute__((vector_size(N * sizeof(double))));
};
using Pair = DoubleLanes<2>::type;
#if defined(__AVX__)
using Wide = DoubleLanes<4>::type;
#else
using Wide = Pair;
#endif
/// Cells per value: 1 for a double, the vector's width otherwise.
template <class S> inline constexpr int lanes_of = static_cast<int>(sizeof(S) / sizeof(double));
/// The mask a comparison of two S gives (bool for a double).
template <class S> using MaskOf = decltype(S{} < S{});

namespace pair_detail {
template <class V> inline V magnitude(V x) {
  const auto sign_bit = (MaskOf<V>)(-V{});  // -0.0 in every lane: the sign bit alone
  return (V)((MaskOf<V>)x & ~sign_bit);
}
template <class V> inline V with_sign_of(V x, V sign) {
  const auto sign_bit = (MaskOf<V>)(-V{});
  return (V)(((MaskOf<V>)x & ~sign_bit) | ((MaskOf<V>)sign & sign_bit));
}
/// std::min(a, b) and std::max(a, b) per lane, for a double or a vector.
template <class S> inline S smaller(S a, S b) { return b < a ? b : a; }
template <class S> inline S larger(S a, S b) { return a < b ? b : a; }
}  // namespace pair_detail

/// Whether any lane of a comparison's result is set (a double's comparison: the bool itself).
template <class Mask> inline bool any_lane(Mask mask) {
  if constexpr (std::is_same_v<Mask, bool>) {
    return mask;
  } else {
    bool any = false;
    for (int l = 0; l < static_cast<int>(sizeof(Mask) / sizeof(mask[0])); ++l) any = any || mask[l] != 0;
    return any;
  }
}

/// Loads one value (double) or adjacent ones (a vector); stores where a mask or flag is set.
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
template <class Mask, class V> inline void store_lanes_where(Mask keep, double* to, V value) {
  const V kept = keep ? value : load_lanes<V>(to);
  __builtin_memcpy(to, &kept, sizeof kept);
}

inline void store_lanes(double* to, double value) { *to = value; }
template <class V> inline void store_lanes(double* to, V value) { __builtin_memcpy(to, &value, sizeof value); }

/// Calls step(i, Wide{}), step(i, Pair{}) or step(i, 0.0) for i = 0 .. count - 1, each call
/// covering lanes_of<its type> consecutive i, the widest first.
template <class Step> inline void for_lanes(int count, Step step) {
  int i = 0;
  if constexpr (lanes_of<Wide> > 2)
    for (; i + lanes_of<Wide> <= count; i += lanes_of<Wide>) step(i, Wide{});
  for (; i + 2 <= count; i += 2) step(i, Pair{});
  for (; i < count; ++i) step(i, 0.0);
}

}  // namespace shaker::continuum
