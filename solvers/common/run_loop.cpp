#include "common/run_loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "common/errors.hpp"

namespace shaker {

bool PhaseInstant::selected(const std::vector<std::int64_t>& chosen_phases,
                            const std::vector<std::int64_t>& chosen_cycles) const {
  const bool in_cycle = chosen_cycles.empty() ? last_cycle()
                                              : std::binary_search(chosen_cycles.begin(), chosen_cycles.end(), cycle);
  return in_cycle && std::binary_search(chosen_phases.begin(), chosen_phases.end(), phase);
}

PhaseSchedule::PhaseSchedule(const RunProtocol& run, const ShakerKinematics& shaker, Clock clock,
                             double start_time, double origin)
    : clock_(clock),
      f_(shaker.frequency()),
      period_(shaker.period()),
      start_time_(start_time),
      origin_(origin),
      transient_(run.transient_cycles),
      sampled_(run.kind == RunProtocol::Kind::single_shock ? 1 : run.sampled_cycles),
      phases_(run.phases_per_cycle),
      protocol_(run) {}

PhaseSchedule PhaseSchedule::whole_cycles(const RunProtocol& run, const ShakerKinematics& shaker,
                                          double t0) {
  // The tolerance keeps a run continued from a whole cycle (t0 f = m up to round-off) at m.
  PhaseSchedule s(run, shaker, Clock::by_frequency, t0, std::ceil(t0 * shaker.frequency() - 1e-9));
  if (run.kind == RunProtocol::Kind::single_shock) s.switch_time_ = s.switch_time_of(run);
  return s;
}

PhaseSchedule PhaseSchedule::from_start(const RunProtocol& run, const ShakerKinematics& shaker,
                                        double t0) {
  PhaseSchedule s(run, shaker, Clock::by_period, t0, t0 / shaker.period());
  if (run.kind == RunProtocol::Kind::single_shock) s.switch_time_ = s.switch_time_of(run);
  return s;
}

double PhaseSchedule::time_of(double cycle_count) const {
  return clock_ == Clock::by_frequency ? cycle_count / f_ : cycle_count * period_;
}

double PhaseSchedule::switch_time_of(const RunProtocol& run) const {
  const double cycles = static_cast<double>(run.transient_cycles) + run.switch_phase;
  return clock_ == Clock::by_frequency ? time_of(origin_ + cycles) : start_time_ + cycles * period_;
}

namespace {

std::string switch_text(const RunProtocol& run, std::optional<double> at) {
  if (!at) return "no switch (run.protocol = \"periodic\")";
  return fmt::format("a switch to {} e = {} at t = {:.10g} (run.transient_cycles = {}, run.switch_phase = {})",
                     to_string(run.after_switch.kind), run.after_switch.e, *at, run.transient_cycles,
                     run.switch_phase);
}

}  // namespace

void PhaseSchedule::check_switch(const RunProtocol& written_by, double time, const std::string& source) const {
  const std::optional<double> before =
      written_by.kind == RunProtocol::Kind::single_shock ? std::optional(switch_time_of(written_by)) : std::nullopt;
  const bool switched = before && *before <= time, will_have_switched = switch_time_ && *switch_time_ <= time;
  if (!switched && !will_have_switched) return;
  if (switched && will_have_switched && *before == *switch_time_ && written_by.after_switch.e == protocol_.after_switch.e &&
      written_by.after_switch.kind == protocol_.after_switch.kind)
    return;
  throw InputError(fmt::format(
      "{} was written at t = {:.10g} by a run with {}{}; this run has {}{}: continued from it, the single "
      "shock would be neither run; allowed: {}", source, time, switch_text(written_by, before),
      switched ? ", after it" : "", switch_text(protocol_, switch_time_), will_have_switched ? ", before the checkpoint" : "",
      switched ? fmt::format("the checkpoint's run.protocol = \"single_shock\", run.transient_cycles = {}, run.switch_phase = {}, "
                             "run.switch_restitution = \"{}\" and run.switch_e = {}", written_by.transient_cycles,
                             written_by.switch_phase, to_string(written_by.after_switch.kind), written_by.after_switch.e)
               : fmt::format("a switch after t = {:.10g} (run.transient_cycles + run.switch_phase > {:.6g})", time,
                             time / time_of(1.0) - origin_)));
}

double PhaseSchedule::target(std::int64_t m, std::int64_t k) const {
  return time_of(origin_ + static_cast<double>(m) + static_cast<double>(k) / static_cast<double>(phases_));
}

double PhaseSchedule::end() const { return time_of(origin_ + static_cast<double>(cycles())); }

SchedulePosition PhaseSchedule::position(std::int64_t m, std::int64_t k) const {
  return SchedulePosition{start_time_, m, k, phases_};
}

void PhaseSchedule::resume_at(const SchedulePosition& p, double time, const std::string& source) {
  if (p.phase != 0 && p.phases != phases_)
    throw InputError(fmt::format(
        "run.phases_per_cycle = {} but {} stopped at stored phase {} of {} in cycle {}: a run "
        "continued mid-cycle keeps the checkpoint's phases; allowed: run.phases_per_cycle = {}",
        phases_, source, p.phase, p.phases, p.cycle, p.phases));
  const std::int64_t first = p.cycle * phases_ + p.phase;
  // A stop at the last stored phase leaves the way to the run's end.
  if (first > cycles() * phases_ || (first == cycles() * phases_ && !(time < end())))
    throw InputError(fmt::format(
        "{} was written at cycle {} (phase {} of {}) of its run, and run.transient_cycles + "
        "run.sampled_cycles = {} leaves nothing to run: a continued run counts its cycles from "
        "the checkpoint run's start; allowed: run.transient_cycles + run.sampled_cycles >= {}",
        source, p.cycle, p.phase, p.phases, cycles(), p.cycle + 1));
  const double next = target(first / phases_, first % phases_);
  if (!(time <= next))
    throw InputError(fmt::format("{} is not a valid checkpoint: its time t = {} lies after the "
                                 "stored phase it continues at (cycle {}, phase {}: t = {})",
                                 source, time, p.cycle, p.phase, next));
  // The checkpoint was written at the stored phase before (in its own phases), or at the start:
  // a time or schedule_start_time that puts it earlier would run for ever towards `next`.
  const double previous = p.cycle == 0 && p.phase == 0
                              ? start_time_
                              : time_of(origin_ + static_cast<double>(p.cycle) +
                                        static_cast<double>(p.phase - 1) / static_cast<double>(p.phases));
  if (!(time >= previous - 1e-9 * time_of(1.0)))
    throw InputError(fmt::format("{} is not a valid checkpoint: its time t = {} lies before the stored "
                                 "phase it was written at (t = {}, from schedule_start_time = {}, "
                                 "cycle {}, phase {} of {}); allowed: {} <= t <= {}", source, time,
                                 previous, start_time_, p.cycle, p.phase, p.phases, previous, next));
  first_ = first;
}

bool PhaseSchedule::switched_before_start() const {
  if (!switch_time_ || first_ == 0) return false;
  return *switch_time_ <= target((first_ - 1) / phases_, (first_ - 1) % phases_);
}

void PhaseSchedule::run(DrivenSolver& solver, const std::vector<RunObserver*>& observers,
                        StopBetweenPhases* stop) const {
  const std::function<bool()> asked = [stop] { return stop != nullptr && stop->asked(); };
  const auto advance = [&](double t, std::int64_t m, std::int64_t k) {
    if (!solver.advance_to(t, asked)) stop->stop_between(position(m, k), solver.time());
  };
  bool switched = !switch_time_;
  if (switched_before_start()) {
    solver.switch_restitution(protocol_.after_switch);
    switched = true;
  }
  const SchedulePosition from = start();
  const double resumed_at =
      static_cast<double>(from.cycle) + static_cast<double>(from.phase) / static_cast<double>(phases_);
  for (std::int64_t i = first_; i < cycles() * phases_; ++i) {
    const std::int64_t m = i / phases_, k = i % phases_;
    const PhaseInstant instant{m, cycles(), k, phases_, target(m, k), m >= transient_, resumed_at};
    if (!switched && *switch_time_ <= instant.t) {
      advance(*switch_time_, m, k);
      solver.switch_restitution(protocol_.after_switch);
      switched = true;
    }
    advance(instant.t, m, k);
    for (RunObserver* observer : observers) observer->at_phase(instant);
    if (k + 1 < phases_) continue;
    const CycleEnd cycle_end{m, cycles(), instant.t, instant.sampled};
    for (RunObserver* observer : observers) observer->at_cycle_end(cycle_end);
  }
  advance(end(), cycles(), 0);
  for (RunObserver* observer : observers) observer->at_run_end(end());
}

}  // namespace shaker
