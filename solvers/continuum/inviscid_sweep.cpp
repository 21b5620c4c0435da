// Inviscid fluxes: limited MUSCL reconstruction of (n, u, T, p, c) to both sides of each face
// (each cell's slopes computed once, for both of its faces) and an approximate Riemann solver. Reconstructed are n, u, p, chi = p / (n T) and c; the
// face temperature is p / (n chi), so pressure and internal energy stay consistent across a
// contact (no pressure wiggles), and the equation of state is not re-evaluated at faces
// (second order all the same, two fewer closure evaluations per face). Pressureless runs
// reconstruct T itself. At wall faces only the normal momentum flux
// (the wall pressure) survives; mass, energy and tangential momentum fluxes are exactly zero,
// so mass is conserved to round-off.
//
// The stages, each in its own file: reconstruction and limiting, wall cells included
// (reconstruction.hpp); the face states' temperature, Riemann problems and the fluxes added to
// dU/dt (face_states.hpp); the Riemann solvers (riemann.hpp). Here: the sweep, which cuts each
// direction's faces into blocks and runs the stages on each, and the choice of limiter and
// solver.
#include <algorithm>

#include "continuum/face_states.hpp"
#include "continuum/reconstruction.hpp"
#include "continuum/riemann.hpp"

namespace shaker::continuum {

namespace {

using inviscid::Block;
using inviscid::block_slots;
using inviscid::BlockContext;
using inviscid::FaceStates;

/// The cells of one direction as pencils (a, b), `length` cells each, count_a across a row
/// (the b of a slab: slab_sweep); base index of each pencil.
struct Pencils {
  int count_a, length;
  std::ptrdiff_t base(const Grid& g, int d, int a, int b) const {
    return d == 0 ? g.index(0, a, b) : d == 1 ? g.index(a, 0, b) : g.index(a, b, 0);
  }
};
Pencils pencils_of(const Grid& g, int d) {
  if (d == 0) return {g.ny, g.nx};
  if (d == 1) return {g.nx, g.ny};
  return {g.nx, g.nz};
}

/// Most pencils side by side in one block (a longer row is cut into balanced runs).
constexpr int max_lanes = 32;

// Face f lies between cells f - 1 and f. The block first reconstructs both face states
// of its cells f0 - 1 .. f1 - 1 (each cell's slopes once, field by field: simple loops
// without a dependence from one cell to the next), then solves the faces' Riemann
// problems.
template <Limiter L, RiemannSolver R> void block_fluxes(const BlockContext& x, const Block& block, State& dUdt) {
  FaceStates minus, plus;
  inviscid::reconstruct_block<L>(x, block, minus, plus);
  inviscid::add_block_fluxes<R>(x, block, minus, plus, dUdt);
}

// Pencils across x (y and z faces) go a run of a row at a time (at most max_lanes, a longer
// row cut into balanced runs): side by side in storage, their cells are reconstructed and
// their fluxes added as contiguous rows, and neighbours share a vector (bit for bit the
// scalar arithmetic of each). Blocks along the pencils hold block_slots slots.
// Dynamic scheduling: on a shared machine a thread that is held up does not hold up the
// other (pencils touch disjoint cells, so the result does not depend on the order). A
// chunk is a whole row or plane of pencils, so that two threads rarely write into the
// same cache line.
/// The faces of direction x.d that belong to planes k0 .. k1 - 1 (slab_sweep).
template <Limiter L, RiemannSolver R> void sweep(const BlockContext& x, State& dUdt, int k0, int k1) {
  const Grid& g = x.g;
  const int d = x.d;
  const Pencils P = pencils_of(g, d);
  const bool across = x.s != 1;
  const int runs_per_row = across ? (P.count_a + max_lanes - 1) / max_lanes : P.count_a;
  const SlabSweep part = slab_sweep(g, d, k0, k1);
  const int groups = runs_per_row * part.b_count;
#pragma omp parallel for schedule(dynamic, runs_per_row) if (g.threaded())
  for (int group = 0; group < groups; ++group) {
    const int run = group % runs_per_row, b = part.b_first + group / runs_per_row;
    const int a = across ? run * P.count_a / runs_per_row : run;
    const int W = across ? (run + 1) * P.count_a / runs_per_row - a : 1;
    const std::ptrdiff_t base = P.base(g, d, a, b);
    const int faces_per_block = block_slots / W - 1;
    for (int f0 = part.f_begin; f0 < part.f_end; f0 += faces_per_block)
      block_fluxes<L, R>(x, Block{W, base, f0, std::min(f0 + faces_per_block, part.f_end)}, dUdt);
  }
}

template <Limiter L, RiemannSolver R>
void inviscid_fluxes(const Grid& g, const std::array<std::vector<double>, variable_count>& w,
                     const Operator::Closure& closure, bool pressureful, State& dUdt, int k0, int k1) {
  for (int d = g.first_direction(); d < 3; ++d)
    sweep<L, R>(inviscid::block_context(g, d, w, closure, pressureful), dUdt, k0, k1);
}

template <Limiter L>
void dispatch_riemann(RiemannSolver r, const Grid& g,
                      const std::array<std::vector<double>, variable_count>& w,
                      const Operator::Closure& closure, bool pressureful, State& dUdt, int k0, int k1) {
  if (r == RiemannSolver::hllc)
    inviscid_fluxes<L, RiemannSolver::hllc>(g, w, closure, pressureful, dUdt, k0, k1);
  else
    inviscid_fluxes<L, RiemannSolver::hll>(g, w, closure, pressureful, dUdt, k0, k1);
}
}  // namespace

void Operator::add_inviscid_fluxes(State& dUdt, int k0, int k1) {
  switch (settings_.limiter) {
    case Limiter::minmod:
      return dispatch_riemann<Limiter::minmod>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
    case Limiter::mc:
      return dispatch_riemann<Limiter::mc>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
    case Limiter::van_leer:
      return dispatch_riemann<Limiter::van_leer>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
    case Limiter::none:
      return dispatch_riemann<Limiter::none>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
    case Limiter::first_order:
      return dispatch_riemann<Limiter::first_order>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt,
                                                    k0, k1);
  }
}

}  // namespace shaker::continuum
