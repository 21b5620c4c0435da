#include "continuum/operator.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "common/errors.hpp"
#include "continuum/halo.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace shaker::continuum {

namespace {
/// The threads an OpenMP region of this process runs on (1 without OpenMP).
int threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}
}  // namespace

Operator::Operator(const Grid& grid, const PhysicsSettings& settings, std::shared_ptr<const Halo> halo)
    : grid_(grid), settings_(settings), halo_(std::move(halo)) {
  const std::size_t cells = grid_.size();
  for (auto& v : w_) v.assign(cells, 0.0);
  for (auto* v : {&closure_.p, &closure_.c, &closure_.chi, &closure_.mu, &closure_.lambda, &closure_.kappa, &closure_.loss})
    v->assign(cells, 0.0);
  pow_argument_.assign(cells, std::numeric_limits<double>::quiet_NaN());  // matches nothing
  pow_value_.assign(cells, 0.0);
}

void Operator::rhs(double t, const State& U, State& dUdt, Part part) {
  const Terms& terms = settings_.terms;
  const bool diffusive = part != Part::hyperbolic_and_sources &&
                         (terms.shear_viscosity || terms.bulk_viscosity || terms.conduction);
  evaluate_closure(U, diffusive);
  // A 3D box goes a slab of planes at a time, its fields and right-hand side staying in cache
  // from one sweep to the next (six passes over the box from memory otherwise): the slab's
  // right-hand side is zeroed, its inviscid fluxes added, then the viscous fluxes of the slab
  // before it. Every cell still receives its terms in the order of whole-box sweeps (inviscid
  // x, y, z low, z high, then viscous alike; a slab's top z face is swept with the next slab),
  // so the sums are the same bit for bit. Only the interior planes are zeroed: nothing writes
  // or reads the z ghosts of a right-hand side.
  const bool inviscid = part != Part::diffusive && terms.advection;
  // (A box shared by several threads goes whole: a parallel region per sweep and slab would
  // cost more than the cache saves.)
  const bool shared = grid_.threaded() && threads() > 1;
  const int nz = grid_.nz, slab = grid_.dimension == 3 && !shared ? slab_planes : nz;
  const std::ptrdiff_t plane = grid_.stride_z(), first = plane * Grid::ghosts;  // plane 0, x and y ghosts too
  for (int k0 = 0; k0 < nz + slab; k0 += slab) {
    if (k0 < nz) {
      const int k1 = std::min(k0 + slab, nz);
      // Threaded plane by plane (the fill would be the largest serial part of the evaluation).
#pragma omp parallel for schedule(static) if (grid_.threaded())
      for (int k = k0; k < k1; ++k)
        for (auto& v : dUdt.q) std::fill_n(v.begin() + first + k * plane, plane, 0.0);
      if (inviscid) add_inviscid_fluxes(dUdt, k0, k1);
    }
    if (diffusive && k0 > 0 && k0 - slab < nz) add_diffusive_fluxes(dUdt, k0 - slab, std::min(k0, nz));
  }
  if (part != Part::diffusive) {
    add_artificial_fluxes(dUdt);
    add_sources(t, U, dUdt);
  }
}

ArtificialForm effective_artificial_form(const PhysicsSettings& s) {
  if (!s.terms.artificial_dissipation) return ArtificialForm::none;
  if (s.artificial.form != ArtificialForm::automatic) return s.artificial.form;
  return s.transport == model::Transport::paper ? ArtificialForm::transport_coefficients : ArtificialForm::none;
}

double Operator::artificial_step() const {
  const int dims = grid_.dimension == 3 ? 3 : 1;
  const double D = halo_ ? halo_->max(artificial_diffusivity_) : artificial_diffusivity_;
  return D > 0.0 ? grid_.h * grid_.h / (2.0 * dims * D) : std::numeric_limits<double>::infinity();
}

double Operator::plate_columns() const {
  return halo_ ? halo_->plate_columns() : static_cast<double>(grid_.nx) * grid_.ny;
}

void Operator::evaluate_closure(const State& U, bool need_transport) {
  if (!halo_) {
    update_primitives_and_closure(U, need_transport);
    return copy_closure_to_ghosts();
  }
  // A rank that threw alone would leave the others waiting in the next exchange.
  std::string failure;
  try {
    update_primitives_and_closure(U, need_transport);
  } catch (const std::domain_error& error) {
    failure = error.what();
  }
  if (!halo_->agree(failure)) throw DomainError(failure);
  copy_closure_to_ghosts();
}

// Both step limits scan the interior as contiguous runs (a 1D column is one run), threaded
// only on large grids (an OpenMP region with a false `if` still costs a runtime call).
template <class CellValue>
static double interior_maximum(const Grid& g, CellValue value) {
  const int rows = g.interior_rows(), length = g.row_length();
  const auto run = [&](int row) {
    const std::ptrdiff_t first = g.row_start(row);
    double m = 0.0;
    for (std::ptrdiff_t c = first; c < first + length; ++c) m = std::max(m, value(c));
    return m;
  };
  double largest = 0.0;
  if (g.threaded()) {
#pragma omp parallel for schedule(static) reduction(max : largest)
    for (int row = 0; row < rows; ++row) largest = std::max(largest, run(row));
  } else {
    for (int row = 0; row < rows; ++row) largest = std::max(largest, run(row));
  }
  return largest;
}

double Operator::advective_step(double cfl) const {
  const Grid& g = grid_;
  const double* u[3] = {w_[1].data(), w_[2].data(), w_[3].data()};
  const double* c_sound = closure_.c.data();
  const int first = g.first_direction();
  double fastest = interior_maximum(g, [&](std::ptrdiff_t c) {
    double sum = 0.0;
    for (int d = first; d < 3; ++d) sum += std::abs(u[d][c]) + c_sound[c];
    return sum;
  });
  if (halo_) fastest = halo_->max(fastest);  // a maximum is exact: the step of the serial run
  return fastest > 0.0 ? cfl * g.h / fastest : std::numeric_limits<double>::infinity();
}

double Operator::diffusive_step() const {
  if (!transport_evaluated_) return std::numeric_limits<double>::infinity();
  const Grid& g = grid_;
  const double* n = w_[0].data();
  const double* mu = closure_.mu.data();
  const double* lambda = closure_.lambda.data();
  const double* kappa = closure_.kappa.data();
  const auto diffusivity = [&](std::ptrdiff_t c) {
    const double momentum = (lambda[c] + 4.0 / 3.0 * mu[c]);
    const double heat = kappa[c] / 1.5;
    return std::max(momentum, heat) / n[c];
  };
  double largest = interior_maximum(g, diffusivity);
  const int dims = g.dimension == 3 ? 3 : 1;
  if (settings_.wall_stress == WallStress::second_order && g.z_boundary == ZBoundary::walls) {
    // The wall row of u_z: diagonal c_1 + 7/2 c_w, off-diagonal c_1 + c_w / 2 (c_w <= 3/2 c_0,
    // viscous_flux.cpp), so its Gershgorin radius is at most (2 + 6) c against the interior's
    // 4 c per direction: the wall cells count with their diffusivity times 1 + 1 / dims.
    const double factor = 1.0 + 1.0 / dims;
    for (int k : {0, g.nz - 1})
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) largest = std::max(largest, factor * diffusivity(g.index(i, j, k)));
  }
  if (halo_) largest = halo_->max(largest);
  return largest > 0.0 ? g.h * g.h / (2.0 * dims * largest) : std::numeric_limits<double>::infinity();
}

Limiter limiter_from_string(const std::string& name) {
  if (name == "minmod") return Limiter::minmod;
  if (name == "mc") return Limiter::mc;
  if (name == "van_leer") return Limiter::van_leer;
  if (name == "none") return Limiter::none;
  if (name == "first_order") return Limiter::first_order;
  throw InputError(
      fmt::format("continuum.limiter = \"{}\": allowed values are minmod, mc, van_leer, none, first_order", name));
}

RiemannSolver riemann_from_string(const std::string& name) {
  if (name == "hllc") return RiemannSolver::hllc;
  if (name == "hll") return RiemannSolver::hll;
  throw InputError(fmt::format("continuum.riemann = \"{}\": allowed values are hllc, hll", name));
}

ArtificialForm artificial_form_from_string(const std::string& name) {
  if (name == "auto") return ArtificialForm::automatic;
  if (name == "none") return ArtificialForm::none;
  if (name == "transport_coefficients") return ArtificialForm::transport_coefficients;
  if (name == "second_difference") return ArtificialForm::second_difference;
  if (name == "von_neumann_richtmyer") return ArtificialForm::von_neumann_richtmyer;
  throw InputError(fmt::format("continuum.artificial_dissipation = \"{}\": allowed values are auto, none, "
                               "transport_coefficients, second_difference, von_neumann_richtmyer", name));
}

WallEnergy wall_energy_from_string(const std::string& key, const std::string& name) {
  if (name == "adiabatic") return WallEnergy::adiabatic;
  if (name == "inelastic") return WallEnergy::inelastic;
  throw InputError(fmt::format("{} = \"{}\": allowed values are adiabatic, inelastic", key, name));
}

}  // namespace shaker::continuum
