#include "continuum/time_integrator.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "continuum/halo.hpp"

namespace shaker::continuum {

TimeIntegrator::TimeIntegrator(const Grid& grid, const PhysicsSettings& physics,
                               const IntegratorSettings& settings, std::shared_ptr<const Halo> halo)
    : op_(grid, physics, halo), implicit_(grid, halo), settings_(settings) {
  for (State* s : {&U_, &U0_, &U1_, &U2_, &K_, &K0_, &start_}) s->resize(grid.size());
}

namespace {
/// Whether body(row) is true for some contiguous run of interior cells (a whole 1D column, or
/// one x row in 3D); body is called for every row, threaded on large grids.
template <class Body> bool any_interior_row(const Grid& g, Body body) {
  const int rows = g.interior_rows();
  bool any = false;
  if (g.threaded()) {
#pragma omp parallel for schedule(dynamic, 2 * g.ny) reduction(|| : any)
    for (int row = 0; row < rows; ++row) any = body(row) || any;
  } else {
    for (int row = 0; row < rows; ++row) any = body(row) || any;
  }
  return any;
}

/// Calls run(first, length, v) for every variable v of every contiguous run of interior cells.
template <class Run> void for_interior_runs(const Grid& g, Run run) {
  any_interior_row(g, [&](int row) {
    for (int v = 0; v < variable_count; ++v) run(g.row_start(row), g.row_length(), v);
    return false;
  });
}

/// Whether some cell of the row is outside the model's domain or below the temperature floor:
/// one branch-free scan (which vectorises); admissible_here looks closer only then.
bool row_suspect(const Grid& g, const State& s, int row, double floor) {
  const double* N = s.q[density].data();
  const double* Mx = s.q[momentum_x].data();
  const double* My = s.q[momentum_y].data();
  const double* Mz = s.q[momentum_z].data();
  const double* E = s.q[energy].data();
  const std::ptrdiff_t first = g.row_start(row);
  bool any = false;
  for (std::ptrdiff_t c = first; c < first + g.row_length(); ++c) {
    const double n = N[c];
    const double kinetic = 0.5 * (Mx[c] * Mx[c] + My[c] * My[c] + Mz[c] * Mz[c]) / n;
    // NaN and infinities fail the comparisons: a non-finite n, E or momentum makes the cell
    // suspect through n or through E - kinetic.
    const bool fine = n > 0.0 && volume_fraction(n) < nu_max && E[c] - kinetic >= 1.5 * n * floor &&
                      E[c] - kinetic < std::numeric_limits<double>::infinity();
    any = any || !fine;
  }
  return any;
}

/// out = a x + b y + c k for variable v on the run of `length` cells from `first`.
void combine_run(State& out, double a, const State& x, double b, const State& y, double c, const State& k,
                 std::ptrdiff_t first, int length, int v) {
  const double* X = x.q[v].data() + first;
  const double* Y = y.q[v].data() + first;
  const double* Kv = k.q[v].data() + first;
  double* O = out.q[v].data() + first;
  for (int i = 0; i < length; ++i) O[i] = a * X[i] + b * Y[i] + c * Kv[i];
}
}  // namespace

bool TimeIntegrator::axpy_and_scan(State& out, double a, const State& x, double b, const State& y,
                                   double c, const State& k) const {
  const Grid& g = op_.grid();
  return any_interior_row(g, [&](int row) {
    for (int v = 0; v < variable_count; ++v) combine_run(out, a, x, b, y, c, k, g.row_start(row), g.row_length(), v);
    return row_suspect(g, out, row, settings_.temperature_floor);
  });
}

void TimeIntegrator::axpy(State& out, double a, const State& x, double b, const State& y,
                          double c, const State& k) const {
  for_interior_runs(op_.grid(), [&](std::ptrdiff_t first, int length, int v) {
    combine_run(out, a, x, b, y, c, k, first, length, v);
  });
}

void TimeIntegrator::axpy(State& out, double a, const State& x, double b, const State& y, double c,
                          const State& k, double d, const State& z, double e, const State& m) const {
  for_interior_runs(op_.grid(), [&](std::ptrdiff_t first, int length, int v) {
    const double* X = x.q[v].data() + first;
    const double* Y = y.q[v].data() + first;
    const double* Kv = k.q[v].data() + first;
    const double* Z = z.q[v].data() + first;
    const double* M = m.q[v].data() + first;
    double* O = out.q[v].data() + first;
    for (int i = 0; i < length; ++i) {
      const double first_three = a * X[i] + b * Y[i] + c * Kv[i];
      O[i] = first_three + d * Z[i] + e * M[i];
    }
  });
}

double interior_energy_sum(const Grid& g, const State& s) {
  double sum = 0.0;
  const double* E = s.q[energy].data();
  for (int row = 0; row < g.interior_rows(); ++row) {
    const std::ptrdiff_t first = g.row_start(row);
    for (std::ptrdiff_t c = first; c < first + g.row_length(); ++c) sum += E[c];
  }
  return sum;
}

double TimeIntegrator::total_energy() const {
  return interior_energy_sum(op_.grid(), U_) * op_.grid().h / op_.plate_columns();
}

bool TimeIntegrator::admissible(State& s, double t, std::string& failure, double* added, const bool* scanned) {
  const Halo* halo = op_.halo();
  if (!halo) return admissible_here(s, t, failure, added, scanned);
  const std::int64_t floors_before = counters_.temperature_floor_uses;
  std::int64_t failing_cell = 0;
  const bool here = admissible_here(s, t, failure, added, scanned, &failing_cell);
  // Every rank must take the same branch (retry or go on), and name the cell a plain run
  // names: the first failing one in the box's storage order.
  std::string first_failure = here ? std::string() : failure;
  if (halo->agree(first_failure, failing_cell)) return true;
  failure = first_failure;
  counters_.temperature_floor_uses = floors_before;  // a failed check counts no floors
  return false;
}

bool TimeIntegrator::admissible_here(State& s, double t, std::string& failure, double* added,
                                     const bool* scanned, std::int64_t* failing_cell) {
  const Grid& g = op_.grid();
  const double floor = settings_.temperature_floor;
  std::int64_t floors = 0;
  double raised = 0.0;
  double* N = s.q[density].data();
  double* Mx = s.q[momentum_x].data();
  double* My = s.q[momentum_y].data();
  double* Mz = s.q[momentum_z].data();
  double* E = s.q[energy].data();
  // Almost always every cell is admissible and above the floor: one scan establishes that
  // (unless the caller's axpy_and_scan did), and only otherwise the cell-by-cell pass below runs.
  const bool suspect = scanned ? *scanned : any_interior_row(g, [&](int row) { return row_suspect(g, s, row, floor); });
  if (!suspect) {
    if (added) *added = 0.0;
    return true;
  }
  // Storage order is (k, j, i) order: the first failing cell and the floor sums are those of
  // the triple loop.
  for (int row = 0; row < g.interior_rows(); ++row) {
    const std::ptrdiff_t first = g.row_start(row);
    for (std::ptrdiff_t c = first; c < first + g.row_length(); ++c) {
      const double n = N[c];
      const bool finite = std::isfinite(n) && std::isfinite(E[c]) && std::isfinite(Mx[c]) &&
                          std::isfinite(My[c]) && std::isfinite(Mz[c]);
      if (!finite || !(n > 0.0) || !(volume_fraction(n) < nu_max)) {
        const std::ptrdiff_t from_plane = c - g.index(0, 0, 0);
        const auto k = static_cast<int>(from_plane / g.stride_z());
        const auto j = static_cast<int>((c - g.index(0, 0, k)) / g.stride_y());
        const auto i = static_cast<int>(c - g.index(0, j, k));
        const Halo* halo = op_.halo();  // the cell's place in the whole box
        const int box_i = halo ? halo->block().i0 + i : i, box_j = halo ? halo->block().j0 + j : j;
        failure = fmt::format("t = {:.10g}, cell (i, j, k) = ({}, {}, {}) at z = {:.6g}: n = {:.6g}, "
                              "E = {:.6g} (need 0 < nu < nu_max and finite values)",
                              t, box_i, box_j, k, g.center(k), n, E[c]);
        if (failing_cell && halo)
          *failing_cell = (static_cast<std::int64_t>(k) * halo->box().ny + box_j) * halo->box().nx + box_i;
        return false;
      }
      const double kinetic = 0.5 * (Mx[c] * Mx[c] + My[c] * My[c] + Mz[c] * Mz[c]) / n;
      if (E[c] - kinetic < 1.5 * n * floor) {
        raised += kinetic + 1.5 * n * floor - E[c];
        E[c] = kinetic + 1.5 * n * floor;
        ++floors;
      }
    }
  }
  counters_.temperature_floor_uses += floors;
  if (added) *added = raised * g.h / op_.plate_columns();
  return true;
}

double TimeIntegrator::choose_step(double t_limit) {
  double dt = settings_.fixed_dt;
  if (dt <= 0.0) {
    dt = op_.advective_step(settings_.cfl * ssp_coefficient());
    if (settings_.diffusion == DiffusionIntegrator::explicit_rk)
      dt = std::min(dt, settings_.diffusion_number * ssp_coefficient() * op_.diffusive_step());
    dt = std::min(dt, settings_.diffusion_number * ssp_coefficient() * op_.artificial_step());
  }
  if (!(dt > 0.0) || !std::isfinite(dt)) dt = t_limit - t_;
  return std::min(dt, t_limit - t_);
}

bool TimeIntegrator::ssp_runge_kutta(double dt, Part part, std::string& failure) {
  if (settings_.order == 2) return ssp_rk_second_order(dt, part, failure);
  // U0_ holds the state at t_, K0_ its right-hand side (already evaluated, sources in power0_).
  // The budget weights are those of the stages in the final combination:
  // U = U0 + dt (K0 / 6 + K1 / 6 + 2 K2 / 3).
  double floor1 = 0, floor2 = 0, floor3 = 0;
  axpy(U1_, 1.0, U0_, 0.0, U0_, dt, K0_);
  if (!admissible(U1_, t_ + dt, failure, &floor1)) return false;
  op_.rhs(t_ + dt, U1_, K_, part);
  const Operator::SourcePower power1 = op_.source_power();
  axpy(U2_, 0.75, U0_, 0.25, U1_, 0.25 * dt, K_);
  if (!admissible(U2_, t_ + 0.5 * dt, failure, &floor2)) return false;
  op_.rhs(t_ + 0.5 * dt, U2_, K_, part);
  const Operator::SourcePower power2 = op_.source_power();
  axpy(U_, 1.0 / 3.0, U0_, 2.0 / 3.0, U2_, 2.0 / 3.0 * dt, K_);
  if (!admissible(U_, t_ + dt, failure, &floor3)) return false;
  book(dt, 1.0 / 6.0, power0_);
  book(dt, 1.0 / 6.0, power1);
  book(dt, 2.0 / 3.0, power2);
  pending_.floor_energy += floor1 / 6.0 + 2.0 / 3.0 * floor2 + floor3;
  return true;
}

// SSP-RK(s,2) (Ketcheson, SIAM J. Sci. Comput. 30, 2113 (2008)): s - 1 forward-Euler stages of
// dt / (s - 1), then U = U0 / s + (s - 1) / s (Y_{s-1} + dt / (s - 1) L(Y_{s-1})). It is SSP with
// coefficient s - 1, so with s stages the step may be s - 1 Euler steps; s = 2 is Heun's method.
// Each stage's right-hand side enters U with weight 1 / s (the budget weights); the floor
// energy added to an intermediate stage reaches U with weight (s - 1) / s.
bool TimeIntegrator::ssp_rk_second_order(double dt, Part part, std::string& failure) {
  const int s = settings_.stages;
  const double h = dt / (s - 1);
  const double carried = (s - 1.0) / s;
  State* previous = &U0_;
  const State* slope = &K0_;
  double floors = 0.0;
  book(dt, 1.0 / s, power0_);  // pending_ is discarded if the step fails
  for (int stage = 1; stage < s; ++stage) {
    State& Y = stage % 2 == 1 ? U1_ : U2_;
    double floor = 0.0;
    const bool suspect = axpy_and_scan(Y, 1.0, *previous, 0.0, *previous, h, *slope);
    if (!admissible(Y, t_ + stage * h, failure, &floor, &suspect)) return false;
    floors += carried * floor;
    op_.rhs(t_ + stage * h, Y, K_, part);
    book(dt, 1.0 / s, op_.source_power());
    previous = &Y;
    slope = &K_;
  }
  double floor_end = 0.0;
  const bool suspect = axpy_and_scan(U_, 1.0 / s, U0_, carried, *previous, carried * h, K_);
  if (!admissible(U_, t_ + dt, failure, &floor_end, &suspect)) return false;
  pending_.floor_energy += floors + floor_end;
  return true;
}

void TimeIntegrator::book(double dt, double weight, const Operator::SourcePower& p) {
  pending_.body_work += weight * dt * p.body;
  pending_.collisional_loss += weight * dt * p.loss;
}

// Backward Euler over dt, Richardson-extrapolated, from U_ into U_ (the SSP stage U1_ is free
// during the split diffusion step). The whole step and the first half step both start from
// U_; advance() only reads the operator's closure, so both reuse it when it is U_'s.
bool TimeIntegrator::implicit_extrapolated(double dt, std::string& failure) {
  State& whole = U1_;
  whole.q = U_.q;
  if (!closure_at_start_) op_.prepare(U_, true);
  implicit_.advance(op_, whole, dt, true);
  implicit_.advance(op_, U_, 0.5 * dt, true);
  if (!admissible(U_, t_, failure)) return false;
  implicit_.advance(op_, U_, 0.5 * dt);
  axpy(U_, 2.0, U_, -1.0, whole, 0.0, whole);
  return admissible(U_, t_, failure);
}

// RKL2 over dt for the diffusive part, from U_ into U_ (U0_ keeps the step's start state).
bool TimeIntegrator::rkl2(double dt, std::string& failure) {
  // The stage recursion needs Y0, Y_{j-1}, Y_{j-2}, Y_j, M0 = L(Y0) and L(Y_{j-1}). The
  // SSP stages U1_, U2_, K_ are free during the split diffusion step; three more scratch
  // states are allocated once, on the first RKL2 step, not per step.
  for (State* stage : {&Yjm2_, &Yjm1_, &Yj_})
    if (stage->size() != U_.size()) stage->resize(U_.size());
  // Y0 is U_ itself, read until the last stage; the stages rotate through three scratch
  // states (Y_{j-2} is Y0 itself at j = 2), and the last is swapped into U_. No copies: only
  // interiors are written and read (no state's ghosts are read).
  const State& Y0 = U_;
  State& M0 = K_;
  State& L = U2_;
  op_.rhs(t_, Y0, M0, Part::diffusive);
  const double dt_fe = op_.diffusive_step();
  if (!std::isfinite(dt_fe)) return true;
  // Stability of s stages: dt <= dt_fe (s^2 + s - 2) / 4 (with the safety factor).
  const double needed = dt / (settings_.diffusion_number * dt_fe);
  int s = 2;
  while ((s * s + s - 2) / 4.0 < needed) ++s;
  counters_.diffusion_stages += s;
  auto b = [](int j) { return j <= 2 ? 1.0 / 3.0 : (j * j + j - 2.0) / (2.0 * j * (j + 1.0)); };
  const double w1 = 4.0 / (s * s + s - 2.0);
  State* scratch[3] = {&Yjm2_, &Yjm1_, &Yj_};
  const State* Yjm2 = &Y0;
  State* Yjm1 = scratch[0];
  axpy(*Yjm1, 1.0, Y0, 0.0, Y0, b(1) * w1 * dt, M0);
  if (!admissible(*Yjm1, t_, failure)) return false;
  for (int j = 2; j <= s; ++j) {
    const double mu = (2.0 * j - 1.0) / j * b(j) / b(j - 1);
    const double nu = -(j - 1.0) / j * b(j) / b(j - 2);
    const double mu_tilde = mu * w1;
    const double gamma_tilde = -(1.0 - b(j - 1)) * mu_tilde;
    op_.rhs(t_, *Yjm1, L, Part::diffusive);
    State* Yj = scratch[(j - 1) % 3];
    axpy(*Yj, mu, *Yjm1, nu, *Yjm2, mu_tilde * dt, L, 1.0 - mu - nu, Y0, gamma_tilde * dt, M0);
    if (!admissible(*Yj, t_, failure)) return false;
    Yjm2 = Yjm1;
    Yjm1 = Yj;
  }
  std::swap(U_.q, Yjm1->q);
  return true;
}

bool TimeIntegrator::try_step(double dt, std::string& failure) {
  pending_ = EnergyBudget{};
  try {
    if (settings_.diffusion == DiffusionIntegrator::explicit_rk)
      return ssp_runge_kutta(dt, Part::all, failure);
    // The diffusive terms conserve energy, so whatever the split step changes in the total
    // energy is what the floor added in its stages.
    const auto diffuse = [&](double tau) {
      const double before = total_energy();
      bool ok = true;
      if (settings_.diffusion == DiffusionIntegrator::rkl2) {
        ok = rkl2(tau, failure);
      } else if (settings_.diffusion == DiffusionIntegrator::implicit_extrapolated) {
        ok = implicit_extrapolated(tau, failure);
      } else {
        implicit_.advance(op_, U_, tau, closure_at_start_);
        ok = admissible(U_, t_, failure);
      }
      closure_at_start_ = false;
      pending_.floor_energy += total_energy() - before;
      return ok;
    };
    // U_ equals U0_ here (step() sets both, on every attempt).
    if (!diffuse(0.5 * dt)) return false;
    std::swap(U0_.q, U_.q);  // the SSP step reads U0_ and overwrites U_'s interior
    op_.rhs(t_, U0_, K0_, Part::hyperbolic_and_sources);
    power0_ = op_.source_power();
    if (!ssp_runge_kutta(dt, Part::hyperbolic_and_sources, failure)) return false;
    return diffuse(0.5 * dt);
  } catch (const std::domain_error& error) {
    failure = fmt::format("t = {:.10g}: {}", t_, error.what());
    return false;
  }
}

double TimeIntegrator::step(double t_limit) {
  U0_.q = U_.q;
  // The split scheme overwrites U0_ and K0_; the explicit one leaves them intact.
  const bool split = settings_.diffusion != DiffusionIntegrator::explicit_rk;
  try {
    if (split) {
      // The step needs only the closure here (the hyperbolic right-hand side is evaluated
      // after the first diffusive half step); with the transport coefficients, the implicit
      // half step reuses it.
      const bool implicit = settings_.diffusion == DiffusionIntegrator::implicit ||
                            settings_.diffusion == DiffusionIntegrator::implicit_extrapolated;
      op_.prepare(U0_, implicit);
      closure_at_start_ = implicit;
    } else {
      op_.rhs(t_, U0_, K0_, Part::all);
      power0_ = op_.source_power();
    }
  } catch (const std::domain_error& error) {
    throw StepFailure(fmt::format("continuum: the state at t = {:.10g} is outside the model's "
                                  "domain: {}", t_, error.what()));
  }
  double dt = choose_step(t_limit);
  if (split) start_.q = U0_.q;
  std::string failure;
  for (int attempt = 0; attempt <= settings_.max_retries; ++attempt) {
    if (try_step(dt, failure)) {
      t_ = (t_limit - t_ <= dt) ? t_limit : t_ + dt;
      ++counters_.steps;
      budget_.body_work += pending_.body_work;
      budget_.collisional_loss += pending_.collisional_loss;
      budget_.floor_energy += pending_.floor_energy;
      return dt;
    }
    ++counters_.rejected_steps;
    if (split) {
      U0_.q = start_.q;
      closure_at_start_ = false;
    }
    U_.q = U0_.q;
    dt *= 0.5;
  }
  throw StepFailure(fmt::format("continuum: step failed after {} retries (last step {:.3g}): {}",
                                settings_.max_retries, 2.0 * dt, failure));
}

void TimeIntegrator::advance_to(double t_end) {
  while (t_ < t_end) step(t_end);
}

}  // namespace shaker::continuum
