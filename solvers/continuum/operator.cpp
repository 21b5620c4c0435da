#include "continuum/operator.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/errors.hpp"

namespace shaker::continuum {

Operator::Operator(const Grid& grid, const PhysicsSettings& settings)
    : grid_(grid), settings_(settings) {
  const std::size_t cells = grid_.size();
  for (auto& v : w_) v.assign(cells, 0.0);
  for (auto* v : {&closure_.p, &closure_.c, &closure_.chi, &closure_.mu, &closure_.lambda, &closure_.kappa, &closure_.loss})
    v->assign(cells, 0.0);
}

void Operator::rhs(double t, State& U, State& dUdt, Part part) {
  fill_ghosts(U);
  const Terms& terms = settings_.terms;
  const bool diffusive = part != Part::hyperbolic_and_sources &&
                         (terms.shear_viscosity || terms.bulk_viscosity || terms.conduction);
  update_primitives_and_closure(U, diffusive);
  for (auto& v : dUdt.q) std::fill(v.begin(), v.end(), 0.0);
  if (part != Part::diffusive) {
    if (terms.advection) add_inviscid_fluxes(dUdt);
  }
  if (diffusive) add_diffusive_fluxes(dUdt);
  if (part != Part::diffusive) add_sources(t, U, dUdt);
}

double Operator::advective_step(double cfl) const {
  const Grid& g = grid_;
  double fastest = 0.0;
#pragma omp parallel for schedule(static) reduction(max : fastest) if (g.interior_cells() > 4096)
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::ptrdiff_t c = g.index(i, j, k);
        double sum = 0.0;
        for (int d = g.first_direction(); d < 3; ++d) sum += std::abs(w_[1 + d][c]) + closure_.c[c];
        fastest = std::max(fastest, sum);
      }
  return fastest > 0.0 ? cfl * g.h / fastest : std::numeric_limits<double>::infinity();
}

double Operator::diffusive_step() const {
  if (!transport_evaluated_) return std::numeric_limits<double>::infinity();
  const Grid& g = grid_;
  double largest = 0.0;
#pragma omp parallel for schedule(static) reduction(max : largest) if (g.interior_cells() > 4096)
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::ptrdiff_t c = g.index(i, j, k);
        const double momentum = (closure_.lambda[c] + 4.0 / 3.0 * closure_.mu[c]);
        const double heat = closure_.kappa[c] / 1.5;
        largest = std::max(largest, std::max(momentum, heat) / w_[0][c]);
      }
  const int dims = g.dimension == 3 ? 3 : 1;
  return largest > 0.0 ? g.h * g.h / (2.0 * dims * largest) : std::numeric_limits<double>::infinity();
}

Limiter limiter_from_string(const std::string& name) {
  if (name == "minmod") return Limiter::minmod;
  if (name == "mc") return Limiter::mc;
  if (name == "van_leer") return Limiter::van_leer;
  if (name == "none") return Limiter::none;
  throw InputError(fmt::format("continuum.limiter = \"{}\": allowed values are minmod, mc, van_leer, none", name));
}

RiemannSolver riemann_from_string(const std::string& name) {
  if (name == "hllc") return RiemannSolver::hllc;
  if (name == "hll") return RiemannSolver::hll;
  throw InputError(fmt::format("continuum.riemann = \"{}\": allowed values are hllc, hll", name));
}

}  // namespace shaker::continuum
