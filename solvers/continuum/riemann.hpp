#pragma once
// Approximate Riemann solvers for the inviscid flux through one face, in the face's frame
// (normal velocity un, tangential ut1, ut2). Wave speeds are Davis's estimates from the
// states' own sound speeds (the model's c for the granular equation of state). HLL is the
// simple reference; HLLC restores the contact wave.
#include <algorithm>

#include "continuum/operator.hpp"
#include "continuum/simd_pair.hpp"

namespace shaker::continuum {

/// One side of a face, for one face (S = double) or several (S a vector, simd_pair.hpp).
template <class S> struct FaceStateOf {
  S n, un, ut1, ut2, T, p, c;
  S total_energy() const { return n * (1.5 * T + 0.5 * (un * un + ut1 * ut1 + ut2 * ut2)); }
};
using FaceState = FaceStateOf<double>;

/// Flux components: mass, normal momentum, two tangential momenta, energy.
template <class S> inline void physical_flux(const FaceStateOf<S>& s, S E, S* F) {
  F[0] = s.n * s.un;
  F[1] = F[0] * s.un + s.p;
  F[2] = F[0] * s.ut1;
  F[3] = F[0] * s.ut2;
  F[4] = (E + s.p) * s.un;
}

// Written without branches on the state, so that a vector S solves several faces at once:
// every case's flux is formed and each lane selects its own (supersonic left or right, HLL,
// HLLC), which is per lane the arithmetic of a solver that returns early, bit for bit (the test
// RiemannFlux.VectorLanesMatchTheBranchingSolver holds it to one written that way). HLL's flux,
// which HLLC needs only where its star state does not exist, is formed only if some lane does.
// Always inlined into the per-face loop of the flux kernel (docs/performance.md).
template <RiemannSolver Solver, class S>
[[gnu::always_inline]] inline void riemann_flux(const FaceStateOf<S>& L, const FaceStateOf<S>& R, S* F) {
  using pair_detail::larger;
  using pair_detail::smaller;
  const S SL = smaller(L.un - L.c, R.un - R.c);
  const S SR = larger(L.un + L.c, R.un + R.c);
  const S EL = L.total_energy(), ER = R.total_energy();
  S FL[5], FR[5];
  physical_flux(L, EL, FL);
  physical_flux(R, ER, FR);
  const auto from_left = SL >= 0.0, from_right = SR <= 0.0;
  S between[5];
  const auto hll = [&](S* out) {
    const S UL[5] = {L.n, L.n * L.un, L.n * L.ut1, L.n * L.ut2, EL};
    const S UR[5] = {R.n, R.n * R.un, R.n * R.ut1, R.n * R.ut2, ER};
    const S inv = 1.0 / (SR - SL);
    for (int v = 0; v < 5; ++v) out[v] = (SR * FL[v] - SL * FR[v] + SL * SR * (UR[v] - UL[v])) * inv;
  };
  if constexpr (Solver == RiemannSolver::hll) {
    hll(between);
  } else {
    const S mL = L.n * (SL - L.un), mR = R.n * (SR - R.un);
    // Pressureless flux (c = 0 on both sides) with the sides moving apart: SL = L.un and
    // SR = R.un make both mass fluxes mK zero and S_star 0 / 0 (NaN). The exact solution opens
    // a vacuum between the sides, whose flux is zero; HLL gives exactly that (F_K = u_K U_K).
    const auto vacuum = !(mR - mL > 0.0);
    const S S_star = (R.p - L.p + L.un * mL - R.un * mR) / (mL - mR);
    const auto left = S_star >= 0.0;
    const auto side = [&](const S& l, const S& r) -> S { return left ? l : r; };
    const FaceStateOf<S> K{side(L.n, R.n), side(L.un, R.un), side(L.ut1, R.ut1), side(L.ut2, R.ut2),
                           side(L.T, R.T), side(L.p, R.p), side(L.c, R.c)};
    const S SK = side(SL, SR), EK = side(EL, ER), mK = side(mL, mR);
    const S factor = mK / (SK - S_star);
    const S U_star[5] = {factor, factor * S_star, factor * K.ut1, factor * K.ut2,
                         factor * (EK / K.n + (S_star - K.un) * (S_star + K.p / mK))};
    const S UK[5] = {K.n, K.n * K.un, K.n * K.ut1, K.n * K.ut2, EK};
    for (int v = 0; v < 5; ++v) between[v] = side(FL[v], FR[v]) + SK * (U_star[v] - UK[v]);
    if (any_lane(vacuum)) {
      S F_hll[5];
      hll(F_hll);
      for (int v = 0; v < 5; ++v) between[v] = vacuum ? F_hll[v] : between[v];
    }
  }
  for (int v = 0; v < 5; ++v) F[v] = from_left ? FL[v] : from_right ? FR[v] : between[v];
}

}  // namespace shaker::continuum
