#pragma once
// The one run loop of every solver (docs/models.md, "Run protocols"): a phase schedule
// (transient cycles, then sampled cycles, each stopped at run.phases_per_cycle stored phases;
// for a single shock a change of restitution at run.switch_phase before the one recorded
// cycle) drives a solver through DrivenSolver, and observers, in the manner of DynamO's output
// plugins, record what each needs: profiles, time series, field snapshots, progress. The loop
// itself only moves the solver; observers only read it, so what is observed never changes
// the trajectory.
#include <cstdint>
#include <optional>
#include <vector>

#include "common/case_parameters.hpp"

namespace shaker {

/// What the loop needs of a solver.
class DrivenSolver {
 public:
  virtual double time() const = 0;
  /// Brings the solver to time t >= time().
  virtual void advance_to(double t) = 0;
  /// The single shock's change of restitution, from now on.
  virtual void switch_restitution(const Restitution& after) = 0;

 protected:
  ~DrivenSolver() = default;
};

/// A stored phase the solver has just reached.
struct PhaseInstant {
  std::int64_t cycle = 0, cycles = 0;  ///< this cycle, counted from 0, of `cycles` in the run
  std::int64_t phase = 0, phases = 0;  ///< stored phase k of K: k / K of a cycle past its start
  double t = 0.0;                      ///< the target time
  bool sampled = false;                ///< in a sampled cycle (a single shock's recorded cycle)
  bool last_cycle() const { return cycle + 1 == cycles; }
  /// Cycles of the run behind this instant, fractions included.
  double cycles_done() const {
    return static_cast<double>(cycle) + static_cast<double>(phase) / static_cast<double>(phases);
  }
};

/// A cycle whose stored phases have all been observed.
struct CycleEnd {
  std::int64_t cycle = 0, cycles = 0;  ///< as in PhaseInstant
  double t = 0.0;                      ///< the time of its last stored phase
  bool sampled = false;
};

/// Sees the run at its stored phases; every hook has an empty default.
class RunObserver {
 public:
  virtual ~RunObserver() = default;
  virtual void at_phase(const PhaseInstant&) {}
  /// After at_phase of a cycle's last stored phase: per-cycle work, progress, and where
  /// periodic checkpoints belong.
  virtual void at_cycle_end(const CycleEnd&) {}
  /// The solver has reached the end of the last cycle, t.
  virtual void at_run_end(double) {}
};

class PhaseSchedule {
 public:
  /// The MD's schedule: the run starts at the first whole cycle at or after t0 (so every run,
  /// continued or not, keeps the phase f t of its stored phases), and times are cycles / f.
  static PhaseSchedule whole_cycles(const RunProtocol& run, const ShakerKinematics& shaker, double t0);
  /// The continuum's: cycles are counted from t0 itself, and times are
  /// (t0 / period + cycles) x period: absolute cycle counts, so that a restarted run meets the
  /// same target times as a straight one.
  static PhaseSchedule from_start(const RunProtocol& run, const ShakerKinematics& shaker, double t0);

  std::int64_t cycles() const { return transient_ + sampled_; }
  std::int64_t transient_cycles() const { return transient_; }
  std::int64_t phases() const { return phases_; }
  /// The time of stored phase k of cycle m (from 0).
  double target(std::int64_t m, std::int64_t k) const;
  /// The end of the last cycle.
  double end() const;

  /// Takes the solver through every stored phase of every cycle and on to end(), calling each
  /// observer, in the order given, at each phase, at each cycle end and at the end.
  void run(DrivenSolver& solver, const std::vector<RunObserver*>& observers) const;

 private:
  // The two solvers turn cycle counts into times with different roundings (x / f against
  // x * period); each keeps its own, so their trajectories stay what they were.
  enum class Clock { by_frequency, by_period };
  PhaseSchedule(const RunProtocol& run, const ShakerKinematics& shaker, Clock clock, double origin);
  double time_of(double cycle_count) const;

  Clock clock_;
  double f_, period_;
  double origin_;  ///< the cycle count of the run's start
  std::int64_t transient_, sampled_, phases_;
  std::optional<double> switch_time_;  ///< single shock only
  Restitution after_switch_;
};

}  // namespace shaker
