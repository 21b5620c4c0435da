#pragma once
// Approximate Riemann solvers for the inviscid flux through one face, in the face's frame
// (normal velocity un, tangential ut1, ut2). Wave speeds are Davis's estimates from the
// states' own sound speeds (the model's c for the granular equation of state). HLL is the
// simple reference; HLLC restores the contact wave.
#include <algorithm>

#include "continuum/operator.hpp"

namespace shaker::continuum {

struct FaceState {
  double n, un, ut1, ut2, T, p, c;
  double total_energy() const { return n * (1.5 * T + 0.5 * (un * un + ut1 * ut1 + ut2 * ut2)); }
};

/// Flux components: mass, normal momentum, two tangential momenta, energy.
inline void physical_flux(const FaceState& s, double E, double* F) {
  F[0] = s.n * s.un;
  F[1] = F[0] * s.un + s.p;
  F[2] = F[0] * s.ut1;
  F[3] = F[0] * s.ut2;
  F[4] = (E + s.p) * s.un;
}

// Always inlined into the per-face loop of the flux kernel: GCC declined once that loop became
// a template over the number of pencils, and the call costs time (docs/performance.md).
template <RiemannSolver Solver>
[[gnu::always_inline]] inline void riemann_flux(const FaceState& L, const FaceState& R, double* F) {
  const double SL = std::min(L.un - L.c, R.un - R.c);
  const double SR = std::max(L.un + L.c, R.un + R.c);
  const double EL = L.total_energy(), ER = R.total_energy();
  if (SL >= 0.0) return physical_flux(L, EL, F);
  if (SR <= 0.0) return physical_flux(R, ER, F);
  double FL[5], FR[5];
  physical_flux(L, EL, FL);
  physical_flux(R, ER, FR);
  const auto hll = [&] {
    const double UL[5] = {L.n, L.n * L.un, L.n * L.ut1, L.n * L.ut2, EL};
    const double UR[5] = {R.n, R.n * R.un, R.n * R.ut1, R.n * R.ut2, ER};
    const double inv = 1.0 / (SR - SL);
    for (int v = 0; v < 5; ++v) F[v] = (SR * FL[v] - SL * FR[v] + SL * SR * (UR[v] - UL[v])) * inv;
  };
  if constexpr (Solver == RiemannSolver::hll) {
    hll();
  } else {
    const double mL = L.n * (SL - L.un), mR = R.n * (SR - R.un);
    // Pressureless flux (c = 0 on both sides) with the sides moving apart: SL = L.un and
    // SR = R.un make both mass fluxes mK zero and S_star 0 / 0 (NaN). The exact solution opens
    // a vacuum between the sides, whose flux is zero; HLL gives exactly that (F_K = u_K U_K).
    if (!(mR - mL > 0.0)) return hll();
    const double S_star = (R.p - L.p + L.un * mL - R.un * mR) / (mL - mR);
    const bool left = S_star >= 0.0;
    const FaceState& K = left ? L : R;
    const double SK = left ? SL : SR, EK = left ? EL : ER;
    const double* FK = left ? FL : FR;
    const double mK = left ? mL : mR;
    const double factor = mK / (SK - S_star);
    const double U_star[5] = {factor, factor * S_star, factor * K.ut1, factor * K.ut2,
                              factor * (EK / K.n + (S_star - K.un) * (S_star + K.p / mK))};
    const double UK[5] = {K.n, K.n * K.un, K.n * K.ut1, K.n * K.ut2, EK};
    for (int v = 0; v < 5; ++v) F[v] = FK[v] + SK * (U_star[v] - UK[v]);
  }
}

}  // namespace shaker::continuum
