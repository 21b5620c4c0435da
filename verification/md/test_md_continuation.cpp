// A run stopped by SIGTERM at any stored phase and continued from its checkpoint ends as the
// uninterrupted run does: the same final checkpoint, the same profiles and per-cycle sums in
// its run file, bit for bit, and the uninterrupted run's time-series rows after the restart
// point. The stops are deterministic (support/continuation.hpp).
#include <string>
#include <vector>

#include "common/config.hpp"
#include "md/run_md.hpp"
#include "md_test_support.hpp"
#include "support/continuation.hpp"

namespace shaker::md {
namespace {

constexpr int phases = 10, transient = 2, sampled = 3;

/// Time-series columns counted from the start of each run (README, "Continuing").
bool run_relative(const std::string& column) {
  for (const char* name : {"energy_budget_residual", "energy_budget_relative_residual", "collisions"})
    if (column == name) return true;
  return column.rfind("crossings_z", 0) == 0 || column.rfind("particles_z", 0) == 0;
}

shaker::testing::Continuation small_case(const std::filesystem::path& dir, const std::vector<std::string>& settings,
                                         std::int64_t cycles) {
  auto c = shaker::testing::continuation_of(
      [](const config::Config& config, const ProgressSettings& progress) { return run(config, {}, progress); }, dir,
      {phases, transient, sampled},
      {"layer.particles=200", "md.box_width=6.0", "md.ceiling=60.0", "md.crossing_heights=[12.5]"}, settings, cycles,
      run_relative);
  c.same_run_file = true;
  return c;
}

TEST(MdContinuation, StoppedAtAnyStoredPhaseEndsAsTheStraightRun) {
  const auto dir = testing::test_directory();
  // In the transient, at the first sampled phase, mid-way through sampled cycles, and at the
  // last two phases of the run (whose checkpoint continues to the run's end).
  shaker::testing::expect_continuations_exact(dir, small_case(dir, {}, transient + sampled),
                                              {{1, 4}, {2, 0}, {2, 7}, {3, 3}, {4, 8}, {4, 9}});
}

TEST(MdContinuation, SingleShockStoppedAfterItsSwitchEndsAsTheStraightRun) {
  const auto dir = testing::test_directory();
  // The switch at f t = -0.33 of the recorded cycle 2: stops before it, just after it, and in
  // the recorded cycle.
  shaker::testing::expect_continuations_exact(
      dir, small_case(dir, {"run.protocol=single_shock", "run.switch_e=0.8"}, transient + 1),
      {{1, 5}, {1, 7}, {2, 4}});
}

}  // namespace
}  // namespace shaker::md
