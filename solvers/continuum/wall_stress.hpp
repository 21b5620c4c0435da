#pragma once
// The viscous normal stress at a wall, one definition for the explicit kernels
// (viscous_flux.cpp) and the implicit diffusion step (implicit_diffusion.cpp).
// The wall face is treated as an interior face whose outer cell is a ghost extrapolated from
// the first three cells (centres h/2, 3h/2, 5h/2 from the wall): u_z from the cubic through
// u_z(wall) = 0 and the three cells, each transport coefficient from the quadratic through
// them. The face then has the interior faces' error, O(h^2), so the wall cell's local error
// stays O(h^2) and the force the wall exerts is second order. A mirror ghost (u_g = -u_0, the
// wall cell's own coefficient) is the same only where n and T are even and u_z odd about the
// wall: where n' != 0 or u_z'' != 0 there its slope 2 u_0 / h = u_z'(0) + u_z''(0) h / 2 and
// coefficient mu(h/2) make an O(h) error of the wall force (mms WallViscousStress), which
// moves the column's centre of mass at first order.
namespace shaker::continuum::wall {

/// h u_z'(wall) = (u_0 - u_ghost) = sum_i slope_weight[i] u_i, cells i = 0, 1, 2 counted from
/// the wall inwards, times the wall's side (+1 the plate, -1 the ceiling);
/// u_ghost = -3 u_0 + u_1 - u_2 / 5.
inline constexpr double slope_weight[3] = {4.0, -1.0, 0.2};

template <class S> S normal_slope(const S (&u)[3], double side, double inv_h) {
  return side * inv_h * (slope_weight[0] * u[0] + slope_weight[1] * u[1] + slope_weight[2] * u[2]);
}

/// A transport coefficient in the ghost cell from cells 0, 1, 2: quadratic extrapolation,
/// 3 x0 - 3 x1 + x2, kept within [x0 / 2, 2 x0] (else x0, the mirror's): a coefficient that
/// changes by a factor 2 within three cells is not resolved there, and the extrapolation must
/// not make it negative. The face takes the harmonic mean of x0 and this, as interior faces do.
template <class S> S ghost_coefficient(S x0, S x1, S x2) {
  const S extrapolated = 3.0 * (x0 - x1) + x2;
  const S above_half = extrapolated >= 0.5 * x0 ? extrapolated : x0;
  return above_half <= 2.0 * x0 ? above_half : x0;
}

}  // namespace shaker::continuum::wall
