#pragma once
// Time integration: explicit strong-stability-preserving Runge–Kutta (SSP-RK(s,2) or SSP-RK3)
// with adaptive steps from the advective (CFL) and diffusive limits; or, for the stiff
// `full` transport, a Strang split in which the diffusive terms advance by the second-order
// Runge–Kutta–Legendre super-time-stepping scheme RKL2 (Meyer, Balsara & Aslam 2014) and the
// rest by SSP-RK with the advective step only.
//
// A third choice, `implicit`, replaces RKL2 by a backward-Euler step of the diffusive terms
// (implicit_diffusion.hpp): unconditionally stable, first order in time. `implicit_extrapolated`
// takes that step twice with half the step and once whole and keeps 2 x (two halves) - (whole):
// Richardson extrapolation, second order, still L-stable (its factor tends to 0 for stiff modes,
// though it is slightly negative there, so the floor may act) and conservative (a combination
// of conservative steps with weights summing to 1).
//
// Positivity: after every stage n must be positive and finite (otherwise the step is
// rejected and retried with half the step); T below temperature_floor is raised to the floor,
// and every such use is counted. A step that still fails after max_retries halvings stops the
// run with an error naming the time and the cell; the state stays the last good one.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "continuum/implicit_diffusion.hpp"
#include "continuum/operator.hpp"

namespace shaker::continuum {

enum class DiffusionIntegrator { explicit_rk, rkl2, implicit, implicit_extrapolated };

struct IntegratorSettings {
  int order = 2;                  ///< 2: SSP-RK(stages, 2), 3: SSP-RK3 (Shu–Osher)
  int stages = 2;                 ///< order 2 only: 2 is Heun; s stages allow s - 1 times the step
  double cfl = 0.4;               ///< Courant number of each forward-Euler stage
  double diffusion_number = 0.8;  ///< fraction of the forward-Euler diffusive limit
  double fixed_dt = 0.0;          ///< > 0: constant step (convergence tests), else adaptive
  double temperature_floor = 1e-12;
  int max_retries = 12;
  DiffusionIntegrator diffusion = DiffusionIntegrator::explicit_rk;
};

struct Counters {
  std::int64_t steps = 0, rejected_steps = 0, temperature_floor_uses = 0, diffusion_stages = 0;
};

/// Energy budget in the container frame, per unit plate area, accumulated over accepted steps
/// with the Runge–Kutta weights of the stages (so it is the scheme's own discrete budget):
///   E(t) - E(0) = body_work - collisional_loss + floor_energy   (to round-off),
/// E = sum of (1/2 n |u|^2 + 3/2 n T) in the container frame. Fluxes cancel between cells and
/// vanish at the walls; the body force (gravity + frame force) does body_work; the
/// temperature floor adds floor_energy. External (manufactured) sources are not counted.
struct EnergyBudget {
  double body_work = 0, collisional_loss = 0, floor_energy = 0;
};

/// Sum of the energy density over the interior cells, in storage order.
double interior_energy_sum(const Grid& g, const State& s);

/// A step that cannot be completed even with the smallest retried step.
class StepFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class TimeIntegrator {
 public:
  /// With a `halo`, `grid` is this rank's block (halo->local()) and the integrator one of the
  /// ranks that advance the decomposed box together: every decision (step size, rejection,
  /// failure) is taken alike on every rank. The energy budget, the temperature floor count
  /// and total_energy() are then this rank's shares (per unit plate area of the whole box),
  /// summed over the ranks by whoever reports them.
  TimeIntegrator(const Grid& grid, const PhysicsSettings& physics, const IntegratorSettings& settings,
                 std::shared_ptr<const Halo> halo = nullptr);

  Operator& op() { return op_; }
  const Operator& op() const { return op_; }
  State& state() { return U_; }
  const State& state() const { return U_; }
  double time() const { return t_; }
  void set_time(double t) { t_ = t; }
  const Counters& counters() const { return counters_; }
  Counters& counters() { return counters_; }
  const EnergyBudget& budget() const { return budget_; }
  EnergyBudget& budget() { return budget_; }
  /// Container-frame energy (kinetic + thermal) of the state per unit plate area.
  double total_energy() const;
  const IntegratorSettings& settings() const { return settings_; }

  /// One step, never beyond t_limit (lands on it exactly). Returns the step taken.
  double step(double t_limit);
  void advance_to(double t_end);

 private:
  double choose_step(double t_limit);
  bool try_step(double dt, std::string& failure);
  bool ssp_runge_kutta(double dt, Part part, std::string& failure);
  bool ssp_rk_second_order(double dt, Part part, std::string& failure);
  /// Step of the scheme over that of one forward-Euler stage at the same Courant number.
  double ssp_coefficient() const { return settings_.order == 2 ? settings_.stages - 1.0 : 1.0; }
  bool rkl2(double dt, std::string& failure);
  bool implicit_extrapolated(double dt, std::string& failure);
  /// Adds weight * dt times the source power of one stage to the pending budget.
  void book(double dt, double weight, const Operator::SourcePower& p);
  /// `added` (if given) receives the energy per unit plate area the temperature floor added;
  /// `scanned` (if given) is axpy_and_scan's result for s, which spares the scan.
  bool admissible(State& s, double t, std::string& failure, double* added = nullptr,
                  const bool* scanned = nullptr);
  /// admissible on this rank's cells; `failing_cell` (if given) receives a failing cell's place
  /// in the box's storage order.
  bool admissible_here(State& s, double t, std::string& failure, double* added, const bool* scanned,
                       std::int64_t* failing_cell = nullptr);
  void axpy(State& out, double a, const State& x, double b, const State& y, double c,
            const State& k) const;  ///< out = a x + b y + c k on interior cells
  /// axpy, and whether some cell of `out` needs admissible's closer look, in one pass.
  bool axpy_and_scan(State& out, double a, const State& x, double b, const State& y, double c,
                     const State& k) const;
  /// out = (a x + b y + c k) + d z + e m on interior cells: bit for bit the first axpy, then
  /// axpy(out, 1, out, d, z, e, m), in one pass.
  void axpy(State& out, double a, const State& x, double b, const State& y, double c, const State& k,
            double d, const State& z, double e, const State& m) const;

  Operator op_;
  ImplicitDiffusion implicit_;
  IntegratorSettings settings_;
  State U_, U0_, U1_, U2_, K_, K0_, start_;
  State Yjm2_, Yjm1_, Yj_;  ///< RKL2 stages (sized on first use)
  double t_ = 0.0;
  Counters counters_;
  EnergyBudget budget_, pending_;     ///< pending_: the step being tried
  Operator::SourcePower power0_;      ///< source power at the step's start state U0_
  bool closure_at_start_ = false;     ///< op_'s closure is that of the step's start state
};

}  // namespace shaker::continuum
