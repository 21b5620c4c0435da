#include "continuum/implicit_diffusion.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <cmath>

#include "common/errors.hpp"

namespace shaker::continuum {

namespace {
inline double harmonic_mean(double a, double b) {
  const double sum = a + b;
  return sum > 0.0 ? 2.0 * a * b / sum : 0.0;
}
}  // namespace

ImplicitDiffusion::ImplicitDiffusion(const Grid& grid) : grid_(grid) {
  for (int k = 0; k < grid.nz; ++k)
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i) storage_.push_back(grid.index(i, j, k));
  const auto cells = static_cast<Eigen::Index>(storage_.size());
  matrix_.resize(cells, cells);
}

// Calls visit(m, neighbour_m or -1 for a wall, direction) for each face of each cell once
// (neighbours with larger index, plus the walls).
template <class Visit> void for_each_face(const Grid& g, Visit visit) {
  const auto id = [&](int i, int j, int k) {
    return static_cast<Eigen::Index>(i + g.nx * (j + static_cast<std::ptrdiff_t>(g.ny) * k));
  };
  const bool walls = g.z_boundary == ZBoundary::walls;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Eigen::Index m = id(i, j, k);
        if (g.dimension == 3) {
          visit(m, id((i + 1) % g.nx, j, k), 0);
          visit(m, id(i, (j + 1) % g.ny, k), 1);
        }
        if (k + 1 < g.nz)
          visit(m, id(i, j, k + 1), 2);
        else if (!walls)
          visit(m, id(i, j, 0), 2);
        if (walls && (k == 0 || k + 1 == g.nz)) visit(m, Eigen::Index{-1}, 2);
      }
}

void ImplicitDiffusion::assemble(const Operator& op, int component, double dt) {
  const auto& w = op.primitives();
  const auto& cl = op.closure();
  const double inv_h2 = 1.0 / (grid_.h * grid_.h);
  triplets_.clear();
  const double mass_factor = component == 3 ? 1.5 : 1.0;
  for (std::size_t m = 0; m < storage_.size(); ++m) {
    const auto c = storage_[m];
    triplets_.emplace_back(m, m, mass_factor * w[0][c] / dt);
  }
  const auto coefficient = [&](std::ptrdiff_t c, int direction) {
    if (component == 3) return cl.kappa[c];
    return direction == component ? cl.lambda[c] + 4.0 / 3.0 * cl.mu[c] : cl.mu[c];
  };
  for_each_face(grid_, [&](Eigen::Index a, Eigen::Index b, int direction) {
    const auto ca = storage_[a];
    if (b < 0) {  // wall: only u_z has a condition (u_z = 0, mirror ghost), the rest no flux
      if (component == 2) triplets_.emplace_back(a, a, 2.0 * coefficient(ca, direction) * inv_h2);
      return;
    }
    if (a == b) return;  // a single cell across a periodic direction
    const double f = harmonic_mean(coefficient(ca, direction), coefficient(storage_[b], direction)) * inv_h2;
    triplets_.emplace_back(a, a, f);
    triplets_.emplace_back(b, b, f);
    triplets_.emplace_back(a, b, -f);
    triplets_.emplace_back(b, a, -f);
  });
  matrix_.setFromTriplets(triplets_.begin(), triplets_.end());
}

Eigen::VectorXd ImplicitDiffusion::solve(const Eigen::VectorXd& rhs) {
  if (grid_.dimension == 1) {
    if (!tridiagonal_) {
      tridiagonal_ = std::make_unique<Tridiagonal>();
      tridiagonal_->analyzePattern(matrix_);
    }
    tridiagonal_->factorize(matrix_);
    if (tridiagonal_->info() != Eigen::Success) throw DomainError("implicit diffusion: factorisation failed");
    return tridiagonal_->solve(rhs);
  }
  Eigen::ConjugateGradient<Matrix, Eigen::Lower | Eigen::Upper> solver;
  solver.setTolerance(1e-13);
  solver.compute(matrix_);
  Eigen::VectorXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success) throw DomainError("implicit diffusion: CG did not converge");
  return x;
}

void ImplicitDiffusion::advance(Operator& op, State& U, double dt) {
  op.prepare(U);
  const auto& w = op.primitives();
  const auto& cl = op.closure();
  const std::size_t cells = storage_.size();
  const auto M = static_cast<Eigen::Index>(cells);
  std::vector<Eigen::VectorXd> velocity(3, Eigen::VectorXd(M));
  Eigen::VectorXd dissipation = Eigen::VectorXd::Zero(M);
  const double inv_h2 = 1.0 / (grid_.h * grid_.h);
  for (int component = 0; component < 3; ++component) {
    Eigen::VectorXd rhs(M);
    for (std::size_t m = 0; m < cells; ++m) rhs[m] = w[0][storage_[m]] * w[1 + component][storage_[m]] / dt;
    // A component that vanishes everywhere stays zero exactly (e.g. u_x, u_y of a 1D column).
    if (rhs.isZero(0.0)) {
      velocity[component].setZero();
      continue;
    }
    assemble(op, component, dt);
    velocity[component] = solve(rhs);
    const Eigen::VectorXd& u = velocity[component];
    // Discrete dissipation: what the implicit step removes from the kinetic energy.
    for (std::size_t m = 0; m < cells; ++m) {
      const double change = u[m] - w[1 + component][storage_[m]];
      dissipation[m] += 0.5 * w[0][storage_[m]] * change * change / dt;
    }
    for_each_face(grid_, [&](Eigen::Index a, Eigen::Index b, int direction) {
      const auto coefficient = [&](std::ptrdiff_t c) {
        return direction == component ? cl.lambda[c] + 4.0 / 3.0 * cl.mu[c] : cl.mu[c];
      };
      if (b < 0) {
        if (component == 2) dissipation[a] += 2.0 * coefficient(storage_[a]) * u[a] * u[a] * inv_h2;
        return;
      }
      if (a == b) return;
      const double f = harmonic_mean(coefficient(storage_[a]), coefficient(storage_[b])) * inv_h2;
      const double jump = u[a] - u[b];
      dissipation[a] += 0.5 * f * jump * jump;
      dissipation[b] += 0.5 * f * jump * jump;
    });
  }
  Eigen::VectorXd rhs(M);
  for (std::size_t m = 0; m < cells; ++m)
    rhs[m] = 1.5 * w[0][storage_[m]] * w[4][storage_[m]] / dt + dissipation[m];
  assemble(op, 3, dt);
  const Eigen::VectorXd T = solve(rhs);
  for (std::size_t m = 0; m < cells; ++m) {
    const auto c = storage_[m];
    store_primitive(U, c, Primitive{w[0][c], velocity[0][m], velocity[1][m], velocity[2][m], T[m]});
  }
}

}  // namespace shaker::continuum
