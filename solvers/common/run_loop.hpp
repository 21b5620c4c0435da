#pragma once
// The one run loop of every solver (docs/models.md, "Run protocols"): a phase schedule
// (transient cycles, then sampled cycles, each stopped at run.phases_per_cycle stored phases;
// for a single shock a change of restitution at run.switch_phase before the one recorded
// cycle) drives a solver through DrivenSolver, and observers, in the manner of DynamO's output
// plugins, record what each needs: profiles, time series, field snapshots, progress. The loop
// itself only moves the solver; observers only read it, so what is observed never changes
// the trajectory.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/case_parameters.hpp"

namespace shaker {

/// What the loop needs of a solver.
class DrivenSolver {
 public:
  virtual double time() const = 0;
  /// Brings the solver to time t >= time().
  virtual void advance_to(double t) = 0;
  /// Brings the solver towards time t >= time(), looking at `stop` before each of its steps:
  /// false if it stopped short of t (at a step's end) because `stop` said so. A solver whose
  /// steps cannot end between stored phases takes them all (the default).
  virtual bool advance_to(double t, const std::function<bool()>& stop) {
    (void)stop;
    advance_to(t);
    return true;
  }
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
  /// cycles_done() where this process took the run up: 0, or a continued run's checkpoint.
  double resumed_at = 0.0;
  bool last_cycle() const { return cycle + 1 == cycles; }
  /// Whether this is one of `chosen_phases` in one of `chosen_cycles` (both increasing, as
  /// stored_phase_indices and cycle_indices give them); no cycles: the last cycle.
  bool selected(const std::vector<std::int64_t>& chosen_phases, const std::vector<std::int64_t>& chosen_cycles) const;
  /// Cycles of the run behind this instant, fractions included.
  double cycles_done() const {
    return static_cast<double>(cycle) + static_cast<double>(phase) / static_cast<double>(phases);
  }
};

/// Where a run stands in its schedule, as every checkpoint records it: the time the run first
/// started (from which its schedule was built) and the next stored phase to reach, phase
/// `phase` of `phases` in cycle `cycle` (from 0). A run continued from it rebuilds the same
/// schedule, so it meets the target times of the run that wrote it, mid-cycle included.
struct SchedulePosition {
  double start_time = 0.0;
  std::int64_t cycle = 0, phase = 0, phases = 1;
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

/// Stops a run between stored phases (PhaseSchedule::run): asked() is looked at before every
/// step of the solver; once it is true the run stops there and stop_between() is called with
/// the stored phase the run would have reached next and the solver's time.
class StopBetweenPhases {
 public:
  virtual bool asked() = 0;
  /// Never returns (it ends the run, e.g. with StopRequested after a checkpoint).
  [[noreturn]] virtual void stop_between(const SchedulePosition& next, double t) = 0;

 protected:
  ~StopBetweenPhases() = default;
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

  /// Continues the run a checkpoint at `position`, of time `time`, belongs to; the schedule
  /// must have been built from position.start_time. InputError (naming `source`, the key that
  /// gave the checkpoint) if no stored phase of this schedule is left after the position,
  /// or if the position lies mid-cycle and run.phases_per_cycle differs from the checkpoint's.
  void resume_at(const SchedulePosition& position, double time, const std::string& source);
  /// InputError (naming `source`) unless this run meets the single shock's switch as the run
  /// that wrote the checkpoint at `time` (protocol `written_by`; its schedule started at the
  /// same time) did: both switched before the checkpoint, at the same time to the same
  /// restitution, or neither did. Otherwise the continued run would be neither run.
  void check_switch(const RunProtocol& written_by, double time, const std::string& source) const;
  /// The position of stored phase k of cycle m; (cycles(), 0) is the end of the run.
  SchedulePosition position(std::int64_t m, std::int64_t k) const;
  /// Where run() starts: (0, 0), or where resume_at put it.
  SchedulePosition start() const { return position(first_ / phases_, first_ % phases_); }

  /// Takes the solver through every stored phase of every cycle and on to end(), calling each
  /// observer, in the order given, at each phase, at each cycle end and at the end.
  /// With `stop`, the run may also end between stored phases, at a step of the solver.
  void run(DrivenSolver& solver, const std::vector<RunObserver*>& observers,
           StopBetweenPhases* stop = nullptr) const;

 private:
  // The two solvers turn cycle counts into times with different roundings (x / f against
  // x * period); each keeps its own, so their trajectories stay what they were.
  enum class Clock { by_frequency, by_period };
  PhaseSchedule(const RunProtocol& run, const ShakerKinematics& shaker, Clock clock, double start_time,
                double origin);
  double time_of(double cycle_count) const;
  /// The time of `run`'s switch on this schedule's clock (a single shock's).
  double switch_time_of(const RunProtocol& run) const;
  /// A continued run past the single shock's switch.
  bool switched_before_start() const;

  Clock clock_;
  double f_, period_;
  double start_time_;  ///< the time the run first started from
  double origin_;      ///< the cycle count of the run's start
  std::int64_t first_ = 0;  ///< m * phases + k of the first stored phase run() reaches
  std::int64_t transient_, sampled_, phases_;
  std::optional<double> switch_time_;  ///< single shock only
  RunProtocol protocol_;
};

}  // namespace shaker
