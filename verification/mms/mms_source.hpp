#pragma once
// Source terms of the method of manufactured solutions: the residual of the full continuum
// equations of docs/models.md for the fields of manufactured_solution.hpp, by automatic
// differentiation through the constitutive functions of common/granular_model.hpp (no
// hand-expanded formula: the solver and the source share those functions).
//
// Two nested Eigen::AutoDiffScalar levels over (t, x, y, z): the outer level differentiates the
// fields once more, so that the velocity and temperature gradients entering P and q are
// themselves differentiable and div P, div q come out exact to rounding.
//
// Primitive form (as docs/models.md writes the equations), residual R = left side - right side:
//   R_n = dn/dt + div(n u)
//   R_i = n (du_i/dt + u . grad u_i) - d_j P_ij - n b_i
//   R_E = (3/2) n (dT/dt + u . grad T) + div q - P : E + gamma
// with P_ij = [-p + (lambda - 2 mu / 3) E_kk] delta_ij + 2 mu E_ij, q = -kappa grad T and the
// body force per unit mass b = -(g + a_p(t)) z_hat = -g (1 + Gamma cos(omega t)) z_hat.
// Conservative form, for the variables (n, n u, n |u|^2 / 2 + (3/2) n T):
//   S_n = R_n,  S_i = d_t(n u_i) + d_j(n u_i u_j - P_ij) - n b_i,
//   S_E = d_t E + d_j(E u_j - P_ij u_i + q_j) - n b . u + gamma.
// A solver that integrates dU/dt = L(U) adds S (or R for a primitive-variable scheme) to L.
// Each physical term can be switched off (Terms); the same switch acts on both forms, and on
// both the momentum and the energy equation (a pressure switched off also drops -p div u).
//
// Plugging into the continuum solver (solvers/continuum/operator.hpp): its conserved variables
// are exactly (n, n u, E) above, so Operator::external_source adds conservative_source (or,
// better for a finite-volume scheme, average_conservative_source of cell_average.hpp) to
// out[density], out[momentum_x..z], out[energy]. Its term switches map one to one, except
// that its `advection` is the whole inviscid flux (pressure included): solver advection off
// means mms advection and pressure off. time_derivative = false exists only for checking
// this file (a solver always has dU/dt). The artificial dissipation of the `paper` variant is
// a numerical term with no counterpart here: switch it off in MMS runs (the manufactured
// nu >= 0.13 keeps its density switch below 4e-5 anyway, but it is first order in h).
#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include <array>

#include "common/granular_model.hpp"
#include "common/shaker_kinematics.hpp"
#include "manufactured_solution.hpp"

namespace shaker::mms {

struct Terms {
  bool time_derivative = true;
  bool advection = true;
  bool pressure = true;
  bool bulk_viscosity = true;
  bool shear_viscosity = true;
  bool conduction = true;
  bool collisional_loss = true;
  bool gravity = true;        ///< -n g
  bool frame_forcing = true;  ///< -n a_p(t), the oscillating frame force

  static Terms none() {
    return {false, false, false, false, false, false, false, false, false};
  }
};

/// The physical parameters the source depends on.
struct Physics {
  double e = 0.9;
  model::Transport transport = model::Transport::full;
  ShakerKinematics shaker{3.0, 0.095};
};

/// Residual or source of the mass, momentum (x, y, z) and energy equations at one point.
struct Residual {
  double mass = 0.0;
  std::array<double, 3> momentum{};
  double energy = 0.0;
};

namespace detail {
using Gradient = Eigen::Matrix<double, 4, 1>;  ///< d/dt, d/dx, d/dy, d/dz
using First = Eigen::AutoDiffScalar<Gradient>;
using Second = Eigen::AutoDiffScalar<Eigen::Matrix<First, 4, 1>>;

/// Independent variable number `index` (0 = t, 1..3 = x, y, z) at `value`, seeded at both levels.
inline Second seed(double value, int index) {
  Second s;
  s.value() = First(value, 4, index);
  s.derivatives().resize(4);
  for (int a = 0; a < 4; ++a) s.derivatives()(a) = First(a == index ? 1.0 : 0.0, Gradient::Zero());
  return s;
}

/// The fields and what both forms need, at the first AD level (value and gradient).
struct Point {
  First n, T;
  std::array<First, 3> u;
  std::array<std::array<First, 3>, 3> grad_u;  ///< grad_u[i][j] = d_j u_i, differentiable
  std::array<First, 3> grad_T;
  std::array<std::array<First, 3>, 3> P;       ///< stress tensor with the enabled terms
  std::array<First, 3> q;                      ///< heat flux (zero with conduction off)
  double body_force_z = 0.0;                   ///< b_z with the enabled terms
  double loss = 0.0;                           ///< gamma (zero with the loss off)
};

inline Point evaluate(const ManufacturedSolution& solution, const Physics& physics,
                      const Terms& terms, double t, const std::array<double, 3>& x) {
  const Fields<Second> f =
      solution(seed(t, 0), seed(x[0], 1), seed(x[1], 2), seed(x[2], 3));
  Point p;
  p.n = f.n.value();
  p.T = f.T.value();
  for (int i = 0; i < 3; ++i) {
    p.u[i] = f.u[i].value();
    for (int j = 0; j < 3; ++j) p.grad_u[i][j] = f.u[i].derivatives()(j + 1);
    p.grad_T[i] = f.T.derivatives()(i + 1);
  }
  First divergence = p.grad_u[0][0] + p.grad_u[1][1] + p.grad_u[2][2];
  const First zero(0.0, Gradient::Zero());
  const First pressure = terms.pressure ? model::pressure(p.n, p.T, physics.e) : zero;
  const First lambda = terms.bulk_viscosity ? model::bulk_viscosity(p.n, p.T) : zero;
  const First mu =
      terms.shear_viscosity ? model::shear_viscosity(p.n, p.T, physics.transport) : zero;
  const First kappa =
      terms.conduction ? model::thermal_conductivity(p.n, p.T, physics.transport) : zero;
  const First isotropic = -pressure + (lambda - 2.0 / 3.0 * mu) * divergence;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const First strain = 0.5 * (p.grad_u[i][j] + p.grad_u[j][i]);
      p.P[i][j] = 2.0 * mu * strain + (i == j ? isotropic : zero);
    }
    p.q[i] = -kappa * p.grad_T[i];
  }
  if (terms.gravity) p.body_force_z -= gravity;
  if (terms.frame_forcing) p.body_force_z -= physics.shaker.acceleration(t);
  if (terms.collisional_loss) p.loss = model::collisional_loss(p.n, p.T, physics.e).value();
  return p;
}

inline double d(const First& q, int index) { return q.derivatives()(index); }
}  // namespace detail

/// Primitive-form residual (see the file comment) at time t and position x.
inline Residual primitive_residual(const ManufacturedSolution& solution, const Physics& physics,
                                   const Terms& terms, double t, const std::array<double, 3>& x) {
  using detail::d;
  const detail::Point p = detail::evaluate(solution, physics, terms, t, x);
  const double n = p.n.value();
  Residual r;
  if (terms.time_derivative) r.mass += d(p.n, 0);
  for (int j = 0; j < 3; ++j)
    if (terms.advection) r.mass += d(p.n * p.u[j], j + 1);

  double stress_power = 0.0;  // P : E = P_ij d_j u_i for symmetric P
  for (int i = 0; i < 3; ++i) {
    double& m = r.momentum[i];
    if (terms.time_derivative) m += n * d(p.u[i], 0);
    for (int j = 0; j < 3; ++j) {
      if (terms.advection) m += n * p.u[j].value() * p.grad_u[i][j].value();
      m -= d(p.P[i][j], j + 1);
      stress_power += p.P[i][j].value() * p.grad_u[i][j].value();
    }
  }
  r.momentum[2] -= n * p.body_force_z;

  if (terms.time_derivative) r.energy += 1.5 * n * d(p.T, 0);
  for (int j = 0; j < 3; ++j) {
    if (terms.advection) r.energy += 1.5 * n * p.u[j].value() * p.grad_T[j].value();
    r.energy += d(p.q[j], j + 1);
  }
  r.energy += -stress_power + p.loss;
  return r;
}

/// Conservative-form source for (n, n u, n |u|^2/2 + 3 n T / 2) at time t and position x.
inline Residual conservative_source(const ManufacturedSolution& solution, const Physics& physics,
                                    const Terms& terms, double t, const std::array<double, 3>& x) {
  using detail::d;
  using detail::First;
  const detail::Point p = detail::evaluate(solution, physics, terms, t, x);
  const First kinetic = 0.5 * p.n * (p.u[0] * p.u[0] + p.u[1] * p.u[1] + p.u[2] * p.u[2]);
  const First energy = kinetic + 1.5 * p.n * p.T;
  Residual s;
  if (terms.time_derivative) {
    s.mass += d(p.n, 0);
    for (int i = 0; i < 3; ++i) s.momentum[i] += d(p.n * p.u[i], 0);
    s.energy += d(energy, 0);
  }
  for (int j = 0; j < 3; ++j) {
    if (terms.advection) {
      s.mass += d(p.n * p.u[j], j + 1);
      for (int i = 0; i < 3; ++i) s.momentum[i] += d(p.n * p.u[i] * p.u[j], j + 1);
      s.energy += d(energy * p.u[j], j + 1);
    }
    for (int i = 0; i < 3; ++i) {
      s.momentum[i] -= d(p.P[i][j], j + 1);
      s.energy -= d(p.P[i][j] * p.u[i], j + 1);
    }
    s.energy += d(p.q[j], j + 1);
  }
  s.momentum[2] -= p.n.value() * p.body_force_z;
  s.energy += -p.n.value() * p.body_force_z * p.u[2].value() + p.loss;
  return s;
}

}  // namespace shaker::mms
