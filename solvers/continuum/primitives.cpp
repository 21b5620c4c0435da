// The primitive variables (n, u, T) of a run of cells from the conserved ones: the first half
// of the closure's row loop (transport.cpp), which evaluates the closure from them while the
// row is in cache.
#include "continuum/simd_pair.hpp"
#include "continuum/state.hpp"

namespace shaker::continuum {

void to_primitives(const State& U, std::array<std::vector<double>, variable_count>& w, std::ptrdiff_t first,
                   int length) {
  const double* N = U.q[density].data();
  const double* Mx = U.q[momentum_x].data();
  const double* My = U.q[momentum_y].data();
  const double* Mz = U.q[momentum_z].data();
  const double* E = U.q[energy].data();
  double* wn = w[0].data();
  double* wx = w[1].data();
  double* wy = w[2].data();
  double* wz = w[3].data();
  double* wT = w[4].data();
  // Adjacent cells at once (simd_pair.hpp), per lane what to_primitive computes.
  for_lanes(length, [&](int i, auto lanes) {
    using S = decltype(lanes);
    const std::ptrdiff_t c = first + i;
    const S n = load_lanes<S>(N + c), mx = load_lanes<S>(Mx + c), my = load_lanes<S>(My + c),
            mz = load_lanes<S>(Mz + c);
    const S inv = 1.0 / n;
    const S ux = mx * inv, uy = my * inv, uz = mz * inv;
    const S kinetic = 0.5 * (mx * ux + my * uy + mz * uz);
    // E - kinetic loses digits in fast, cold, dilute cells: a round-off negative is zero.
    const S thermal = (load_lanes<S>(E + c) - kinetic) * inv / 1.5;
    store_lanes(wn + c, n);
    store_lanes(wx + c, ux);
    store_lanes(wy + c, uy);
    store_lanes(wz + c, uz);
    store_lanes(wT + c, 0.0 < thermal ? thermal : S{});  // std::max(0.0, thermal) per lane
  });
}

}  // namespace shaker::continuum
