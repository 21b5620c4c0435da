#include "continuum/implicit_diffusion.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include "common/errors.hpp"
#include "continuum/face_coefficients.hpp"
#include "continuum/halo.hpp"

namespace shaker::continuum {

namespace {

/// Diffusion coefficient of `component` (0..2: u_x, u_y, u_z; 3: T) across a face normal
/// to `direction`.
inline double coefficient(const Operator::Closure& cl, std::ptrdiff_t c, int component, int direction) {
  if (component == 3) return cl.kappa[c];
  return direction == component ? cl.lambda[c] + 4.0 / 3.0 * cl.mu[c] : cl.mu[c];
}
/// The u_z row of wall cell c0 (c1 the next cell away from the wall) holds the wall's normal
/// stress as diagonal * u_z*(c0) - lagged, both per unit volume and velocity or momentum. The
/// mirror wall: 2 (lambda + 4 mu / 3)(c0) / h^2, nothing lagged. The second-order wall
/// (viscous_flux.cpp, wall_normal_stress): C (7 m_0 - m_1) / (2 h^2 n_w), C = 4 mu_w / 3 +
/// lambda_w, with m_0 = n_0 u_z*(c0) implicit and m_1 = n_1 u_z(c1) at the step's start, so
/// the matrix stays symmetric (as CG needs) and keeps its positive diagonal; the lag is an
/// O(dt) error of the step like backward Euler's own, which the extrapolated integrator's
/// half steps cancel with it. The tangential divergence of the wall stress is one of the
/// mixed-derivative terms this operator leaves out.
struct WallRow {
  double diagonal = 0.0, lagged = 0.0;
};
WallRow wall_row(const Operator& op, std::ptrdiff_t c0, std::ptrdiff_t c1, double inv_h2) {
  const auto& cl = op.closure();
  if (op.settings().wall_stress == WallStress::mirror) return {2.0 * coefficient(cl, c0, 2, 2) * inv_h2, 0.0};
  const double* n = op.primitives()[0].data();
  const double* u = op.primitives()[3].data();
  const double c = 4.0 / 3.0 * extrapolated_to_wall(cl.mu[c0], cl.mu[c1]) +
                   extrapolated_to_wall(cl.lambda[c0], cl.lambda[c1]);
  const double scale = c * 0.5 * inv_h2 / extrapolated_to_wall(n[c0], n[c1]);
  return {7.0 * n[c0] * scale, n[c1] * u[c1] * scale};
}
/// A decomposed block's wall cells are its first and last planes (z is not decomposed); the
/// wall row of cell c of such a plane k.
bool wall_plane(const Grid& g, int k) { return k == 0 || k + 1 == g.nz; }
WallRow plane_wall_row(const Operator& op, const Grid& g, std::ptrdiff_t c, int k, double inv_h2) {
  return wall_row(op, c, c + (k == 0 ? g.stride(2) : -g.stride(2)), inv_h2);
}

/// CG preconditioner for the 3D systems: Jacobi plus an exact solve of the horizontally
/// uniform part (two-level, additive: z = D^-1 r + P Ac^-1 P^T r, P the constant prolongation
/// from the nz planes of cells, Ac = P^T A P, tridiagonal). The base case is nearly flat and
/// stiff where the gas is dilute: the slow modes of Jacobi-preconditioned CG are the
/// horizontally uniform, vertically smooth ones (a column is 80 / h cells tall), and the
/// coarse solve removes exactly those. Rows are cells m = i + nx (j + ny k): plane k is the
/// rows plane k .. plane (k + 1) - 1. Symmetric positive definite, as CG needs.
class PlaneAveragedColumn {
 public:
  using StorageIndex = int;
  void set_planes(Eigen::Index plane, Eigen::Index planes) {
    plane_ = plane;
    planes_ = planes;
  }
  template <class M> PlaneAveragedColumn& analyzePattern(const M&) { return *this; }
  template <class M> PlaneAveragedColumn& compute(const M& a) { return factorize(a); }
  template <class M> PlaneAveragedColumn& factorize(const M& a) {
    const auto n = static_cast<std::size_t>(a.cols());
    const auto planes = static_cast<std::size_t>(planes_);
    inverse_diagonal_.assign(n, 1.0);
    std::vector<double> diagonal(planes, 0.0);  // Ac(k, k); lower_ holds Ac(k, k - 1)
    lower_.assign(planes, 0.0);
    for (Eigen::Index col = 0; col < a.outerSize(); ++col) {
      const auto k = static_cast<std::size_t>(col / plane_);
      for (typename M::InnerIterator it(a, col); it; ++it) {
        if (it.index() == col && it.value() != 0.0) inverse_diagonal_[static_cast<std::size_t>(col)] = 1.0 / it.value();
        const auto row_plane = static_cast<std::size_t>(it.index() / plane_);
        if (row_plane == k) diagonal[k] += it.value();
        else if (row_plane + 1 == k) lower_[k] += it.value();
      }
    }
    // Thomas elimination of Ac once per matrix.
    inverse_pivot_.assign(planes, 1.0);
    upper_.assign(planes, 0.0);
    for (std::size_t k = 0; k < planes; ++k) {
      const double pivot = diagonal[k] - (k > 0 ? lower_[k] * upper_[k - 1] : 0.0);
      inverse_pivot_[k] = 1.0 / pivot;
      upper_[k] = (k + 1 < planes ? lower_[k + 1] : 0.0) * inverse_pivot_[k];
    }
    return *this;
  }
  template <class Rhs> Eigen::VectorXd solve(const Rhs& r) const {
    const auto planes = static_cast<std::size_t>(planes_);
    std::vector<double>& coarse = coarse_;  // applied every CG iteration: no allocation
    coarse.resize(planes);
    for (std::size_t k = 0; k < planes; ++k) {
      double sum = 0.0;
      for (Eigen::Index m = static_cast<Eigen::Index>(k) * plane_; m < static_cast<Eigen::Index>(k + 1) * plane_; ++m)
        sum += r[m];
      coarse[k] = (sum - (k > 0 ? lower_[k] * coarse[k - 1] : 0.0)) * inverse_pivot_[k];
    }
    for (std::size_t k = planes - 1; k-- > 0;) coarse[k] -= upper_[k] * coarse[k + 1];
    Eigen::VectorXd z(r.size());
    for (Eigen::Index m = 0; m < r.size(); ++m)
      z[m] = inverse_diagonal_[static_cast<std::size_t>(m)] * r[m] + coarse[static_cast<std::size_t>(m / plane_)];
    return z;
  }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  Eigen::Index plane_ = 1, planes_ = 1;
  std::vector<double> inverse_diagonal_, lower_, upper_, inverse_pivot_;
  mutable std::vector<double> coarse_;  ///< solve's work vector, one value per plane
};
}  // namespace

ImplicitDiffusion::ImplicitDiffusion(const Grid& grid, std::shared_ptr<const Halo> halo)
    : grid_(grid), halo_(std::move(halo)), column_(grid.dimension == 1 && grid.z_boundary == ZBoundary::walls) {
  if (halo_) return;  // the decomposed path keeps its vectors in the block's storage
  for (int k = 0; k < grid.nz; ++k)
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i) storage_.push_back(grid.index(i, j, k));
  const auto cells = static_cast<Eigen::Index>(storage_.size());
  if (column_) {
    for (auto* v : {&face_, &diagonal_, &forward_, &backward_}) v->assign(storage_.size(), 0.0);
  } else {
    matrix_.resize(cells, cells);
  }
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

Eigen::Index ImplicitDiffusion::wall_neighbour(Eigen::Index m) const {
  const Eigen::Index plane = static_cast<Eigen::Index>(grid_.nx) * grid_.ny;
  if (grid_.nz == 1) return m;  // one plane between the walls: no other cell
  return m < plane ? m + plane : m - plane;
}

template <class Visit> void ImplicitDiffusion::for_each_wall_cell(Visit visit) const {
  if (grid_.z_boundary != ZBoundary::walls) return;
  const Eigen::Index plane = static_cast<Eigen::Index>(grid_.nx) * grid_.ny;
  const auto cells = static_cast<Eigen::Index>(storage_.size());
  for (Eigen::Index m = 0; m < plane; ++m) visit(m, wall_neighbour(m));
  for (Eigen::Index m = std::max(plane, cells - plane); m < cells; ++m) visit(m, wall_neighbour(m));
}

// Tridiagonal solve for the column: sub/super-diagonals -face_[m], diagonal the mass term
// plus the faces of the cell (plus the mirrored wall for u_z). The mass term makes the matrix
// strictly diagonally dominant, so elimination without pivoting is stable. Twisted
// (two-sided) elimination: rows from the top and from the bottom are eliminated together,
// meeting at the middle row, then substituted back outwards. The same work as the Thomas
// algorithm, but two independent chains of divisions of half the length, which a core
// overlaps (the one-sided sweep was bound by the latency of its chain).
void ImplicitDiffusion::solve_column(const Operator& op, int component, double dt, Eigen::VectorXd& x) {
  const double* n = op.primitives()[0].data();
  const auto& cl = op.closure();
  const std::size_t M = storage_.size();
  const double inv_h2 = 1.0 / (grid_.h * grid_.h);
  const double mass_factor = (component == 3 ? 1.5 : 1.0) / dt;
  for (std::size_t m = 0; m + 1 < M; ++m)
    face_[m] = harmonic_mean(coefficient(cl, storage_[m], component, 2),
                             coefficient(cl, storage_[m + 1], component, 2)) * inv_h2;
  face_[M - 1] = 0.0;
  for (std::size_t m = 0; m < M; ++m)
    diagonal_[m] = mass_factor * n[storage_[m]] + face_[m] + (m > 0 ? face_[m - 1] : 0.0);
  // wall: only u_z has a condition (u_z = 0), the rest no flux
  if (component == 2)
    for_each_wall_cell([&](Eigen::Index m, Eigen::Index next) {
      diagonal_[static_cast<std::size_t>(m)] += wall_row(op, storage_[m], storage_[next], inv_h2).diagonal;
    });
  // Rows 0 .. k - 1 from the top: x[m] + forward_[m] x[m + 1] = x[m] (the reduced right-hand
  // side, kept in x); rows M - 1 .. k + 1 from the bottom: x[m] + backward_[m] x[m - 1] = x[m].
  const std::size_t k = (M - 1) / 2;
  const auto top = [&](std::size_t m) {
    const double inverse_pivot =
        1.0 / (m > 0 ? diagonal_[m] + face_[m - 1] * forward_[m - 1] : diagonal_[m]);
    forward_[m] = -face_[m] * inverse_pivot;
    x[m] = (m > 0 ? rhs_[m] + face_[m - 1] * x[m - 1] : rhs_[m]) * inverse_pivot;
  };
  const auto bottom = [&](std::size_t m) {
    const double inverse_pivot =
        1.0 / (m + 1 < M ? diagonal_[m] + face_[m] * backward_[m + 1] : diagonal_[m]);
    backward_[m] = -face_[m - 1] * inverse_pivot;
    x[m] = (m + 1 < M ? rhs_[m] + face_[m] * x[m + 1] : rhs_[m]) * inverse_pivot;
  };
  for (std::size_t i = 0; i < k; ++i) {
    top(i);
    bottom(M - 1 - i);
  }
  if (M - 1 - k > k) bottom(k + 1);  // an even M has one more row below the middle
  double pivot = diagonal_[k], right = rhs_[k];
  if (k > 0) {
    pivot += face_[k - 1] * forward_[k - 1];
    right += face_[k - 1] * x[k - 1];
  }
  if (k + 1 < M) {
    pivot += face_[k] * backward_[k + 1];
    right += face_[k] * x[k + 1];
  }
  x[k] = right / pivot;
  for (std::size_t i = 1; i <= k; ++i) {
    x[k - i] -= forward_[k - i] * x[k - i + 1];
    x[k + i] -= backward_[k + i] * x[k + i - 1];
  }
  if (M - 1 - k > k) x[M - 1] -= backward_[M - 1] * x[M - 2];
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
  for_each_face(grid_, [&](Eigen::Index a, Eigen::Index b, int direction) {
    const auto ca = storage_[a];
    if (b < 0) {  // wall: only u_z has a condition (u_z = 0), the rest no flux
      if (component == 2) triplets_.emplace_back(a, a, wall_row(op, ca, storage_[wall_neighbour(a)], inv_h2).diagonal);
      return;
    }
    if (a == b) return;  // a single cell across a periodic direction
    const double f = harmonic_mean(coefficient(cl, ca, component, direction),
                                   coefficient(cl, storage_[b], component, direction)) * inv_h2;
    triplets_.emplace_back(a, a, f);
    triplets_.emplace_back(b, b, f);
    triplets_.emplace_back(a, b, -f);
    triplets_.emplace_back(b, a, -f);
  });
  matrix_.setFromTriplets(triplets_.begin(), triplets_.end());
}

void ImplicitDiffusion::solve_sparse(Eigen::VectorXd& x) {
  if (grid_.dimension == 1) {
    if (!banded_) {
      banded_ = std::make_unique<Banded>();
      banded_->analyzePattern(matrix_);
    }
    banded_->factorize(matrix_);
    if (banded_->info() != Eigen::Success) throw DomainError("implicit diffusion: factorisation failed");
    x = banded_->solve(rhs_);
    return;
  }
  Eigen::ConjugateGradient<Matrix, Eigen::Lower | Eigen::Upper, PlaneAveragedColumn> solver;
  solver.setTolerance(1e-13);
  solver.preconditioner().set_planes(static_cast<Eigen::Index>(grid_.nx) * grid_.ny, grid_.nz);
  solver.compute(matrix_);
  // Started from the state before the step (x on entry): the step changes it little except in
  // the stiff dilute gas, and CG then needs far fewer iterations than from zero.
  x = solver.solveWithGuess(rhs_, x);
  if (solver.info() != Eigen::Success) throw DomainError("implicit diffusion: CG did not converge");
}

void ImplicitDiffusion::solve(const Operator& op, int component, double dt, Eigen::VectorXd& x) {
  if (column_) return solve_column(op, component, dt, x);
  assemble(op, component, dt);
  solve_sparse(x);
}

void ImplicitDiffusion::add_dissipation(const Operator& op, int component, const Eigen::VectorXd& u) {
  const auto& cl = op.closure();
  const double inv_h2 = 1.0 / (grid_.h * grid_.h);
  const auto wall = [&](Eigen::Index a) {
    if (component != 2) return;
    const WallRow row = wall_row(op, storage_[a], storage_[wall_neighbour(a)], inv_h2);
    dissipation_[a] += (row.diagonal * u[a] - row.lagged) * u[a];
  };
  if (column_) {  // face_ still holds this component's coefficients
    const auto M = static_cast<Eigen::Index>(storage_.size());
    for (Eigen::Index m = 0; m + 1 < M; ++m) {
      const double jump = u[m] - u[m + 1];
      dissipation_[m] += 0.5 * face_[m] * jump * jump;
      dissipation_[m + 1] += 0.5 * face_[m] * jump * jump;
    }
    wall(0);
    if (M > 1) wall(M - 1);
    return;
  }
  for_each_face(grid_, [&](Eigen::Index a, Eigen::Index b, int direction) {
    if (b < 0) return wall(a);
    if (a == b) return;
    const double f = harmonic_mean(coefficient(cl, storage_[a], component, direction),
                                   coefficient(cl, storage_[b], component, direction)) * inv_h2;
    const double jump = u[a] - u[b];
    dissipation_[a] += 0.5 * f * jump * jump;
    dissipation_[b] += 0.5 * f * jump * jump;
  });
}

void ImplicitDiffusion::advance(Operator& op, State& U, double dt, bool closure_is_current) {
  if (halo_) return advance_decomposed(op, U, dt, closure_is_current);
  if (!closure_is_current) op.prepare(U);
  const auto& w = op.primitives();
  const std::size_t cells = storage_.size();
  // Work vectors sized on the first step, not at construction: a run that never diffuses
  // implicitly does not carry them (6 doubles per cell).
  if (rhs_.size() != static_cast<Eigen::Index>(cells))
    for (Eigen::VectorXd* v : {&rhs_, &dissipation_, &temperature_, &velocity_[0], &velocity_[1], &velocity_[2]})
      v->resize(static_cast<Eigen::Index>(cells));
  // body(m, storage index of interior cell m) for every cell; a column's cells are contiguous
  // in storage, and its loops then vectorise.
  const std::ptrdiff_t first = storage_.front();
  const auto for_cells = [&](auto body) {
    if (column_) {
      for (std::size_t m = 0; m < cells; ++m) body(m, first + static_cast<std::ptrdiff_t>(m));
    } else {
      for (std::size_t m = 0; m < cells; ++m) body(m, storage_[m]);
    }
  };
  const double* n = w[0].data();
  dissipation_.setZero();
  for (int component = 0; component < 3; ++component) {
    const double* u0 = w[1 + component].data();
    for_cells([&](std::size_t m, std::ptrdiff_t c) { rhs_[m] = n[c] * u0[c] / dt; });
    if (component == 2)
      for_each_wall_cell([&](Eigen::Index m, Eigen::Index next) {
        rhs_[m] += wall_row(op, storage_[m], storage_[next], 1.0 / (grid_.h * grid_.h)).lagged;
      });
    Eigen::VectorXd& u = velocity_[component];
    // A component that vanishes everywhere stays zero exactly (e.g. u_x, u_y of a 1D column).
    if (rhs_.isZero(0.0)) {
      u.setZero();
      continue;
    }
    for_cells([&](std::size_t m, std::ptrdiff_t c) { u[m] = u0[c]; });  // CG's first guess
    solve(op, component, dt, u);
    // Discrete dissipation: what the implicit step removes from the kinetic energy.
    for_cells([&](std::size_t m, std::ptrdiff_t c) {
      const double change = u[m] - u0[c];
      dissipation_[m] += 0.5 * n[c] * change * change / dt;
    });
    add_dissipation(op, component, u);
  }
  const double* T = w[4].data();
  for_cells([&](std::size_t m, std::ptrdiff_t c) {
    rhs_[m] = 1.5 * n[c] * T[c] / dt + dissipation_[m];
    temperature_[m] = T[c];  // CG's first guess
  });
  solve(op, 3, dt, temperature_);
  for_cells([&](std::size_t m, std::ptrdiff_t c) {
    store_primitive(U, c, Primitive{n[c], velocity_[0][m], velocity_[1][m], velocity_[2][m], temperature_[m]});
  });
}

// The decomposed box. Every vector lives in the storage of the rank's block, ghosts included:
// the matrix-free product reads the neighbours of the block's edge cells from the x and y
// ghosts the halo fills. The matrix and preconditioner are those of the Eigen path (the same
// faces, the same Jacobi plus plane-averaged column); sums over the box are taken plane by
// plane (each plane's sum independent of the threads), summed over the ranks, then over the
// planes in order.
namespace {
/// Calls plane(k) for every plane k, shared between threads on a large block (serial otherwise:
/// even an OpenMP region whose `if` is false costs a runtime call, and CG makes many).
template <class Plane> void for_planes(const Grid& g, Plane plane) {
  if (g.threaded()) {
#pragma omp parallel for schedule(static)
    for (int k = 0; k < g.nz; ++k) plane(k);
  } else {
    for (int k = 0; k < g.nz; ++k) plane(k);
  }
}

/// body(c, k) for every interior cell c of plane k.
template <class Body> void for_interior(const Grid& g, Body body) {
  for_planes(g, [&](int k) {
    for (int j = 0; j < g.ny; ++j) {
      const std::ptrdiff_t first = g.index(0, j, k);
      for (std::ptrdiff_t c = first; c < first + g.nx; ++c) body(c, k);
    }
  });
}

/// Per plane k, sums[k * count + s] = sum over the plane's interior cells c of term(c, k)[s],
/// s < count, in storage order (the accumulators stay in registers).
template <int count, class Term> void plane_sums(const Grid& g, std::vector<double>& sums, Term term) {
  sums.assign(static_cast<std::size_t>(g.nz) * count, 0.0);
  for_planes(g, [&](int k) {
    std::array<double, count> sum{};
    for (int j = 0; j < g.ny; ++j) {
      const std::ptrdiff_t first = g.index(0, j, k);
      for (std::ptrdiff_t c = first; c < first + g.nx; ++c) {
        const std::array<double, count> terms = term(c, k);
        for (int s = 0; s < count; ++s) sum[s] += terms[s];
      }
    }
    std::copy(sum.begin(), sum.end(), sums.begin() + static_cast<std::ptrdiff_t>(k) * count);
  });
}
}  // namespace

double ImplicitDiffusion::box_sum_of_products(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double>& sums = decomposed_.plane_sums;
  plane_sums<1>(grid_, sums, [&](std::ptrdiff_t c, int) { return std::array<double, 1>{a[c] * b[c]}; });
  halo_->sum(sums);
  double total = 0.0;
  for (const double s : sums) total += s;
  return total;
}

void ImplicitDiffusion::assemble_decomposed(const Operator& op, int component, double dt) {
  const Grid& g = grid_;
  Decomposed& d = decomposed_;
  const auto& cl = op.closure();
  const double* n = op.primitives()[0].data();
  const double inv_h2 = 1.0 / (g.h * g.h);
  const double mass_factor = component == 3 ? 1.5 : 1.0;
  const std::ptrdiff_t strides[3] = {g.stride(0), g.stride(1), g.stride(2)};
  const auto face = [&](std::ptrdiff_t c, int direction) {
    d.face[direction][c] = harmonic_mean(coefficient(cl, c, component, direction),
                                         coefficient(cl, c + strides[direction], component, direction)) * inv_h2;
  };
  // x and y faces from the low ghost on (the face into the block), z faces between planes:
  // the wall faces' entries stay 0.
  for_planes(g, [&](int k) {
    for (int j = -1; j < g.ny; ++j)
      for (int i = -1; i < g.nx; ++i) {
        const std::ptrdiff_t c = g.index(i, j, k);
        if (j >= 0) face(c, 0);
        if (i >= 0) face(c, 1);
        if (i >= 0 && j >= 0 && k + 1 < g.nz) face(c, 2);
      }
  });
  const auto wall = [&](std::ptrdiff_t c, int k) {
    return component == 2 && wall_plane(g, k) ? plane_wall_row(op, g, c, k, inv_h2).diagonal : 0.0;
  };
  for_interior(g, [&](std::ptrdiff_t c, int k) {
    double diagonal = mass_factor * n[c] / dt + wall(c, k);
    for (int direction = 0; direction < 3; ++direction)
      diagonal += d.face[direction][c] + d.face[direction][c - strides[direction]];
    d.diagonal[c] = diagonal;
    d.inverse_diagonal[c] = 1.0 / diagonal;
  });
  // The coarse system Ac = P^T A P: per plane the mass, wall and z-face terms (the horizontal
  // faces cancel) and the coupling to the plane below.
  std::vector<double>& sums = d.plane_sums;
  plane_sums<2>(g, sums, [&](std::ptrdiff_t c, int k) {
    const double below = d.face[2][c - strides[2]];
    return std::array<double, 2>{mass_factor * n[c] / dt + wall(c, k) + d.face[2][c] + below, -below};
  });
  halo_->sum(sums);
  const auto planes = static_cast<std::size_t>(g.nz);
  d.inverse_pivot.assign(planes, 1.0);
  d.upper.assign(planes, 0.0);
  d.coarse_lower.assign(planes, 0.0);
  for (std::size_t k = 0; k < planes; ++k) d.coarse_lower[k] = sums[2 * k + 1];
  for (std::size_t k = 0; k < planes; ++k) {
    const double pivot = sums[2 * k] - (k > 0 ? d.coarse_lower[k] * d.upper[k - 1] : 0.0);
    d.inverse_pivot[k] = 1.0 / pivot;
    d.upper[k] = (k + 1 < planes ? d.coarse_lower[k + 1] : 0.0) * d.inverse_pivot[k];
  }
}

void ImplicitDiffusion::apply_decomposed(const std::vector<double>& x, std::vector<double>& out) const {
  const Grid& g = grid_;
  const Decomposed& d = decomposed_;
  const std::ptrdiff_t sy = g.stride(1), sz = g.stride(2);
  const double* fx = d.face[0].data();
  const double* fy = d.face[1].data();
  const double* fz = d.face[2].data();
  for_interior(g, [&](std::ptrdiff_t c, int) {
    out[c] = d.diagonal[c] * x[c] - fx[c] * x[c + 1] - fx[c - 1] * x[c - 1] - fy[c] * x[c + sy] -
             fy[c - sy] * x[c - sy] - fz[c] * x[c + sz] - fz[c - sz] * x[c - sz];
  });
}

std::pair<double, double> ImplicitDiffusion::precondition_decomposed(const std::vector<double>& r,
                                                                     std::vector<double>& z) {
  const Grid& g = grid_;
  Decomposed& d = decomposed_;
  // Per plane: the sum of r (the coarse right-hand side), r.r and r.D^-1.r, in one reduction;
  // r.z = r.D^-1.r + sum_k coarse_k (plane sum of r)_k follows without a second one.
  std::vector<double>& sums = d.plane_sums;
  plane_sums<3>(g, sums, [&](std::ptrdiff_t c, int) {
    return std::array<double, 3>{r[c], r[c] * r[c], r[c] * r[c] * d.inverse_diagonal[c]};
  });
  halo_->sum(sums);
  const auto planes = static_cast<std::size_t>(g.nz);
  std::vector<double>& coarse = d.rhs_coarse;
  coarse.resize(planes);
  double rr = 0.0, rz = 0.0;
  for (std::size_t k = 0; k < planes; ++k) {
    coarse[k] = (sums[3 * k] - (k > 0 ? d.coarse_lower[k] * coarse[k - 1] : 0.0)) * d.inverse_pivot[k];
    rr += sums[3 * k + 1];
    rz += sums[3 * k + 2];
  }
  for (std::size_t k = planes - 1; k-- > 0;) coarse[k] -= d.upper[k] * coarse[k + 1];
  for (std::size_t k = 0; k < planes; ++k) rz += coarse[k] * sums[3 * k];
  for_interior(g, [&](std::ptrdiff_t c, int k) { z[c] = d.inverse_diagonal[c] * r[c] + coarse[static_cast<std::size_t>(k)]; });
  return {rr, rz};
}

// Preconditioned CG as Eigen's (the same recurrences and stopping rule, |r|^2 < tol^2 |b|^2),
// from the first guess in x.
void ImplicitDiffusion::solve_decomposed(std::vector<double>& x) {
  Decomposed& d = decomposed_;
  std::vector<double>& r = d.residual;
  std::vector<double>& z = d.preconditioned;
  std::vector<double>& p = d.search;
  std::vector<double>& q = d.product;
  const double rhs_norm2 = box_sum_of_products(d.rhs, d.rhs);
  if (rhs_norm2 == 0.0) {
    for_interior(grid_, [&](std::ptrdiff_t c, int) { x[c] = 0.0; });
    return;
  }
  constexpr double tolerance = 1e-13;
  const double threshold = std::max(tolerance * tolerance * rhs_norm2, std::numeric_limits<double>::min());
  halo_->exchange({x.data()});
  apply_decomposed(x, q);
  for_interior(grid_, [&](std::ptrdiff_t c, int) { r[c] = d.rhs[c] - q[c]; });
  auto [rr, rz] = precondition_decomposed(r, z);
  if (rr < threshold) return;
  for_interior(grid_, [&](std::ptrdiff_t c, int) { p[c] = z[c]; });
  const double most = 2.0 * static_cast<double>(halo_->box().interior_cells());  // Eigen's default
  for (double iteration = 0; iteration < most; ++iteration) {
    halo_->exchange({p.data()});
    apply_decomposed(p, q);
    const double alpha = rz / box_sum_of_products(p, q);
    for_interior(grid_, [&](std::ptrdiff_t c, int) {
      x[c] += alpha * p[c];
      r[c] -= alpha * q[c];
    });
    const double previous = rz;
    std::tie(rr, rz) = precondition_decomposed(r, z);
    if (rr < threshold) return;
    const double beta = rz / previous;
    for_interior(grid_, [&](std::ptrdiff_t c, int) { p[c] = z[c] + beta * p[c]; });
  }
  throw DomainError("implicit diffusion: CG did not converge");
}

void ImplicitDiffusion::add_dissipation_decomposed(const Operator& op, int component, std::vector<double>& u) {
  const Grid& g = grid_;
  Decomposed& d = decomposed_;
  const double inv_h2 = 1.0 / (g.h * g.h);
  const std::ptrdiff_t strides[3] = {g.stride(0), g.stride(1), g.stride(2)};
  halo_->exchange({u.data()});
  // Each cell takes half of every one of its faces' dissipation, from its own side.
  for_interior(g, [&](std::ptrdiff_t c, int k) {
    double sum = 0.0;
    for (int direction = 0; direction < 3; ++direction) {
      const std::ptrdiff_t s = strides[direction];
      const double up = u[c] - u[c + s], down = u[c] - u[c - s];
      sum += 0.5 * d.face[direction][c] * up * up + 0.5 * d.face[direction][c - s] * down * down;
    }
    if (component == 2 && wall_plane(g, k)) {
      const WallRow row = plane_wall_row(op, g, c, k, inv_h2);
      sum += (row.diagonal * u[c] - row.lagged) * u[c];
    }
    d.dissipation[c] += sum;
  });
}

void ImplicitDiffusion::advance_decomposed(Operator& op, State& U, double dt, bool closure_is_current) {
  if (!closure_is_current) op.prepare(U);
  const Grid& g = grid_;
  Decomposed& d = decomposed_;
  if (d.rhs.size() != g.size()) {
    for (auto* v : {&d.rhs, &d.dissipation, &d.residual, &d.preconditioned, &d.search, &d.product,
                    &d.diagonal, &d.inverse_diagonal})
      v->assign(g.size(), 0.0);
    for (auto& v : d.solution) v.assign(g.size(), 0.0);
    for (auto& v : d.face) v.assign(g.size(), 0.0);
  }
  const auto& w = op.primitives();
  const double* n = w[0].data();
  std::fill(d.dissipation.begin(), d.dissipation.end(), 0.0);
  for (int component = 0; component < 3; ++component) {
    const double* u0 = w[1 + component].data();
    std::vector<double>& u = d.solution[static_cast<std::size_t>(component)];
    const double inv_h2 = 1.0 / (g.h * g.h);
    for_interior(g, [&](std::ptrdiff_t c, int k) {
      d.rhs[c] = n[c] * u0[c] / dt;
      if (component == 2 && wall_plane(g, k)) d.rhs[c] += plane_wall_row(op, g, c, k, inv_h2).lagged;
      u[c] = u0[c];  // CG's first guess
    });
    // A component that vanishes everywhere stays zero exactly, on every rank alike.
    if (box_sum_of_products(d.rhs, d.rhs) == 0.0) {
      for_interior(g, [&](std::ptrdiff_t c, int) { u[c] = 0.0; });
      continue;
    }
    assemble_decomposed(op, component, dt);
    solve_decomposed(u);
    for_interior(g, [&](std::ptrdiff_t c, int) {
      const double change = u[c] - u0[c];
      d.dissipation[c] += 0.5 * n[c] * change * change / dt;
    });
    add_dissipation_decomposed(op, component, u);
  }
  const double* T = w[4].data();
  std::vector<double>& temperature = d.solution[3];
  for_interior(g, [&](std::ptrdiff_t c, int) {
    d.rhs[c] = 1.5 * n[c] * T[c] / dt + d.dissipation[c];
    temperature[c] = T[c];
  });
  assemble_decomposed(op, 3, dt);
  solve_decomposed(temperature);
  for_interior(g, [&](std::ptrdiff_t c, int) {
    store_primitive(U, c, Primitive{n[c], d.solution[0][c], d.solution[1][c], d.solution[2][c], temperature[c]});
  });
}

}  // namespace shaker::continuum
