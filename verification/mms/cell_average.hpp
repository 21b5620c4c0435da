#pragma once
// Cell averages of the manufactured fields and sources, for finite-volume runs: the initial
// state and the reference solution of a cell are its averages, and the source of a cell is the
// average of the pointwise source. Three-point Gauss-Legendre in each direction (exact for
// polynomials of degree 5, error O(h^6) for smooth integrands), so the averaging error stays
// far below the O(h^2) discretisation error being measured.
#include <array>
#include <cmath>

#include "manufactured_solution.hpp"
#include "mms_source.hpp"

namespace shaker::mms {

namespace detail {
inline constexpr std::array<double, 3> gauss_offsets{-0.7745966692414834, 0.0, 0.7745966692414834};
inline constexpr std::array<double, 3> gauss_weights{5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
}  // namespace detail

// Scaling and accumulation of the result types cell_average supports.
inline double scaled(double x, double w) { return w * x; }
inline void accumulate(double& sum, double x, double w) { sum += w * x; }
inline Fields<double> scaled(const Fields<double>& f, double w) {
  return {w * f.n, {w * f.u[0], w * f.u[1], w * f.u[2]}, w * f.T};
}
inline void accumulate(Fields<double>& sum, const Fields<double>& f, double w) {
  sum.n += w * f.n;
  for (int i = 0; i < 3; ++i) sum.u[i] += w * f.u[i];
  sum.T += w * f.T;
}
inline Residual scaled(const Residual& r, double w) {
  return {w * r.mass, {w * r.momentum[0], w * r.momentum[1], w * r.momentum[2]}, w * r.energy};
}
inline void accumulate(Residual& sum, const Residual& r, double w) {
  sum.mass += w * r.mass;
  for (int i = 0; i < 3; ++i) sum.momentum[i] += w * r.momentum[i];
  sum.energy += w * r.energy;
}

/// Average of f(point) over the box centre +- width / 2. In 1D (dimension 1) only z is
/// integrated and x, y stay at the centre. f returns anything with +=, * double (a double,
/// Fields<double>, Residual).
template <class Function>
auto cell_average(const Function& f, const std::array<double, 3>& centre,
                  const std::array<double, 3>& width, int dimension) {
  using detail::gauss_offsets;
  using detail::gauss_weights;
  const int horizontal_points = dimension == 3 ? 3 : 1;
  using Result = decltype(f(centre));
  Result sum{};
  bool first = true;
  for (int i = 0; i < horizontal_points; ++i)
    for (int j = 0; j < horizontal_points; ++j)
      for (int k = 0; k < 3; ++k) {
        const double wx = dimension == 3 ? gauss_weights[i] : 1.0;
        const double wy = dimension == 3 ? gauss_weights[j] : 1.0;
        const double ox = dimension == 3 ? gauss_offsets[i] : 0.0;
        const double oy = dimension == 3 ? gauss_offsets[j] : 0.0;
        const std::array<double, 3> point{centre[0] + 0.5 * width[0] * ox,
                                          centre[1] + 0.5 * width[1] * oy,
                                          centre[2] + 0.5 * width[2] * gauss_offsets[k]};
        const double weight = wx * wy * gauss_weights[k];
        if (first) {
          sum = scaled(f(point), weight);
          first = false;
        } else {
          accumulate(sum, f(point), weight);
        }
      }
  return sum;
}

/// Cell averages of n, u, T at time t (primitive fields averaged; a conservative scheme that
/// needs averages of n u or of the energy integrates those with cell_average directly).
inline Fields<double> average_fields(const ManufacturedSolution& solution, double t,
                                     const std::array<double, 3>& centre,
                                     const std::array<double, 3>& width) {
  return cell_average(
      [&](const std::array<double, 3>& x) { return solution(t, x[0], x[1], x[2]); }, centre,
      width, solution.dimension);
}

/// Cell average of the conservative-form source at time t.
inline Residual average_conservative_source(const ManufacturedSolution& solution,
                                            const Physics& physics, const Terms& terms, double t,
                                            const std::array<double, 3>& centre,
                                            const std::array<double, 3>& width) {
  return cell_average(
      [&](const std::array<double, 3>& x) {
        return conservative_source(solution, physics, terms, t, x);
      },
      centre, width, solution.dimension);
}

}  // namespace shaker::mms
