// The run loop of common/run_loop.hpp with a stand-in solver: the target times of both
// clocks to the bit, the order of advances, switch and observer calls, a run continued from a
// schedule position (mid-cycle too) against the straight run, the progress observer's lines
// (plain, live and quiet), and the checkpoint observer: the last two periodic checkpoints kept,
// and a real SIGTERM / SIGINT answered at the next stored phase.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/atomic_output.hpp"
#include "common/checkpoints.hpp"
#include "common/errors.hpp"
#include "common/progress.hpp"
#include "common/run_loop.hpp"
#include "common/signals.hpp"
#include "test_support.hpp"

namespace {

using shaker::CycleEnd;
using shaker::PhaseInstant;
using shaker::PhaseSchedule;
using shaker::RunProtocol;
using shaker::ShakerKinematics;

const ShakerKinematics shaker_base{3.0, 0.095};

RunProtocol protocol(std::int64_t transient, std::int64_t sampled, std::int64_t phases) {
  RunProtocol run;
  run.transient_cycles = transient;
  run.sampled_cycles = sampled;
  run.phases_per_cycle = phases;
  return run;
}

/// Writes down everything the loop asks of it, in order.
class LoggingSolver final : public shaker::DrivenSolver {
 public:
  explicit LoggingSolver(double t0) : t_(t0) {}
  double time() const override { return t_; }
  void advance_to(double t) override {
    EXPECT_GE(t, t_) << "the loop went back in time";
    t_ = t;
    log.push_back("advance " + std::to_string(t));
    times.push_back(t);
  }
  void switch_restitution(const shaker::Restitution& after) override {
    log.push_back("switch " + std::to_string(after.e));
  }
  std::vector<std::string> log;
  std::vector<double> times;  ///< of the advances, to the bit

 private:
  double t_;
};

class LoggingObserver final : public shaker::RunObserver {
 public:
  explicit LoggingObserver(std::vector<std::string>& log) : log_(log) {}
  void at_phase(const PhaseInstant& p) override {
    log_.push_back("phase " + std::to_string(p.cycle) + "/" + std::to_string(p.cycles) + " " +
                   std::to_string(p.phase) + "/" + std::to_string(p.phases) + (p.sampled ? " sampled" : ""));
    instants.push_back(p);
  }
  void at_cycle_end(const CycleEnd& e) override {
    log_.push_back("cycle end " + std::to_string(e.cycle) + (e.sampled ? " sampled" : ""));
  }
  void at_run_end(double t) override { log_.push_back("run end " + std::to_string(t)); }
  std::vector<PhaseInstant> instants;

 private:
  std::vector<std::string>& log_;
};

TEST(PhaseSchedule, WholeCyclesKeepTheMdArithmetic) {
  const RunProtocol run = protocol(2, 3, 7);
  const double f = shaker_base.frequency();
  const PhaseSchedule fresh = PhaseSchedule::whole_cycles(run, shaker_base, 0.0);
  ASSERT_EQ(fresh.cycles(), 5);
  for (std::int64_t m = 0; m < 5; ++m)
    for (std::int64_t k = 0; k < 7; ++k)
      EXPECT_EQ(fresh.target(m, k), (static_cast<double>(m) + static_cast<double>(k) / 7.0) / f);
  EXPECT_EQ(fresh.end(), 5.0 / f);
  // A run continued from mid-cycle starts at the next whole cycle; from a whole cycle (up to
  // round-off), at that cycle.
  EXPECT_EQ(PhaseSchedule::whole_cycles(run, shaker_base, 2.5 / f).target(0, 0), 3.0 / f);
  EXPECT_EQ(PhaseSchedule::whole_cycles(run, shaker_base, 4.0 / f).target(0, 0), 4.0 / f);
}

TEST(PhaseSchedule, FromStartKeepsTheContinuumArithmetic) {
  const RunProtocol run = protocol(1, 2, 5);
  const double period = shaker_base.period(), t0 = 1.2345;
  const PhaseSchedule s = PhaseSchedule::from_start(run, shaker_base, t0);
  for (std::int64_t m = 0; m < 3; ++m)
    for (std::int64_t k = 0; k < 5; ++k)
      EXPECT_EQ(s.target(m, k),
                (t0 / period + static_cast<double>(m) + static_cast<double>(k) / 5.0) * period);
  EXPECT_EQ(s.end(), (t0 / period + 3.0) * period);
}

TEST(PhaseSchedule, CallsObserversInOrderAtEveryPhaseCycleEndAndTheEnd) {
  const PhaseSchedule s = PhaseSchedule::whole_cycles(protocol(1, 1, 2), shaker_base, 0.0);
  LoggingSolver solver(0.0);
  std::vector<std::string> log;
  LoggingObserver first(log), second(log);
  s.run(solver, {&first, &second});
  const std::vector<std::string> expected = {
      "phase 0/2 0/2", "phase 0/2 0/2", "phase 0/2 1/2", "phase 0/2 1/2", "cycle end 0",
      "cycle end 0", "phase 1/2 0/2 sampled", "phase 1/2 0/2 sampled", "phase 1/2 1/2 sampled",
      "phase 1/2 1/2 sampled", "cycle end 1 sampled", "cycle end 1 sampled",
      "run end " + std::to_string(s.end()), "run end " + std::to_string(s.end())};
  EXPECT_EQ(log, expected);
  std::vector<std::string> advances;
  for (std::int64_t m = 0; m < 2; ++m)
    for (std::int64_t k = 0; k < 2; ++k) advances.push_back("advance " + std::to_string(s.target(m, k)));
  advances.push_back("advance " + std::to_string(s.end()));
  EXPECT_EQ(solver.log, advances);
  ASSERT_EQ(first.instants.size(), 4u);
  EXPECT_EQ(first.instants[3].t, s.target(1, 1));
  EXPECT_TRUE(first.instants[3].last_cycle());
  EXPECT_FALSE(first.instants[1].last_cycle());
  EXPECT_EQ(first.instants[3].cycles_done(), 1.5);
}

TEST(PhaseSchedule, SingleShockSwitchesOnceBeforeTheFirstPhaseAfterTheSwitch) {
  RunProtocol run = protocol(2, 10, 4);  // a single shock records one cycle whatever sampled_cycles says
  run.kind = RunProtocol::Kind::single_shock;
  run.switch_phase = -0.3;
  run.after_switch.e = 0.5;
  for (const bool whole : {true, false}) {
    const PhaseSchedule s = whole ? PhaseSchedule::whole_cycles(run, shaker_base, 0.0)
                                  : PhaseSchedule::from_start(run, shaker_base, 0.0);
    ASSERT_EQ(s.cycles(), 3);
    LoggingSolver solver(0.0);
    s.run(solver, {});
    const double switch_time = whole ? (0.0 + 2.0 - 0.3) / shaker_base.frequency() : 0.0 + (2.0 - 0.3) * shaker_base.period();
    // f t = 1.5 comes before the switch at f t = 1.7, and 1.75 after it.
    const std::vector<std::string> around = {"advance " + std::to_string(s.target(1, 2)),
                                             "advance " + std::to_string(switch_time),
                                             "switch " + std::to_string(0.5),
                                             "advance " + std::to_string(s.target(1, 3))};
    ASSERT_EQ(solver.log.size(), 3u * 4u + 1u + 2u);
    EXPECT_EQ(std::vector<std::string>(solver.log.begin() + 6, solver.log.begin() + 10), around);
  }
}

/// What a ProgressReport writes for a run of `cycles` cycles of `phases` phases.
std::string progress_text(const shaker::ProgressSettings& settings, bool live, std::int64_t cycles,
                          std::int64_t phases) {
  char* buffer = nullptr;
  std::size_t size = 0;
  std::FILE* stream = open_memstream(&buffer, &size);
  double work = 0.0;
  {
    shaker::ProgressReport report("shaker test", "widgets/s", [&] { return work; }, settings, stream, live);
    const PhaseSchedule s = PhaseSchedule::whole_cycles(protocol(1, cycles - 1, phases), shaker_base, 0.0);
    LoggingSolver solver(0.0);
    struct Work final : shaker::RunObserver {
      double& work;
      explicit Work(double& w) : work(w) {}
      void at_phase(const PhaseInstant&) override { work += 10.0; }
    } counter(work);
    s.run(solver, {&counter, &report});
  }
  std::fclose(stream);
  std::string text(buffer, size);
  std::free(buffer);
  return text;
}

TEST(ProgressReport, PlainLinesAtEveryPhaseWithIntervalZero) {
  const std::string text = progress_text({false, 0.0}, false, 3, 2);
  // Phase (0, 0) has nothing done; then (0, 1), (1, 0), (1, 1), (2, 0), (2, 1) and the end.
  const std::vector<std::string> cycles = {"1", "2", "2", "3", "3", "3"};
  std::size_t at = 0;
  for (const std::string& cycle : cycles) {
    const std::string line = "shaker test: cycle " + cycle + " of 3, t = ";
    const std::size_t found = text.find(line, at);
    ASSERT_NE(found, std::string::npos) << "no '" << line << "' after offset " << at << " in\n" << text;
    EXPECT_NE(text.find(" widgets/s, ", found), std::string::npos);
    at = found + line.size();
  }
  EXPECT_EQ(text.find("shaker test:", at), std::string::npos) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos);
  EXPECT_EQ(text.back(), '\n');
}

TEST(ProgressReport, QuietWritesNothingAndALongIntervalOnlyTheLiveLine) {
  EXPECT_EQ(progress_text({true, 0.0}, false, 3, 2), "");
  EXPECT_EQ(progress_text({true, 0.0}, true, 3, 2), "");
  EXPECT_EQ(progress_text({false, 3600.0}, false, 3, 2), "");
  // A terminal gets the live line at the end of the run, and a newline after it.
  const std::string live = progress_text({false, 3600.0}, true, 3, 2);
  EXPECT_EQ(live.rfind("\rshaker test: cycle 3 of 3, t = ", 0), 0u) << live;
  EXPECT_EQ(live.back(), '\n');
}

TEST(ProgressReport, IntervalOutsideItsRangeIsInputError) {
  EXPECT_NO_THROW((shaker::ProgressSettings{false, 0.0}.validate()));
  EXPECT_NO_THROW((shaker::ProgressSettings{false, 86400.0}.validate()));
  for (const double bad : {-1.0, 1e9, std::nan("")}) {
    try {
      shaker::ProgressSettings{false, bad}.validate();
      ADD_FAILURE() << bad << " accepted";
    } catch (const shaker::InputError& error) {
      EXPECT_NE(std::string(error.what()).find("--progress-interval"), std::string::npos);
      EXPECT_NE(std::string(error.what()).find("0 <= value <= 86400"), std::string::npos) << error.what();
    }
  }
}

TEST(ProgressReport, DurationsReadAsPeopleSayThem) {
  EXPECT_EQ(shaker::duration_text(0.42), "0.42 s");
  EXPECT_EQ(shaker::duration_text(42.0), "42 s");
  EXPECT_EQ(shaker::duration_text(750.0), "12.5 min");
  EXPECT_EQ(shaker::duration_text(3.2 * 3600.0), "3.2 h");
}

/// The schedule of `run` from `t0` by either clock.
PhaseSchedule schedule(bool whole, const RunProtocol& run, double t0) {
  return whole ? PhaseSchedule::whole_cycles(run, shaker_base, t0) : PhaseSchedule::from_start(run, shaker_base, t0);
}

/// The loop continued at `position` of a run of `run`, from a solver at `time`.
LoggingSolver continued_run(bool whole, const RunProtocol& run, const shaker::SchedulePosition& position,
                            double time) {
  PhaseSchedule continued = schedule(whole, run, position.start_time);
  continued.resume_at(position, time, "the test");
  LoggingSolver solver(time);
  continued.run(solver, {});
  return solver;
}

TEST(PhaseSchedule, ContinuedRunMeetsTheStraightRunsTargets) {
  const RunProtocol run = protocol(2, 3, 7);
  for (const bool whole : {true, false}) {
    const double t0 = whole ? 2.5 / shaker_base.frequency() : 1.2345;
    const PhaseSchedule straight = schedule(whole, run, t0);
    LoggingSolver all(t0);
    straight.run(all, {});
    // After stored phase 3 of cycle 1 (mid-cycle), after the last of cycle 1, and at cycle 4.
    for (const auto& [m, k] : {std::pair<std::int64_t, std::int64_t>{1, 4}, {2, 0}, {4, 0}}) {
      const auto done = static_cast<std::ptrdiff_t>(m * 7 + k);  // stored phases before
      const LoggingSolver rest = continued_run(whole, run, straight.position(m, k), all.times[done - 1]);
      const std::vector<double> expected(all.times.begin() + done, all.times.end());
      EXPECT_EQ(rest.times, expected) << (whole ? "whole_cycles" : "from_start") << " at " << m << ", " << k;
    }
  }
}

TEST(PhaseSchedule, ContinuedSingleShockSwitchesOnceWhereTheStraightRunDid) {
  RunProtocol run = protocol(2, 10, 4);
  run.kind = RunProtocol::Kind::single_shock;
  run.switch_phase = -0.3;
  run.after_switch.e = 0.5;
  for (const bool whole : {true, false}) {
    const PhaseSchedule straight = schedule(whole, run, 0.0);
    LoggingSolver all(0.0);
    straight.run(all, {});
    // The switch at f t = 1.7 lies between stored phases (1, 2) and (1, 3): a run continued
    // before (1, 3) switches where the straight run did, one continued after it at once.
    const LoggingSolver before = continued_run(whole, run, straight.position(1, 3), straight.target(1, 2));
    EXPECT_EQ(before.log, std::vector<std::string>(all.log.begin() + 7, all.log.end()));
    const LoggingSolver after = continued_run(whole, run, straight.position(2, 0), straight.target(1, 3));
    std::vector<std::string> expected{"switch " + std::to_string(0.5)};
    expected.insert(expected.end(), all.log.begin() + 10, all.log.end());
    EXPECT_EQ(after.log, expected);
  }
}

TEST(PhaseSchedule, ResumeRefusesNothingLeftOtherPhasesMidCycleAndAStateOutsideItsPhase) {
  const PhaseSchedule two = PhaseSchedule::whole_cycles(protocol(1, 1, 5), shaker_base, 0.0);
  const std::string source = "run.restart_from = \"c.h5\"";
  shaker::testing::expect_input_error([&] { PhaseSchedule(two).resume_at({0.0, 2, 0, 5}, two.end(), source); },
                                      {source + " was written at cycle 2", "run.transient_cycles + "
                                       "run.sampled_cycles >= 3"});
  shaker::testing::expect_input_error([&] { PhaseSchedule(two).resume_at({0.0, 1, 2, 4}, two.target(1, 0), source); },
                                      {"run.phases_per_cycle = 5", "stored phase 2 of 4",
                                       "allowed: run.phases_per_cycle = 4"});
  shaker::testing::expect_input_error(
      [&] { PhaseSchedule(two).resume_at({0.0, 1, 0, 5}, two.target(1, 0) * (1 + 1e-12), source); },
      {source + " is not a valid checkpoint", "lies after the stored phase"});
  // A time before the stored phase the checkpoint was written at (a schedule_start_time moved
  // ahead) would never reach the next one.
  shaker::testing::expect_input_error(
      [&] { PhaseSchedule(two).resume_at({0.0, 1, 0, 5}, two.target(0, 4) - 1e-3, source); },
      {source + " is not a valid checkpoint", "lies before the stored phase", "allowed"});
  shaker::testing::expect_input_error(
      [&] { PhaseSchedule(two).resume_at({0.0, 0, 0, 5}, -1.0, source); },
      {"lies before the stored phase"});
  // At a cycle boundary the phases per cycle may change.
  PhaseSchedule other_phases = two;
  other_phases.resume_at({0.0, 1, 0, 4}, two.target(0, 4), source);
  EXPECT_EQ(other_phases.start().cycle, 1);
  EXPECT_EQ(other_phases.start().phase, 0);
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Checkpoints of the stand-in solver: its time and the position, as text, counted.
shaker::CheckpointWriter text_writer(const LoggingSolver& solver, int& writes) {
  return [&solver, &writes](const std::filesystem::path& path, const shaker::SchedulePosition& p) {
    ++writes;
    shaker::write_text_atomically(path, fmt::format("{} {} {} {}\n", solver.time(), p.cycle, p.phase, p.phases));
  };
}

TEST(CheckpointObserver, PeriodicCheckpointsKeepTheLastTwo) {
  const shaker::testing::TemporaryDirectory dir;
  const PhaseSchedule s = PhaseSchedule::whole_cycles(protocol(1, 4, 3), shaker_base, 0.0);
  shaker::CheckpointSettings settings;
  settings.file = dir / "c.h5";
  settings.every = 2;
  settings.run_output = dir / "run.h5";
  LoggingSolver solver(0.0);
  int writes = 0;
  {
    shaker::CheckpointObserver checkpoints(settings, s, text_writer(solver, writes), "shaker test");
    s.run(solver, {&checkpoints});
  }
  EXPECT_EQ(writes, 3);  // after cycles 1 and 3 (from 0) and at the end
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"c.h5", "c.previous.h5"}));
  EXPECT_EQ(read_text(dir / "c.h5"), fmt::format("{} 5 0 3\n", s.end()));
  EXPECT_EQ(read_text(dir / "c.previous.h5"), fmt::format("{} 4 0 3\n", s.target(3, 2)));
}

/// Sends `signal` to this process at stored phase k of cycle m.
class RaiseAt final : public shaker::RunObserver {
 public:
  RaiseAt(int signal, std::int64_t m, std::int64_t k) : signal_(signal), m_(m), k_(k) {}
  void at_phase(const PhaseInstant& p) override {
    if (p.cycle == m_ && p.phase == k_) std::raise(signal_);
  }

 private:
  int signal_;
  std::int64_t m_, k_;
};

TEST(CheckpointObserver, StopSignalWritesACheckpointAtTheNextStoredPhaseAndStops) {
  shaker::install_signal_cleanup();
  const shaker::testing::TemporaryDirectory dir;
  const PhaseSchedule s = PhaseSchedule::whole_cycles(protocol(1, 2, 5), shaker_base, 0.0);
  shaker::CheckpointSettings settings;
  settings.run_output = dir / "run.h5";  // no run.checkpoint: the checkpoint goes beside it
  for (const auto& [signal, status] : {std::pair{SIGTERM, 143}, {SIGINT, 130}}) {
    LoggingSolver solver(0.0);
    int writes = 0;
    RaiseAt raiser(signal, 1, 2);
    shaker::CheckpointObserver checkpoints(settings, s, text_writer(solver, writes), "shaker test");
    try {
      s.run(solver, {&raiser, &checkpoints});
      ADD_FAILURE() << "the run went on after signal " << signal;
    } catch (const shaker::StopRequested& stop) {
      EXPECT_EQ(stop.exit_code(), status);
      EXPECT_NE(std::string(stop.what()).find("stopped by signal " + std::to_string(signal)), std::string::npos)
          << stop.what();
    }
    EXPECT_EQ(writes, 1);
    EXPECT_EQ(solver.time(), s.target(1, 2));
    EXPECT_EQ(read_text(dir / "run.checkpoint.h5"), fmt::format("{} 1 3 5\n", s.target(1, 2)));
  }
}

TEST(CheckpointObserver, StopSignalDuringTheFinalCheckpointStopsAfterIt) {
  shaker::install_signal_cleanup();
  const shaker::testing::TemporaryDirectory dir;
  const PhaseSchedule s = PhaseSchedule::whole_cycles(protocol(1, 1, 5), shaker_base, 0.0);
  shaker::CheckpointSettings settings;
  settings.run_output = dir / "run.h5";
  settings.file = dir / "c.h5";
  LoggingSolver solver(0.0);
  int writes = 0;
  const auto plain = text_writer(solver, writes);
  // The signal arrives while the final checkpoint is being written (the only one: no every).
  const shaker::CheckpointWriter signalling = [&](const std::filesystem::path& path,
                                                  const shaker::SchedulePosition& p) {
    std::raise(SIGTERM);
    plain(path, p);
  };
  shaker::CheckpointObserver checkpoints(settings, s, signalling, "shaker test");
  try {
    s.run(solver, {&checkpoints});
    ADD_FAILURE() << "the run ended with status 0 after a SIGTERM during its final checkpoint";
  } catch (const shaker::StopRequested& stop) {
    EXPECT_EQ(stop.exit_code(), 143);
    EXPECT_NE(std::string(stop.what()).find("while the final checkpoint was written"), std::string::npos)
        << stop.what();
  }
  EXPECT_EQ(writes, 1);
  EXPECT_EQ(read_text(dir / "c.h5"), fmt::format("{} 2 0 5\n", s.end()));
}

/// Sets a stand-in for another rank's signal at stored phase k of cycle m.
class PeerSignalAt final : public shaker::RunObserver {
 public:
  PeerSignalAt(int& peer, std::int64_t m, std::int64_t k) : peer_(peer), m_(m), k_(k) {}
  void at_phase(const PhaseInstant& p) override {
    if (p.cycle == m_ && p.phase == k_) peer_ = SIGTERM;
  }

 private:
  int& peer_;
  std::int64_t m_, k_;
};

TEST(CheckpointObserver, SignalOfAnotherRankStopsThisOneAtTheSamePhaseWithoutWritingHere) {
  const shaker::testing::TemporaryDirectory dir;
  const PhaseSchedule s = PhaseSchedule::whole_cycles(protocol(1, 2, 5), shaker_base, 0.0);
  shaker::CheckpointSettings settings;
  settings.run_output = dir / "run.h5";
  settings.file = dir / "c.h5";
  for (const bool writer : {false, true}) {
    LoggingSolver solver(0.0);
    int writes = 0, peer = 0, agreements = 0;
    PeerSignalAt other_rank(peer, 1, 2);
    const shaker::StopAcrossRanks ranks{[&](int mine) { ++agreements; return std::max(mine, peer); },
                                        writer};
    shaker::CheckpointObserver checkpoints(settings, s, text_writer(solver, writes), "shaker test",
                                           ranks);
    try {
      s.run(solver, {&other_rank, &checkpoints});
      ADD_FAILURE() << "the run went on after the other rank's signal";
    } catch (const shaker::StopRequested& stop) {
      EXPECT_EQ(stop.exit_code(), 143);
      // The writer's message is the run's; the other ranks stay silent.
      EXPECT_EQ(std::string(stop.what()).empty(), !writer) << stop.what();
    }
    EXPECT_EQ(agreements, 5 + 2 + 1);  // every stored phase up to the stop, the stop's included
    EXPECT_EQ(solver.time(), s.target(1, 2));
    EXPECT_EQ(writes, writer ? 1 : 0);
    EXPECT_EQ(std::filesystem::exists(dir / "c.h5"), writer);
  }
}

}  // namespace
