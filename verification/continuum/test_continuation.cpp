// A continuum run stopped by SIGTERM at any stored phase and continued from its checkpoint ends
// in the uninterrupted run's final checkpoint, bit for bit, with its time-series rows after the
// restart point; a single shock also when stopped after its switch. The stops are deterministic
// (support/continuation.hpp).
#include <string>
#include <vector>

#include "common/config.hpp"
#include "continuum/run_continuum.hpp"
#include "support/continuation.hpp"
#include "support/test_directory.hpp"

namespace shaker::continuum {
namespace {

constexpr int phases = 10, transient = 2, sampled = 2;

/// Time-series columns counted from the start of each run or compared with rows before it.
bool run_relative(const std::string& column) {
  return column == "com_z_change_from_previous_cycle" || column == "energy_budget_residual" ||
         column == "energy_budget_relative_residual" ||
         column == "periodicity_last_two_cycles";
}

shaker::testing::Continuation column(const std::filesystem::path& dir, const std::vector<std::string>& settings,
                                     std::int64_t cycles) {
  return shaker::testing::continuation_of(
      [](const config::Config& config, const ProgressSettings& progress) { return run(config, {}, progress); }, dir,
      {phases, transient, sampled}, {"continuum.cell_size=0.5"}, settings, cycles, run_relative);
}

TEST(Continuation, StoppedAtAnyStoredPhaseEndsAsTheStraightRun) {
  const auto dir = shaker::testing::test_directory();
  shaker::testing::expect_continuations_exact(dir, column(dir, {}, transient + sampled),
                                              {{1, 4}, {2, 0}, {2, 7}, {3, 8}});
}

TEST(Continuation, SingleShockStoppedAfterItsSwitchEndsAsTheStraightRun) {
  const auto dir = shaker::testing::test_directory();
  // The switch at f t = -0.33 of the recorded cycle 2: stops before it, just after it, and in
  // the recorded cycle.
  shaker::testing::expect_continuations_exact(
      dir, column(dir, {"run.protocol=single_shock", "run.switch_e=0.8"}, transient + 1), {{1, 5}, {1, 7}, {2, 4}});
}

}  // namespace
}  // namespace shaker::continuum
