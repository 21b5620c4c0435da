#include "mms_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

namespace shaker::mms {

namespace {
using continuum::Grid;
using continuum::State;

/// Exact conservative variables (n, n u, E) at a point, in a Residual as the container that
/// cell_average already knows how to sum.
Residual conserved_at(const ManufacturedSolution& solution, double t,
                      const std::array<double, 3>& x) {
  const Fields<double> f = solution(t, x[0], x[1], x[2]);
  Residual r;
  r.mass = f.n;
  double kinetic = 0.0;
  for (int i = 0; i < 3; ++i) {
    r.momentum[i] = f.n * f.u[i];
    kinetic += 0.5 * f.n * f.u[i] * f.u[i];
  }
  r.energy = kinetic + 1.5 * f.n * f.T;
  return r;
}

std::array<double, 3> cell_width(const Grid& g) {
  return {g.dimension == 3 ? g.h : 0.0, g.dimension == 3 ? g.h : 0.0, g.h};
}

template <class Visit> void for_each_cell(const Grid& g, const Visit& visit) {
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const double x = g.dimension == 3 ? g.center(i) : 0.0;
        const double y = g.dimension == 3 ? g.center(j) : 0.0;
        visit(g.index(i, j, k), std::array<double, 3>{x, y, g.center(k)});
      }
}

void store_exact_averages(const ManufacturedSolution& solution, const Grid& g, double t,
                          State& U) {
  for_each_cell(g, [&](std::ptrdiff_t c, const std::array<double, 3>& centre) {
    const Residual a = cell_average(
        [&](const std::array<double, 3>& x) { return conserved_at(solution, t, x); }, centre,
        cell_width(g), solution.dimension);
    const auto s = static_cast<std::size_t>(c);
    U.q[continuum::density][s] = a.mass;
    for (int i = 0; i < 3; ++i) U.q[continuum::momentum_x + i][s] = a.momentum[i];
    U.q[continuum::energy][s] = a.energy;
  });
}

void append_primitives(const Grid& g, const State& U, std::array<std::vector<double>, 5>& out) {
  for_each_cell(g, [&](std::ptrdiff_t c, const std::array<double, 3>&) {
    const continuum::Primitive w = continuum::to_primitive(U, static_cast<std::size_t>(c));
    out[0].push_back(w.n);
    out[1].push_back(w.ux);
    out[2].push_back(w.uy);
    out[3].push_back(w.uz);
    out[4].push_back(w.T);
  });
}

Grid grid_for(const MmsCase& c, const ManufacturedSolution& solution) {
  Grid g;
  g.dimension = c.dimension;
  g.h = solution.Lz / c.cells_z;
  const bool periodic = c.boundary == continuum::ZBoundary::periodic;
  g.z_boundary = c.boundary;
  g.nz = periodic ? 2 * c.cells_z : c.cells_z;
  if (c.dimension == 3) {
    g.nx = static_cast<int>(std::lround(solution.Lx / g.h));
    g.ny = static_cast<int>(std::lround(solution.Ly / g.h));
    if (std::abs(g.nx * g.h - solution.Lx) > 1e-9 || std::abs(g.ny * g.h - solution.Ly) > 1e-9)
      throw std::invalid_argument("mms: the cell size must divide the horizontal periods");
  }
  return g;
}

void add_norms(convergence::ErrorTable& table, const std::string& study, int dimension, int level,
               double h, const std::array<std::vector<double>, 5>& a,
               const std::array<std::vector<double>, 5>& b) {
  for (int f = 0; f < 5; ++f) {
    if (dimension == 1 && (f == 1 || f == 2)) continue;  // identically zero in 1D
    table.add_norms(study, field_names[static_cast<std::size_t>(f)], level, h,
                    convergence::error_norms(a[static_cast<std::size_t>(f)],
                                             b[static_cast<std::size_t>(f)]));
  }
}
}  // namespace

CorrectedCentreSource::CorrectedCentreSource(const ManufacturedSolution& solution,
                                             const Physics& physics, const Terms& terms,
                                             const Grid& g)
    : solution_(solution), physics_(physics), terms_(terms), g_(g),
      px_(g.dimension == 3 ? g.nx + 2 : 1), py_(g.dimension == 3 ? g.ny + 2 : 1),
      centre_(static_cast<std::size_t>(px_ * py_ * (g.nz + 2))) {}

Residual CorrectedCentreSource::operator()(double t, const std::array<double, 3>& x) {
  if (!(t == t_)) fill(t);
  const bool box = g_.dimension == 3;
  const auto padded = [&](double coordinate) {
    return static_cast<int>(std::floor(coordinate / g_.h)) + 1;
  };
  const int i = box ? padded(x[0]) : 0, j = box ? padded(x[1]) : 0, k = padded(x[2]);
  const int directions = box ? 3 : 1;
  // (S_- - 2 S + S_+) / 24 per direction: h^2 / 24 times the second derivative.
  Residual average = scaled(at(i, j, k), 1.0 - directions / 12.0);
  const auto add = [&](int a, int b, int c) { accumulate(average, at(a, b, c), 1.0 / 24.0); };
  add(i, j, k - 1);
  add(i, j, k + 1);
  if (box) {
    add(i - 1, j, k);
    add(i + 1, j, k);
    add(i, j - 1, k);
    add(i, j + 1, k);
  }
  return average;
}

std::size_t CorrectedCentreSource::slot(int i, int j, int k) const {
  return static_cast<std::size_t>(i + px_ * (j + py_ * k));
}

const Residual& CorrectedCentreSource::at(int i, int j, int k) const {
  return centre_[slot(i, j, k)];
}

void CorrectedCentreSource::fill(double t) {
  const bool box = g_.dimension == 3;
  for (int k = 0; k < g_.nz + 2; ++k)
    for (int j = 0; j < py_; ++j)
      for (int i = 0; i < px_; ++i) {
        const double x = box ? (i - 0.5) * g_.h : 0.0, y = box ? (j - 0.5) * g_.h : 0.0;
        centre_[slot(i, j, k)] =
            conservative_source(solution_, physics_, terms_, t, {x, y, (k - 0.5) * g_.h});
      }
  t_ = t;
}

ManufacturedSolution solution_for(const MmsCase& c) {
  ManufacturedSolution s;
  s.dimension = c.dimension;
  s.wall_compatible = c.boundary == continuum::ZBoundary::walls;
  s.U0 = c.velocity_amplitude;
  s.density_mode = c.density_mode;
  s.wall_gradients = c.wall_gradients;
  s.Lz = 10.0;
  s.Lx = s.Ly = 5.0;  // a smaller 3D box: half the cells of a cube, same resolution
  return s;
}

Terms effective_terms(const MmsCase& c) {
  Terms t = c.terms;
  if (t.pressure) t.advection = true;  // the solver's pressure lives in its inviscid flux
  return t;
}

continuum::PhysicsSettings physics_for(const MmsCase& c) {
  const Terms t = effective_terms(c);
  continuum::PhysicsSettings p;
  p.e = c.e;
  p.transport = c.transport;
  p.limiter = continuum::Limiter::none;
  p.wall_stress = c.wall_stress;
  p.terms.advection = t.advection;
  p.terms.pressure = t.pressure;
  p.terms.shear_viscosity = t.shear_viscosity;
  p.terms.bulk_viscosity = t.bulk_viscosity;
  p.terms.conduction = t.conduction;
  p.terms.collisional_loss = t.collisional_loss;
  p.terms.gravity = t.gravity;
  p.terms.frame_force = t.frame_forcing;
  p.terms.artificial_dissipation = c.artificial_dissipation;
  return p;
}

MmsResult run_mms(const MmsCase& c) {
  if (!c.terms.time_derivative) throw std::invalid_argument("mms: a run needs dU/dt");
  const ManufacturedSolution solution = solution_for(c);
  const Grid g = grid_for(c, solution);
  const continuum::PhysicsSettings physics = physics_for(c);
  continuum::IntegratorSettings integration;
  integration.order = c.rk_order;
  integration.cfl = c.cfl;
  integration.fixed_dt = c.fixed_dt;
  integration.diffusion = c.diffusion;
  continuum::TimeIntegrator solver(g, physics, integration);

  const Physics source_physics{c.e, c.transport, physics.shaker};
  const Terms terms = effective_terms(c);
  const std::array<double, 3> width = cell_width(g);
  std::optional<CorrectedCentreSource> corrected;
  if (c.source_rule == SourceRule::corrected_centre)
    corrected.emplace(solution, source_physics, terms, g);
  solver.op().external_source = [&](double t, double x, double y, double z, double* out) {
    const Residual s =
        corrected ? (*corrected)(t, {x, y, z})
            : average_conservative_source(solution, source_physics, terms, t, {x, y, z}, width);
    out[continuum::density] += s.mass;
    for (int i = 0; i < 3; ++i) out[continuum::momentum_x + i] += s.momentum[i];
    out[continuum::energy] += s.energy;
  };

  store_exact_averages(solution, g, 0.0, solver.state());
  solver.advance_to(c.t_end);

  MmsResult result;
  result.h = g.h;
  result.steps = solver.counters().steps;
  append_primitives(g, solver.state(), result.numeric);
  State exact;
  exact.resize(g.size());
  store_exact_averages(solution, g, c.t_end, exact);
  append_primitives(g, exact, result.exact);
  return result;
}

double TermShares::share(std::size_t term, int equation) const {
  double total = 0.0;
  for (const auto& r : rms) total += r[static_cast<std::size_t>(equation)];
  return total > 0.0 ? rms[term][static_cast<std::size_t>(equation)] / total : 0.0;
}

TermShares term_shares(const MmsCase& c, int samples) {
  const ManufacturedSolution solution = solution_for(c);
  const Grid g = grid_for(c, solution);
  const Physics physics{c.e, c.transport, physics_for(c).shaker};
  const Terms whole = effective_terms(c);
  using Switch = bool Terms::*;
  const std::vector<std::pair<std::string, Switch>> switches{
      {"time_derivative", &Terms::time_derivative}, {"advection", &Terms::advection},
      {"pressure", &Terms::pressure},               {"bulk_viscosity", &Terms::bulk_viscosity},
      {"shear_viscosity", &Terms::shear_viscosity}, {"conduction", &Terms::conduction},
      {"collisional_loss", &Terms::collisional_loss}, {"gravity", &Terms::gravity},
      {"frame_forcing", &Terms::frame_forcing}};
  TermShares shares;
  std::vector<std::array<double, 5>> sum_of_squares;
  for (const auto& [name, on] : switches)
    if (whole.*on) {
      shares.terms.push_back(name);
      sum_of_squares.push_back({});
    }
  double largest = 0.0, largest_defect = 0.0;
  std::size_t points = 0;
  for (int sample = 0; sample < samples; ++sample) {
    const double t = samples > 1 ? c.t_end * sample / (samples - 1) : 0.0;
    for_each_cell(g, [&](std::ptrdiff_t, const std::array<double, 3>& x) {
      const auto all = components(conservative_source(solution, physics, whole, t, x));
      std::array<double, 5> sum{};
      std::size_t term = 0;
      for (const auto& [name, on] : switches) {
        if (!(whole.*on)) continue;
        Terms alone = Terms::none();
        alone.*on = true;
        const auto part = components(conservative_source(solution, physics, alone, t, x));
        for (std::size_t q = 0; q < 5; ++q) {
          sum_of_squares[term][q] += part[q] * part[q];
          sum[q] += part[q];
        }
        ++term;
      }
      for (std::size_t q = 0; q < 5; ++q) {
        largest = std::max(largest, std::abs(all[q]));
        largest_defect = std::max(largest_defect, std::abs(all[q] - sum[q]));
      }
      ++points;
    });
  }
  for (auto& squares : sum_of_squares) {
    std::array<double, 5> rms{};
    for (std::size_t q = 0; q < 5; ++q) rms[q] = std::sqrt(squares[q] / static_cast<double>(points));
    shares.rms.push_back(rms);
  }
  shares.largest_sum_defect = largest > 0.0 ? largest_defect / largest : 0.0;
  return shares;
}

std::string term_shares_csv(const std::string& study, const TermShares& shares) {
  std::string csv = "study,term,equation,rms,share\n";
  for (std::size_t t = 0; t < shares.terms.size(); ++t)
    for (int q = 0; q < 5; ++q)
      if (shares.rms[t][static_cast<std::size_t>(q)] > 0.0)
        csv += fmt::format("{},{},{},{:.17g},{:.17g}\n", study, shares.terms[t],
                           equation_names[static_cast<std::size_t>(q)],
                           shares.rms[t][static_cast<std::size_t>(q)], shares.share(t, q));
  return csv;
}

void spatial_study(const MmsCase& base, const std::vector<int>& cells_z, const std::string& study,
                   convergence::ErrorTable& table) {
  for (std::size_t level = 0; level < cells_z.size(); ++level) {
    MmsCase c = base;
    c.cells_z = cells_z[level];
    const MmsResult r = run_mms(c);
    std::printf("%s: h %.5f, %lld steps\n", study.c_str(), r.h, static_cast<long long>(r.steps));
    std::fflush(stdout);
    add_norms(table, study, c.dimension, static_cast<int>(level), r.h, r.numeric, r.exact);
  }
}

void temporal_study(const MmsCase& base, const std::vector<double>& dts, double reference_dt,
                    const std::string& study, convergence::ErrorTable& table) {
  MmsCase reference = base;
  reference.fixed_dt = reference_dt;
  const MmsResult ref = run_mms(reference);
  for (std::size_t level = 0; level < dts.size(); ++level) {
    MmsCase c = base;
    c.fixed_dt = dts[level];
    const MmsResult r = run_mms(c);
    add_norms(table, study, c.dimension, static_cast<int>(level), dts[level], r.numeric,
              ref.numeric);
  }
}

}  // namespace shaker::mms
