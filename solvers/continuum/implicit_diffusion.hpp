#pragma once
// Backward-Euler step of the diffusive terms with coefficients frozen at the step's start,
// for the stiff `full` transport (its diffusivities grow like 1/nu in the dilute gas):
//   n (u* - u) / dt = div(c grad u*) per velocity component, c = lambda + 4 mu / 3 along the
//   component's own direction and mu across it; then
//   (3/2) n (T* - T) / dt = div(kappa grad T*) + Phi,
// Phi the viscous dissipation of the implicit momentum step (discrete, face by face, plus
// n |u* - u|^2 / (2 dt)), which makes the step conserve total energy exactly (to the linear
// solver's tolerance). Each system is symmetric positive definite (Eigen: LDLT in 1D,
// preconditioned conjugate gradients in 3D). Mass is untouched. The mixed-derivative
// viscous terms of 3D (d_i (mu d_j u_i), i != j) are not part of this operator; in 3D the full
// variant keeps only the terms above (stated in the report).
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <memory>
#include <vector>

#include "continuum/operator.hpp"

namespace shaker::continuum {

class ImplicitDiffusion {
 public:
  explicit ImplicitDiffusion(const Grid& grid);
  /// Advances the interior of U by dt; op supplies the closure (evaluated here at U).
  void advance(Operator& op, State& U, double dt);

 private:
  using Matrix = Eigen::SparseMatrix<double>;
  void assemble(const Operator& op, int component, double dt);  ///< component 0..2: u, 3: T
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs);

  Grid grid_;
  std::vector<std::ptrdiff_t> storage_;  ///< interior cell m -> storage index
  std::vector<Eigen::Triplet<double>> triplets_;
  Matrix matrix_;
  // 1D: the matrix is tridiagonal in the natural order (no fill, no reordering needed), and
  // its pattern never changes: analysed once, only factorised per solve.
  // (Held by pointer: Eigen's factorisations cannot be moved, the integrator must be.)
  using Tridiagonal = Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::NaturalOrdering<int>>;
  std::unique_ptr<Tridiagonal> tridiagonal_;
};

}  // namespace shaker::continuum
