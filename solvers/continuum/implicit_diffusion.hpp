#pragma once
// Backward-Euler step of the diffusive terms with coefficients frozen at the step's start,
// for the stiff `full` transport (its diffusivities grow like 1/nu in the dilute gas):
//   n (u* - u) / dt = div(c grad u*) per velocity component, c = lambda + 4 mu / 3 along the
//   component's own direction and mu across it; then
//   (3/2) n (T* - T) / dt = div(kappa grad T*) + Phi,
// Phi the viscous dissipation of the implicit momentum step (discrete, face by face, plus
// n |u* - u|^2 / (2 dt)), which makes the step conserve total energy exactly (to the linear
// solver's tolerance). Each system is symmetric positive definite and diagonally dominant.
// A 1D column between walls gives a tridiagonal system, solved directly by two-sided
// (twisted) Gaussian elimination (O(n), no pivoting needed, nothing allocated per step); other grids use Eigen
// (LDLT for a periodic column; in 3D conjugate gradients preconditioned by Jacobi plus an exact
// solve of the horizontally uniform part). Mass is untouched.
// A 3D box run under an MPI launcher (any number of ranks, one included) is decomposed
// (halo.hpp) and uses a distributed CG of its own instead of Eigen's, with the same
// preconditioner (the second half of implicit_diffusion.cpp): Eigen's CG cannot span ranks, and one
// algorithm for every rank count makes the results differ between rank counts only by the
// order of the dot products' sums. A plain run keeps Eigen's CG, so its results stay those it
// always had.
// The mixed-derivative viscous terms of 3D (d_i (mu d_j u_i), i != j) are not part of this
// operator; in 3D the full variant keeps only the terms above (stated in the report).
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "continuum/operator.hpp"

namespace shaker::continuum {

class ImplicitDiffusion {
 public:
  /// `grid` as for the Operator: with a `halo`, this rank's block.
  explicit ImplicitDiffusion(const Grid& grid, std::shared_ptr<const Halo> halo = nullptr);
  /// Advances the interior of U by dt. op supplies the closure: evaluated here at U, unless
  /// closure_is_current says op's primitives and closure already belong to U.
  void advance(Operator& op, State& U, double dt, bool closure_is_current = false);

 private:
  using Matrix = Eigen::SparseMatrix<double>;
  /// Solves the system of `component` (0..2: u, 3: T) for rhs_ into x and adds nothing else.
  void solve(const Operator& op, int component, double dt, Eigen::VectorXd& x);
  void solve_column(const Operator& op, int component, double dt, Eigen::VectorXd& x);
  void assemble(const Operator& op, int component, double dt);
  void solve_sparse(Eigen::VectorXd& x);
  /// Adds the discrete viscous dissipation of velocity component `component` to dissipation_.
  void add_dissipation(const Operator& op, int component, const Eigen::VectorXd& u);
  /// The wall cell m's next cell away from its wall (m in the first or the last plane).
  Eigen::Index wall_neighbour(Eigen::Index m) const;
  /// visit(m, wall_neighbour(m)) for every wall cell m, when z has walls.
  template <class Visit> void for_each_wall_cell(Visit visit) const;

  // The decomposed box (the second half of implicit_diffusion.cpp); vectors in the block's storage.
  void advance_decomposed(Operator& op, State& U, double dt, bool closure_is_current);
  /// Face coefficients, diagonal and the coarse (plane) system of `component`.
  void assemble_decomposed(const Operator& op, int component, double dt);
  void apply_decomposed(const std::vector<double>& x, std::vector<double>& out) const;
  /// z = M^-1 r (Jacobi plus the plane-averaged column); returns (r.r, r.z) over the box.
  std::pair<double, double> precondition_decomposed(const std::vector<double>& r, std::vector<double>& z);
  void solve_decomposed(std::vector<double>& x);
  void add_dissipation_decomposed(const Operator& op, int component, std::vector<double>& u);
  double box_sum_of_products(const std::vector<double>& a, const std::vector<double>& b);

  Grid grid_;
  std::shared_ptr<const Halo> halo_;
  struct Decomposed {
    std::vector<double> rhs, dissipation, residual, preconditioned, search, product, diagonal, inverse_diagonal;
    std::array<std::vector<double>, 4> solution;  ///< u_x, u_y, u_z, T
    std::array<std::vector<double>, 3> face;  ///< coefficient of the face to the +x, +y, +z neighbour
    /// The coarse system: Ac(k, k - 1), its elimination, and the work vectors of the sums.
    std::vector<double> coarse_lower, inverse_pivot, upper, plane_sums, rhs_coarse;
  } decomposed_;
  bool column_ = false;  ///< 1D between walls: tridiagonal, Thomas algorithm
  std::vector<std::ptrdiff_t> storage_;  ///< interior cell m -> storage index
  // Work vectors, sized once (on the first advance).
  Eigen::VectorXd rhs_, dissipation_, temperature_;
  std::array<Eigen::VectorXd, 3> velocity_;
  /// column: face coefficients (face m between m, m + 1), diagonal, and the eliminated
  /// off-diagonals from the top (forward_) and from the bottom (backward_)
  std::vector<double> face_, diagonal_, forward_, backward_;
  // Sparse path.
  std::vector<Eigen::Triplet<double>> triplets_;
  Matrix matrix_;
  // A periodic column: tridiagonal plus corners; its pattern never changes, analysed once.
  // (Held by pointer: Eigen's factorisations cannot be moved, the integrator must be.)
  using Banded = Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::NaturalOrdering<int>>;
  std::unique_ptr<Banded> banded_;
};

}  // namespace shaker::continuum
