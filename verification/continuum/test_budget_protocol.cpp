// Energy budget and the single-shock protocol through the run driver.
//  - The budget columns of the series (container frame): frame_energy(t) - frame_energy(0) =
//    accumulated_drive_work - accumulated_collisional_loss + accumulated_floor_energy. The terms
//    are accumulated with the Runge–Kutta stage weights, so the discrete budget closes to
//    round-off at every resolution: the residual must stay below 1e-10 of the energy that
//    flowed through the layer (work done plus energy lost), for the explicit and the split
//    implicit-diffusion schemes.
//  - single_shock: e switches at run.switch_phase before the recorded cycle (the restitution
//    column changes between the stored phases around it), the run file records the switched
//    e, and so does the checkpoint, which a restart takes over.
#include <cmath>

#include "common/run_file.hpp"
#include "continuum/checkpoint.hpp"
#include "continuum/run_continuum.hpp"
#include "continuum/setup.hpp"
#include "support.hpp"

namespace shaker::continuum::testing {
namespace {

struct BudgetCheck {
  double residual = 0, throughput = 0, floor = 0;
};

BudgetCheck budget_of_run(const std::filesystem::path& dir, double cell_size, const char* transport) {
  config::Config c;
  c.set("run.output=" + (dir / "run.h5").string());
  c.set("continuum.cell_size=" + std::to_string(cell_size));
  c.set(std::string("continuum.transport=") + transport);
  c.set("run.transient_cycles=0");
  c.set("run.sampled_cycles=1");
  c.set("run.phases_per_cycle=20");
  EXPECT_EQ(run(c), 0);
  const RunRecord r = read_run_file(dir / "run.h5");
  const auto& residual = r.series.column("energy_budget_residual");
  const auto& work = r.series.column("accumulated_drive_work");
  const auto& loss = r.series.column("accumulated_collisional_loss");
  const auto& floor = r.series.column("accumulated_floor_energy");
  BudgetCheck b;
  double work_variation = 0;
  for (std::size_t i = 0; i < residual.size(); ++i) {
    b.residual = std::max(b.residual, std::abs(residual[i]));
    if (i > 0) work_variation += std::abs(work[i] - work[i - 1]);
  }
  b.throughput = work_variation + (loss.back() - loss.front());
  b.floor = floor.back() - floor.front();
  std::printf("%s transport, h = %.3g: budget residual %.3e of throughput %.4g (floor energy "
              "%.3e, loss %.4g)\n", transport, cell_size, b.residual, b.throughput, b.floor,
              loss.back() - loss.front());
  return b;
}

TEST(EnergyBudget, ClosesToRoundOffExplicit) {
  const auto dir = test_directory();
  for (double h : {0.5, 0.25}) {
    const BudgetCheck b = budget_of_run(dir, h, "paper");
    EXPECT_GT(b.throughput, 1.0);  // the layer is driven: the check is not vacuous
    EXPECT_LT(b.residual, 1e-10 * b.throughput) << "h = " << h;
  }
}

TEST(EnergyBudget, ClosesToRoundOffWithImplicitDiffusion) {
  const BudgetCheck b = budget_of_run(test_directory(), 0.5, "full");
  EXPECT_GT(b.throughput, 1.0);
  EXPECT_LT(b.residual, 1e-10 * b.throughput);
}

TEST(SingleShock, SwitchesEAtThePhaseAndKeepsItInTheCheckpoint) {
  const auto dir = test_directory();
  config::Config c;
  c.set("run.output=" + (dir / "run.h5").string());
  c.set("continuum.cell_size=0.5");
  c.set("run.protocol=single_shock");
  c.set("run.transient_cycles=1");
  c.set("run.phases_per_cycle=50");
  c.set("run.switch_e=0.6");
  c.set("run.checkpoint=" + (dir / "checkpoint.h5").string());
  ASSERT_EQ(run(c), 0);
  const ContinuumCase cc = continuum_case(c);
  const double before = cc.parameters.restitution.e, after = cc.parameters.run.after_switch.e;
  ASSERT_NE(before, after);
  const double period = cc.parameters.shaker.period();
  const double switch_time = (1.0 + cc.parameters.run.switch_phase) * period;
  const RunRecord r = read_run_file(dir / "run.h5");
  EXPECT_EQ(r.e, after);
  const auto& time = r.series.column("t");
  const auto& e = r.series.column("restitution");
  // The last row before the switch and the first after it lie one stored phase apart.
  double last_before = -1, first_after = 1e300;
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < time.size(); ++i) {
    if (time[i] < switch_time) {
      wrong += e[i] != before;
      last_before = std::max(last_before, time[i]);
    } else {
      wrong += e[i] != after;
      first_after = std::min(first_after, time[i]);
    }
  }
  std::printf("switch at f t = %.4f: last row with e = %.2f at %.4f, first with e = %.2f at %.4f\n",
              switch_time / period, before, last_before / period, after, first_after / period);
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(first_after - last_before, 0.0);
  EXPECT_LE(first_after - last_before, period / 50 * (1 + 1e-12));
  // The checkpoint carries the switched e; a restart from it runs with that e.
  TimeIntegrator restarted = make_solver(cc);
  EXPECT_EQ(restarted.op().settings().e, before);
  read_checkpoint(dir / "checkpoint.h5", restarted);
  EXPECT_EQ(restarted.op().settings().e, after);
}

}  // namespace
}  // namespace shaker::continuum::testing
