#include "common/run_loop.hpp"

#include <cmath>

namespace shaker {

PhaseSchedule::PhaseSchedule(const RunProtocol& run, const ShakerKinematics& shaker, Clock clock,
                             double origin)
    : clock_(clock),
      f_(shaker.f),
      period_(shaker.period()),
      origin_(origin),
      transient_(run.transient_cycles),
      sampled_(run.kind == RunProtocol::Kind::single_shock ? 1 : run.sampled_cycles),
      phases_(run.phases_per_cycle),
      after_switch_(run.after_switch) {}

PhaseSchedule PhaseSchedule::whole_cycles(const RunProtocol& run, const ShakerKinematics& shaker,
                                          double t0) {
  // The tolerance keeps a run continued from a whole cycle (t0 f = m up to round-off) at m.
  PhaseSchedule s(run, shaker, Clock::by_frequency, std::ceil(t0 * shaker.f - 1e-9));
  if (run.kind == RunProtocol::Kind::single_shock)
    s.switch_time_ = (s.origin_ + static_cast<double>(run.transient_cycles) + run.switch_phase) / shaker.f;
  return s;
}

PhaseSchedule PhaseSchedule::from_start(const RunProtocol& run, const ShakerKinematics& shaker,
                                        double t0) {
  PhaseSchedule s(run, shaker, Clock::by_period, t0 / shaker.period());
  if (run.kind == RunProtocol::Kind::single_shock)
    s.switch_time_ = t0 + (static_cast<double>(run.transient_cycles) + run.switch_phase) * shaker.period();
  return s;
}

double PhaseSchedule::time_of(double cycle_count) const {
  return clock_ == Clock::by_frequency ? cycle_count / f_ : cycle_count * period_;
}

double PhaseSchedule::target(std::int64_t m, std::int64_t k) const {
  return time_of(origin_ + static_cast<double>(m) + static_cast<double>(k) / static_cast<double>(phases_));
}

double PhaseSchedule::end() const { return time_of(origin_ + static_cast<double>(cycles())); }

void PhaseSchedule::run(DrivenSolver& solver, const std::vector<RunObserver*>& observers) const {
  bool switched = !switch_time_;
  for (std::int64_t m = 0; m < cycles(); ++m) {
    PhaseInstant instant{m, cycles(), 0, phases_, 0.0, m >= transient_};
    for (std::int64_t k = 0; k < phases_; ++k) {
      instant.phase = k;
      instant.t = target(m, k);
      if (!switched && *switch_time_ <= instant.t) {
        solver.advance_to(*switch_time_);
        solver.switch_restitution(after_switch_);
        switched = true;
      }
      solver.advance_to(instant.t);
      for (RunObserver* observer : observers) observer->at_phase(instant);
    }
    const CycleEnd cycle_end{m, cycles(), instant.t, instant.sampled};
    for (RunObserver* observer : observers) observer->at_cycle_end(cycle_end);
  }
  solver.advance_to(end());
  for (RunObserver* observer : observers) observer->at_run_end(end());
}

}  // namespace shaker
