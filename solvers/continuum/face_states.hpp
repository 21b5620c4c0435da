#pragma once
// The face states of a block of faces and the stages that follow their reconstruction
// (reconstruction.hpp): the face temperature, the faces' Riemann problems (riemann.hpp) and
// their fluxes added to dU/dt. The sweep (inviscid_sweep.cpp) cuts each direction's faces
// into blocks and runs the stages on each.
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "continuum/operator.hpp"
#include "continuum/riemann.hpp"
#include "continuum/simd_pair.hpp"

namespace shaker::continuum::inviscid {

/// Slots (cells x pencils) of a block: its face states (2 x 7 x slots doubles) stay in L1/L2.
constexpr int block_slots = 384;

/// minus[v][slot], plus[v][slot]: face states at the low and high face of the block's cell q
/// of pencil `lane`, slot = q W + lane, for W pencils side by side in x at once (their cells
/// are adjacent in storage). v as in BlockContext::fields.
using FaceStates = double[7][block_slots];
/// Flux / h of the block's face f0 + b of pencil `lane`, per conserved variable: slot b W + lane.
using FaceChanges = double[variable_count][block_slots];

/// What every stage of a block reads: the fields, seen along one direction d of the grid.
struct BlockContext {
  const Grid& g;
  int d;
  std::ptrdiff_t s;  ///< the stride of d: a cell's neighbours along d are s away
  int un_index;      ///< the face-normal velocity's field, 1 + d
  int length;        ///< cells of a pencil along d; its faces are 0 .. length
  bool walls;        ///< walls at faces 0 and length (z with walls)
  bool pressure;     ///< pressureful (else fields[4] is T and chi is not used)
  double inv_h;
  /// n, u_x, u_y, u_z, then p (pressureless: T), chi and c per cell.
  const double* fields[7];
  const double* T;  ///< the cells' temperatures
  const double* p;  ///< the cells' pressures
};
inline BlockContext block_context(const Grid& g, int d, const std::array<std::vector<double>, variable_count>& w,
                                  const Operator::Closure& closure, bool pressure) {
  return {g,
          d,
          g.stride(d),
          1 + d,
          d == 0 ? g.nx : d == 1 ? g.ny : g.nz,
          d == 2 && g.z_boundary == ZBoundary::walls,
          pressure,
          1.0 / g.h,
          {w[0].data(), w[1].data(), w[2].data(), w[3].data(), pressure ? closure.p.data() : w[4].data(),
           closure.chi.data(), closure.c.data()},
          w[4].data(),
          closure.p.data()};
}

/// Faces f0 .. f1 - 1 of W pencils whose first cells are base, base + 1, ... (W = 1 along x:
/// a pencil is a row, contiguous). Face f lies between cells f - 1 and f: the block's cells
/// are f0 - 1 .. f1 - 1.
struct Block {
  int W;
  std::ptrdiff_t base;
  int f0, f1;
  int cells() const { return f1 - f0 + 1; }
  int slots() const { return (f1 - f0) * W; }
  /// Calls step(c, slot, lanes) for every cell of the block, `lanes` a double or a vector of
  /// adjacent cells (simd_pair.hpp, for_lanes): a cell's pencils (W > 1) or the run (W = 1).
  template <class Step> void over_cells(std::ptrdiff_t s, Step step) const {
    const std::ptrdiff_t c0 = base + (f0 - 1) * s;  // the block's cell q of pencil l is c0 + q s + l
    if (W == 1 && s == 1) return for_lanes(cells(), [&](int q, auto lanes) { step(c0 + q, q, lanes); });
    for (int q = 0; q < cells(); ++q)
      for_lanes(W, [&](int lane, auto lanes) { step(c0 + q * s + lane, q * W + lane, lanes); });
  }
};

// Pressureful face states hold p in x[4] and chi in x[5]; this makes them (T, p), with
// T = p / (n chi). Near vacuum the independently limited n, p and chi can combine into a
// face temperature far outside the neighbouring cells' range; such a face state falls back
// to its cell's average (first order there). The band is a factor of 2 around the range,
// so smooth flow (where p / (n chi) differs from T by O(h)) never triggers it.
/// Both face states of the cells at c (slot `slot`), which share the cells' range.
template <class S>
inline void face_temperatures(const BlockContext& x, std::ptrdiff_t c, int slot, FaceStates& low_faces,
                              FaceStates& high_faces) {
  using pair_detail::larger;
  using pair_detail::smaller;
  const std::ptrdiff_t s = x.s;
  const auto at = [](const double* y) { return load_lanes<S>(y); };
  const S Tb = at(x.T + c - s), Tc = at(x.T + c), Tf = at(x.T + c + s);
  const S low = 0.5 * smaller(smaller(Tb, Tc), Tf), high = 2.0 * larger(larger(Tb, Tc), Tf);
  for (FaceStates* faces : {&low_faces, &high_faces}) {
    const S p = at(&(*faces)[4][slot]), T_face = p / (at(&(*faces)[0][slot]) * at(&(*faces)[5][slot]));
    const auto inside = (T_face >= low) & (T_face <= high);
    store_lanes(&(*faces)[4][slot], inside ? T_face : Tc);
    store_lanes(&(*faces)[5][slot], inside ? p : at(x.p + c));
    if (any_lane(!inside))  // rare: the other fields fall back to the cell's too
      for (int v : {0, 1, 2, 3, 6}) store_lanes_where(!inside, &(*faces)[v][slot], at(x.fields[v] + c));
  }
}

/// The face states of the slots at `slot` in the face's frame (normal, two tangential).
template <class S> inline FaceStateOf<S> face_state(const BlockContext& x, const FaceStates& faces, int slot) {
  const int d = x.d;
  const auto at = [&](int v) { return load_lanes<S>(&faces[v][slot]); };
  return FaceStateOf<S>{at(0), at(x.un_index), at(1 + (d + 1) % 3), at(1 + (d + 2) % 3), at(4),
                        x.pressure ? at(5) : S{}, at(6)};
}

/// The Riemann problems of the block's slots b, b + 1, ... (as many as S has lanes): the face
/// of slot b has its left state in plus[.][b] and its right one in minus[.][b + W].
template <RiemannSolver R, class S>
inline void solve_faces(const BlockContext& x, const FaceStates& minus, const FaceStates& plus, int b, int W,
                        FaceChanges& change) {
  const int d = x.d;
  const int normal = momentum_x + d;
  const int tangential1 = momentum_x + (d + 1) % 3, tangential2 = momentum_x + (d + 2) % 3;
  S F[5];
  riemann_flux<R>(face_state<S>(x, plus, b), face_state<S>(x, minus, b + W), F);
  store_lanes(&change[density][b], F[0] * x.inv_h);
  store_lanes(&change[energy][b], F[4] * x.inv_h);
  store_lanes(&change[normal][b], F[1] * x.inv_h);
  store_lanes(&change[tangential1][b], F[2] * x.inv_h);
  store_lanes(&change[tangential2][b], F[3] * x.inv_h);
}

/// The wall's mass, energy and tangential momentum fluxes are zero exactly.
inline void zero_wall_fluxes(const BlockContext& x, const Block& block, FaceChanges& change) {
  const int tangential1 = momentum_x + (x.d + 1) % 3, tangential2 = momentum_x + (x.d + 2) % 3;
  for (int f : {0, x.length})
    if (f >= block.f0 && f < block.f1)
      for (int lane = 0; lane < block.W; ++lane)
        for (int v : {int{density}, int{energy}, tangential1, tangential2})
          change[v][(f - block.f0) * block.W + lane] = 0.0;
}

// Face f adds to cell f (its high side) and subtracts from cell f - 1. Each cell
// receives its low face first, then its high face (in this block or the next), as in
// a face-by-face loop; the loops run along the pencils' row, contiguous in storage.
inline void add_face_changes(const BlockContext& x, const Block& block, const FaceChanges& change, State& dUdt) {
  const std::ptrdiff_t s = x.s;
  const int f0 = block.f0, f1 = block.f1, W = block.W;
  const int add_end = std::min(f1, x.length), subtract_begin = std::max(f0, 1);
  for (int v = 0; v < variable_count; ++v) {
    double* dU = dUdt.q[v].data() + block.base;
    const double* ch = change[v];  // ch[(f - f0) W + lane]: face f of pencil lane
    if (W == 1) {
      for (int f = f0; f < add_end; ++f) dU[f * s] += ch[f - f0];
      for (int f = subtract_begin; f < f1; ++f) dU[(f - 1) * s] -= ch[f - f0];
      continue;
    }
    for (int f = f0; f < add_end; ++f)
      for (int lane = 0; lane < W; ++lane) dU[f * s + lane] += ch[(f - f0) * W + lane];
    for (int f = subtract_begin; f < f1; ++f)
      for (int lane = 0; lane < W; ++lane) dU[(f - 1) * s + lane] -= ch[(f - f0) * W + lane];
  }
}

/// The stages after reconstruction: face temperatures (pressureful), Riemann problems, wall
/// fluxes, and the fluxes added to dU/dt.
template <RiemannSolver R>
inline void add_block_fluxes(const BlockContext& x, const Block& block, FaceStates& minus, FaceStates& plus,
                             State& dUdt) {
  if (x.pressure)
    block.over_cells(x.s, [&](std::ptrdiff_t c, int slot, auto lanes) {
      face_temperatures<decltype(lanes)>(x, c, slot, minus, plus);
    });
  FaceChanges change;
  // Face f0 + b of pencil `lane` has its left state in plus[.][b W + lane] and its right
  // one in minus[.][(b + 1) W + lane]: consecutive slots are consecutive faces (W = 1) or
  // the same face of neighbouring pencils, a vector of them at a time either way.
  for_lanes(block.slots(), [&](int b, auto lanes) {
    solve_faces<R, decltype(lanes)>(x, minus, plus, b, block.W, change);
  });
  if (x.walls) zero_wall_fluxes(x, block, change);
  add_face_changes(x, block, change, dUdt);
}

}  // namespace shaker::continuum::inviscid
