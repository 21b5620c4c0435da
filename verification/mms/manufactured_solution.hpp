#pragma once
// Manufactured fields n, u, T for the method of manufactured solutions.
//
// Written once, as a template over the scalar, so that the source terms (automatic
// differentiation, mms_source.hpp), the independent finite-difference check (long double) and
// the exact solution the solver is compared against (double) all evaluate the same code.
//
// Geometry: 0 <= z <= Lz between the plate and the ceiling (container frame), x and y periodic
// with periods Lx, Ly. Every z dependence is cos(j pi z / Lz + phase) or, for u_z,
// sin(j pi z / Lz + phase); with wall_compatible (phase 0) the fields satisfy the wall
// conditions of docs/models.md at z = 0 and z = Lz for all t, x, y: u_z = 0 and zero normal
// gradients of u_x, u_y, T (and of n). Otherwise the phases are shifted so the solution needs
// exact (Dirichlet) boundary data instead.
//
// Bounds (checked by test_mms_source.cpp on a dense sample): n in n0 [0.62, 1.38], so with
// n0 = 0.4 nu = pi n / 6 stays in [0.13, 0.29], well below nu_max = 0.65; T in T0 [0.55, 1.45].
// dimension 1: a vertical column, u_x = u_y = 0 and nothing depends on x or y.
// dimension 3: every field varies in x, y, z and t.
#include <array>
#include <cmath>

#include "common/units.hpp"

namespace shaker::mms {

template <class S> struct Fields {
  S n;
  std::array<S, 3> u;  ///< x, y, z components
  S T;
};

struct ManufacturedSolution {
  int dimension = 1;              ///< 1 or 3
  double Lx = 11.0, Ly = 11.0;    ///< horizontal periods (the continuum box)
  double Lz = 10.0;               ///< height of the column
  bool wall_compatible = true;
  /// With wall_compatible: n also has a normal gradient and u_z a curvature at the walls, which
  /// the wall conditions allow and the mirror symmetry of the ghost cells does not have.
  bool wall_gradients = false;
  double n0 = 0.4;                ///< mean number density
  double T0 = 1.0;                ///< mean temperature
  double U0 = 0.3;                ///< velocity amplitude
  double omega = 0.5;             ///< angular frequency of the time dependence
  int density_mode = 4;           ///< half-wavelengths of n's main vertical shape across Lz

  template <class S> Fields<S> operator()(const S& t, const S& x, const S& y, const S& z) const {
    using std::cos;
    using std::sin;
    constexpr double shifted = 0.37;  // a phase that makes the walls no symmetry planes
    const double wall_phase = wall_compatible ? 0.0 : shifted;
    // Vertical shapes: j half-wavelengths across the column.
    const auto c = [&](int j) { return cos(static_cast<double>(j) * pi / Lz * z + wall_phase); };
    const auto s = [&](int j) { return sin(static_cast<double>(j) * pi / Lz * z + wall_phase); };
    const double density_phase = wall_gradients ? shifted : wall_phase;
    const auto c_n = [&](int j) { return cos(static_cast<double>(j) * pi / Lz * z + density_phase); };
    // zero with its slope at z = 0 and Lz, curvature 2 (2 pi / Lz)^2 there
    S bowl = 0.0 * z;
    if (wall_gradients) bowl = 1.0 - cos(2.0 * pi / Lz * z);
    const double kx = 2.0 * pi / Lx, ky = 2.0 * pi / Ly;
    const double d = dimension == 3 ? 1.0 : 0.0;  // switches the horizontal variation on

    Fields<S> f;
    f.n = n0 * (1.0 + 0.2 * c_n(density_mode) * (1.0 + 0.4 * sin(omega * t)) +
                d * 0.1 * sin(kx * x + 0.3) * cos(ky * y - 0.2 + 0.5 * omega * t) * c(2));
    f.T = T0 * (1.0 + 0.3 * c(3) * cos(omega * t + 0.5) +
                d * 0.1 * cos(kx * x - ky * y + omega * t) * c(5));
    f.u[2] = U0 * ((s(4) + 0.5 * bowl) * (0.6 + 0.4 * cos(omega * t)) +
                   d * 0.3 * cos(kx * x) * sin(ky * y + 0.3 - omega * t) * s(2));
    f.u[0] = d * U0 * (0.5 * sin(kx * x + ky * y + 0.2 * omega * t) * c(2) +
                       0.2 * cos(ky * y) * c(3));
    f.u[1] = d * U0 * (0.4 * cos(kx * x - 0.4 + omega * t) * c(3) * (1.0 + 0.3 * sin(ky * y)));
    return f;
  }
};

}  // namespace shaker::mms
