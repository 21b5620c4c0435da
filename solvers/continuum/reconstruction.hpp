#pragma once
// Limited MUSCL reconstruction: the face value of a cell is its average plus half a limited
// slope (limiters.hpp).
//
// Here: the component-wise reconstruction (reconstruct_lanes),
// the characteristic limiting of (n, u_n, p), and the wall cells' one-sided slopes and mirror
// states; reconstruct_block runs them on a block of faces (face_states.hpp), the first stage
// of the inviscid fluxes (inviscid_sweep.cpp).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "continuum/face_states.hpp"
#include "continuum/limiters.hpp"
#include "continuum/operator.hpp"
#include "continuum/simd_pair.hpp"

namespace shaker::continuum {

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

namespace inviscid {

// Characteristic limiting of (n, u_n, p): the differences are projected on the acoustic
// and entropy waves of the primitive Euler system (valid for any equation of state, with c
// the isentropic sound speed, which model::sound_speed is), limited wave by wave and
// projected back. Component-wise limiting of n, u and p lets the waves of a strong
// Riemann problem interact in the slopes and leaves oscillations of a few per cent behind
// shocks. A face value that comes out non-positive keeps the component-wise one.
// S = double: cell c; S a vector: cells c, c + 1, ..., either of a contiguous pencil (s = 1,
// slots q, q + 1, ...) or of pencils side by side (lanes l, l + 1, ... of cell q), every
// lane doing the scalar arithmetic, the early returns of the scalar code as a mask.
template <Limiter L, class S>
inline void characteristic_faces(const BlockContext& x, std::ptrdiff_t c, int q, FaceStates& minus,
                                 FaceStates& plus) {
  const std::ptrdiff_t s = x.s;
  const int un = x.un_index;
  const auto at = [](const double* y) { return load_lanes<S>(y); };
  const double* fn = x.fields[0];
  const double* fp = x.p;
  const double* fc = x.fields[6];
  const double* u = x.fields[un];
  const S n0 = at(fn + c), c0 = at(fc + c), p0 = at(fp + c), u0 = at(u + c);
  const S impedance = n0 * c0, inv_c2 = 1.0 / (c0 * c0);
  const S dn_b = n0 - at(fn + c - s), dn_f = at(fn + c + s) - n0;
  const S du_b = u0 - at(u + c - s), du_f = at(u + c + s) - u0;
  const S dp_b = p0 - at(fp + c - s), dp_f = at(fp + c + s) - p0;
  const S w1 = limited_slope<L>(dp_b - impedance * du_b, dp_f - impedance * du_f);
  const S w2 = limited_slope<L>(dn_b - dp_b * inv_c2, dn_f - dp_f * inv_c2);
  const S w3 = limited_slope<L>(dp_b + impedance * du_b, dp_f + impedance * du_f);
  const S dp = 0.5 * (w1 + w3), du = 0.5 * (w3 - w1) / impedance, dn = w2 + dp * inv_c2;
  const S n_plus = n0 + 0.5 * dn, p_plus = p0 + 0.5 * dp;
  const S n_minus = n0 - 0.5 * dn, p_minus = p0 - 0.5 * dp;
  // (no sound speed, or a face value that is not positive: the component-wise values, what
  // reconstruct_lanes gives from the same differences)
  const auto keep = (c0 > 0.0) & (n_plus > 0.0) & (p_plus > 0.0) & (n_minus > 0.0) & (p_minus > 0.0);
  const S half_n = 0.5 * limited_slope<L>(dn_b, dn_f), half_u = 0.5 * limited_slope<L>(du_b, du_f),
          half_p = 0.5 * limited_slope<L>(dp_b, dp_f);
  store_lanes(&plus[0][q], keep ? n_plus : n0 + half_n);
  store_lanes(&plus[un][q], keep ? u0 + 0.5 * du : u0 + half_u);
  store_lanes(&plus[4][q], keep ? p_plus : p0 + half_p);
  store_lanes(&minus[0][q], keep ? n_minus : n0 - half_n);
  store_lanes(&minus[un][q], keep ? u0 - 0.5 * du : u0 - half_u);
  store_lanes(&minus[4][q], keep ? p_minus : p0 - half_p);
}

// Beside a wall the mirror ghost makes every even field a local extremum, and the limiter
// would flatten the wall cell to first order (a hydrostatic layer would then carry O(h)
// spurious velocities there). Even fields take a one-sided interior slope instead (zero if
// a face value would leave [x/2, 2x]); u_z, odd, keeps the mirror. The wall's own Riemann
// problem is the exact mirror image of the wall cell's face state, so its mass and energy
// fluxes vanish by symmetry too.
// The slope is the second-order one-sided difference (-3 x0 + 4 x1 - x2) / 2, exact for
// quadratics like the interior central slope: the wall cell's face values then carry the
// interior's O(h^2) error, and the jump at its interior face stays O(h^3). The plain
// difference x1 - x0 is the slope at that face, not at the cell centre (twice the centre
// slope of an even field): its O(h^2) jump, times the sound speed in the Riemann flux's
// dissipation, was an O(h) truncation error in the wall cell and a first-order density
// error there (MMS full_walls, n Linf pair orders 80 -> 640 cells: 1.58 1.46 1.11 with
// x1 - x0; 1.97 2.00 to 320 cells with this slope).
// sign: +1 when the wanted face lies on the interior side of the cell centre. First order:
// no slope, as everywhere else.
template <Limiter L>
inline void wall_cell(const BlockContext& x, std::ptrdiff_t c, std::ptrdiff_t interior_step, double sign,
                      FaceStates& face, int slot) {
  for (int v = 0; v < 7; ++v) {
    if (v == x.un_index) continue;
    const double* field = x.fields[v];
    const double x0 = field[c];
    const double half_slope = L == Limiter::first_order
                                  ? 0.0
                                  : 0.25 * (4.0 * field[c + interior_step] - 3.0 * x0 - field[c + 2 * interior_step]);
    const double value = x0 + sign * half_slope, other = x0 - sign * half_slope;
    const bool keep = value >= 0.5 * x0 && value <= 2.0 * x0 && other >= 0.5 * x0 && other <= 2.0 * x0;
    face[v][slot] = keep ? value : x0;
  }
}

/// The wall's ghost face state: the mirror image of the wall cell's (u_n reversed).
inline void mirror(const BlockContext& x, const FaceStates& from, int from_slot, FaceStates& to, int to_slot) {
  for (int v = 0; v < 7; ++v) to[v][to_slot] = v == x.un_index ? -from[v][from_slot] : from[v][from_slot];
}

/// The face states of wall face f (0 or length) and of the wall cells' interior faces
/// (1, length - 1) of the pencil whose first cell is `first`; the face's left state is
/// plus[.][left], its right one minus[.][left + W].
template <Limiter L>
inline void wall_face(const BlockContext& x, std::ptrdiff_t first, int f, int left, int W, FaceStates& minus,
                      FaceStates& plus) {
  const std::ptrdiff_t s = x.s;
  const int right = left + W;
  const std::ptrdiff_t cR = first + f * s, cL = cR - s;
  if (f == 0) {
    wall_cell<L>(x, cR, s, -1.0, minus, right);
    mirror(x, minus, right, plus, left);
  } else if (f == x.length) {
    wall_cell<L>(x, cL, -s, -1.0, plus, left);
    mirror(x, plus, left, minus, right);
  } else {
    if (f == 1) wall_cell<L>(x, cL, s, +1.0, plus, left);
    if (f == x.length - 1) wall_cell<L>(x, cR, -s, +1.0, minus, right);
  }
}

/// Both face states of every cell of the block (each cell's slopes once, field by field:
/// simple loops without a dependence from one cell to the next), wall cells included.
template <Limiter L>
inline void reconstruct_block(const BlockContext& x, const Block& block, FaceStates& minus, FaceStates& plus) {
  const std::ptrdiff_t s = x.s;
  for (int v = 0; v < 7; ++v) {
    if (x.pressure && (v == 0 || v == x.un_index || v == 4)) continue;  // characteristic_faces does these
    const double* field = x.fields[v];
    block.over_cells(s, [&](std::ptrdiff_t c, int slot, auto lanes) {
      reconstruct_lanes<L, decltype(lanes)>(field + c, s, minus[v] + slot, plus[v] + slot);
    });
  }
  if (x.pressure)
    block.over_cells(s, [&](std::ptrdiff_t c, int slot, auto lanes) {
      characteristic_faces<L, decltype(lanes)>(x, c, slot, minus, plus);
    });
  if (x.walls)
    for (int f = block.f0; f < block.f1; ++f)
      if (f <= 1 || f >= x.length - 1)
        for (int lane = 0; lane < block.W; ++lane)
          wall_face<L>(x, block.base + lane, f, (f - block.f0) * block.W + lane, block.W, minus, plus);
}

}  // namespace inviscid

}  // namespace shaker::continuum
