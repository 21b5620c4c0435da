// Whole-run checks: mass conservation (1D and 3D), a horizontally uniform 3D run equals the
// 1D run, restart continues identically, and the base-case smoke test (H = 9, e = 0.9, 1D).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <fstream>
#include <iterator>
#include <utility>
#include <vector>

#include "analysis/analysis.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "common/units.hpp"
#include "common/version.hpp"
#include "continuum/checkpoint.hpp"
#include "continuum/initial_state.hpp"
#include "continuum/output.hpp"
#include "continuum/run_continuum.hpp"
#include "continuum/setup.hpp"
#include "support.hpp"

namespace shaker::continuum::testing {
namespace {

config::Config base_config(const std::filesystem::path& dir) {
  config::Config c;
  c.set("run.output=" + (dir / "run.h5").string());
  return c;
}

double relative_mass_drift(config::Config config, double cycles) {
  const ContinuumCase c = continuum_case(config);
  TimeIntegrator solver = make_solver(c);
  const double m0 = total(c.grid, solver.state(), density);
  solver.advance_to(cycles * c.parameters.shaker.period());
  const double m1 = total(c.grid, solver.state(), density);
  std::printf("dimension %d: %lld steps, relative mass change %.3e\n", c.grid.dimension,
              static_cast<long long>(solver.counters().steps), (m1 - m0) / m0);
  return std::abs(m1 - m0) / m0;
}

TEST(MassConservation, OneDimensionalToRoundOff) {
  config::Config c = base_config(test_directory());
  c.set("continuum.cell_size=0.5");
  EXPECT_LT(relative_mass_drift(c, 1.0), 1e-13);
}

TEST(MassConservation, ThreeDimensionalToRoundOff) {
  config::Config c = base_config(test_directory());
  c.set("continuum.dimension=3");
  c.set("continuum.cell_size=0.5");
  c.set("continuum.box_width=2");
  c.set("continuum.ceiling=10");
  c.set("layer.particles=1000");  // a 2.6 high layer keeps the 3D test short
  c.set("continuum.perturbation=0.05");
  EXPECT_LT(relative_mass_drift(c, 0.3), 1e-13);
}

/// One horizontally uniform case as a column (cell 0.5, ceiling 20) and as a box of it
/// (2 x 2, or 2 x `depth`), both at the same fixed step; `c` ends as the box's configuration.
/// Explicit diffusion (the paper transport's), whose box is the column to the bit: the
/// implicit diffusion's solver sums in another order on another grid and agrees to 1e-12
/// (docs/parallel.md).
std::pair<ContinuumCase, ContinuumCase> column_and_box(config::Config& c, const std::string& depth = "0") {
  c.set("continuum.transport=paper");
  c.set("continuum.cell_size=0.5");
  c.set("continuum.ceiling=20");
  c.set("continuum.perturbation=0");
  ContinuumCase one = continuum_case(c);
  c.set("continuum.dimension=3");
  c.set("continuum.box_width=2");
  c.set("continuum.box_depth=" + depth);
  ContinuumCase three = continuum_case(c);
  one.integration.fixed_dt = three.integration.fixed_dt = 2e-4;
  return {one, three};
}

/// Runs the column and the box a tenth of a cycle; the largest relative difference of any box
/// cell from the column, and the largest |n u_x| and |n u_y| in the box.
std::pair<double, double> box_against_column(const ContinuumCase& one, const ContinuumCase& three) {
  TimeIntegrator a = make_solver(one), b = make_solver(three);
  const double t_end = 0.1 * one.parameters.shaker.period();
  a.advance_to(t_end);
  b.advance_to(t_end);
  double worst = 0.0, horizontal = 0.0;
  for (int k = 0; k < one.grid.nz; ++k)
    for (int j = 0; j < three.grid.ny; ++j)
      for (int i = 0; i < three.grid.nx; ++i) {
        for (int v : {density, momentum_z, energy}) {
          const double x = a.state().q[v][one.grid.index(0, 0, k)];
          const double y = b.state().q[v][three.grid.index(i, j, k)];
          worst = std::max(worst, std::abs(x - y) / std::max(1e-300, std::abs(x)));
        }
        for (int v : {momentum_x, momentum_y})
          horizontal = std::max(horizontal, std::abs(b.state().q[v][three.grid.index(i, j, k)]));
      }
  std::printf("%d x %d box: largest relative difference 3D - 1D: %.3e; largest horizontal momentum %.3e "
              "(%lld steps)\n", three.grid.nx, three.grid.ny, worst, horizontal,
              static_cast<long long>(a.counters().steps));
  return {worst, horizontal};
}

TEST(Uniform3D, MatchesOneDimensionalRunToRoundOff) {
  config::Config c = base_config(test_directory());
  const auto [one, three] = column_and_box(c);
  const auto [worst, horizontal] = box_against_column(one, three);
  EXPECT_EQ(worst, 0.0);
  EXPECT_EQ(horizontal, 0.0);
}

TEST(Uniform3D, RectangularBoxMatchesOneDimensionalRunToRoundOff) {
  // The box 2 wide and 3.5 deep (4 x 7 cells): a horizontally uniform state stays the
  // column's, cell by cell, whatever the box's shape.
  config::Config c = base_config(test_directory());
  const auto [one, three] = column_and_box(c, "3.5");
  ASSERT_EQ(three.grid.nx, 4);
  ASSERT_EQ(three.grid.ny, 7);
  const auto [worst, horizontal] = box_against_column(one, three);
  EXPECT_EQ(worst, 0.0);
  EXPECT_EQ(horizontal, 0.0);
}

TEST(Restart, ContinuesIdentically) {
  const auto dir = test_directory();
  config::Config c = base_config(dir);
  c.set("continuum.cell_size=0.5");
  const ContinuumCase cc = continuum_case(c);
  const double half = 0.5 * cc.parameters.shaker.period();
  TimeIntegrator straight = make_solver(cc);
  straight.advance_to(half);
  straight.advance_to(2 * half);
  TimeIntegrator first = make_solver(cc);
  first.advance_to(half);
  write_checkpoint(dir / "checkpoint.h5", first, SchedulePosition{}, c.to_toml());
  TimeIntegrator second = make_solver(cc);
  read_checkpoint(dir / "checkpoint.h5", second);
  second.advance_to(2 * half);
  std::size_t differing = 0;
  for (int v = 0; v < variable_count; ++v)
    for (int k = 0; k < cc.grid.nz; ++k) {
      const auto i = cc.grid.index(0, 0, k);
      differing += straight.state().q[v][i] != second.state().q[v][i];
    }
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(straight.counters().steps, second.counters().steps);
  EXPECT_EQ(straight.time(), second.time());
}

// A 1D column's checkpoint starts a 3D box: each column of the box takes the checkpoint's, the
// time, e, counters and the budget (per unit area) carry over, and at a common fixed step the
// box then stays the column continued, to the bit (as Uniform3D above).
TEST(Restart, ColumnCheckpointStartsTheBoxInTheColumnState) {
  const auto dir = test_directory();
  config::Config c = base_config(dir);
  const auto [one, three] = column_and_box(c);
  const double period = one.parameters.shaker.period();
  TimeIntegrator column = make_solver(one);
  column.advance_to(0.3 * period);
  write_checkpoint(dir / "column.h5", column, SchedulePosition{}, c.to_toml());
  TimeIntegrator box = make_solver(three);
  read_checkpoint(dir / "column.h5", box);
  EXPECT_EQ(box.time(), column.time());
  EXPECT_EQ(box.counters().steps, column.counters().steps);
  EXPECT_EQ(box.budget().collisional_loss, column.budget().collisional_loss);
  const auto worst_difference = [&] {
    double worst = 0.0;
    for (int v = 0; v < variable_count; ++v)
      for (int k = 0; k < three.grid.nz; ++k)
        for (int j = 0; j < three.grid.ny; ++j)
          for (int i = 0; i < three.grid.nx; ++i)
            worst = std::max(worst, std::abs(box.state().q[v][three.grid.index(i, j, k)] -
                                             column.state().q[v][one.grid.index(0, 0, k)]));
    return worst;
  };
  EXPECT_EQ(worst_difference(), 0.0);
  column.advance_to(0.4 * period);
  box.advance_to(0.4 * period);
  std::printf("box - column after 0.1 cycle from the column's checkpoint: %.3e (%lld steps)\n",
              worst_difference(), static_cast<long long>(box.counters().steps));
  EXPECT_EQ(worst_difference(), 0.0);
  // The box sums its cells in another order: the budget agrees to round-off.
  EXPECT_NEAR(box.budget().body_work, column.budget().body_work, 1e-13 * std::abs(column.budget().body_work));
}

// A column continues only a box of its own cell size and height; anything else is refused
// before the box is touched, naming the mismatch.
TEST(Restart, ColumnCheckpointOfAnotherGridIsRefused) {
  const auto dir = test_directory();
  config::Config c = base_config(dir);
  c.set("continuum.cell_size=0.5");
  c.set("continuum.ceiling=20");
  c.set("layer.particles=1000");  // a layer low enough for the box of ceiling 10
  TimeIntegrator column = make_solver(continuum_case(c));
  write_checkpoint(dir / "column.h5", column, SchedulePosition{}, c.to_toml());
  c.set("continuum.dimension=3");
  c.set("continuum.box_width=2");
  const auto message = [&](const std::vector<std::string>& settings) {
    config::Config box_config = c;
    for (const auto& setting : settings) box_config.set(setting);
    TimeIntegrator box = make_solver(continuum_case(box_config));
    try {
      read_checkpoint(dir / "column.h5", box);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const std::string taller = message({"continuum.ceiling=25"});
  EXPECT_NE(taller.find("nz = 40 cells, the 3D box nz = 50"), std::string::npos) << taller;
  EXPECT_NE(taller.find("run.restart_from"), std::string::npos) << taller;
  const std::string finer = message({"continuum.cell_size=0.25"});
  EXPECT_NE(finer.find("nz = 40 cells, the 3D box nz = 80"), std::string::npos) << finer;
  const std::string finer_same_cells = message({"continuum.cell_size=0.25", "continuum.ceiling=10"});
  EXPECT_NE(finer_same_cells.find("cell size 0.5, the configuration needs continuum.cell_size = 0.25"),
            std::string::npos) << finer_same_cells;
}

TEST(Restart, ThroughTheProgramGivesTheSameProfiles) {
  const auto dir = test_directory();
  config::Config c = base_config(dir);
  c.set("continuum.cell_size=0.5");
  c.set("run.phases_per_cycle=10");
  c.set("run.sampled_cycles=1");
  c.set("run.transient_cycles=1");
  c.set("run.output=" + (dir / "straight.h5").string());
  ASSERT_EQ(run(c), 0);
  // The first cycle alone, then the same two-cycle run continued from its checkpoint.
  c.set("run.transient_cycles=0");
  c.set("run.output=" + (dir / "first.h5").string());
  c.set("run.checkpoint=" + (dir / "checkpoint.h5").string());
  ASSERT_EQ(run(c), 0);
  c.set("run.transient_cycles=1");
  c.set("run.checkpoint=");
  c.set("run.restart_from=" + (dir / "checkpoint.h5").string());
  c.set("run.output=" + (dir / "second.h5").string());
  ASSERT_EQ(run(c), 0);
  const RunRecord a = read_run_file(dir / "straight.h5"), b = read_run_file(dir / "second.h5");
  ASSERT_EQ(a.profiles.size(), b.profiles.size());
  std::size_t differing = 0;
  for (std::size_t p = 0; p < a.profiles.size(); ++p)
    for (std::size_t i = 0; i < a.profiles[p].size(); ++i)
      differing += (a.profiles[p].n[i] != b.profiles[p].n[i]) + (a.profiles[p].T[i] != b.profiles[p].T[i]) +
                   (a.profiles[p].uz[i] != b.profiles[p].uz[i]);
  EXPECT_EQ(differing, 0u);
}

// The paper's base case in 1D: after the transient the state is periodic (centre of mass
// repeats from cycle to cycle) and a shock is found between f t = 0.1 and 0.4.
TEST(BaseCase, PeriodicStateAndShock) {
  const auto dir = test_directory();
  config::Config c = base_config(dir);
  c.set("continuum.cell_size=0.25");
  c.set("run.transient_cycles=10");
  c.set("run.sampled_cycles=2");
  ASSERT_EQ(run(c), 0);
  const RunRecord r = read_run_file(dir / "run.h5");
  const auto& change = r.series.column("com_z_change_from_previous_cycle");
  const auto& com = r.series.column("com_z");
  const std::size_t K = r.profiles.size();
  double d2 = 0, h2 = 0;
  for (std::size_t i = com.size() - K; i < com.size(); ++i) {
    d2 += change[i] * change[i];
    h2 += com[i] * com[i];
  }
  const double periodicity = std::sqrt(d2 / h2);
  int shocks = 0;
  for (const Profile& p : r.profiles) {
    const auto shock = analysis::find_shock(p);
    if (shock && p.phase >= 0.1 && p.phase <= 0.4) ++shocks;
    if (shock) std::printf("phase %.2f: shock at %.3f, width %.3f\n", p.phase, shock->location, shock->width);
  }
  std::printf("periodicity (fractional RMS change of the centre of mass, last two cycles) %.3e; "
              "phases with a shock in [0.1, 0.4]: %d\n", periodicity, shocks);
  EXPECT_LT(periodicity, 0.01);
  // The run stores the same number (last row of its periodicity column).
  EXPECT_NEAR(r.series.column("periodicity_last_two_cycles").back(), periodicity, 1e-12 * periodicity);
  EXPECT_GE(shocks, 3);
  const auto& mass = r.series.column("total_mass");
  EXPECT_LT(std::abs(mass.back() - mass.front()) / mass.front(), 1e-12);
  // Settled, and above the floor: nothing doubtful.
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
}

std::string text_of(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A short coarse column: 2 cycles from the initial state, far from its periodic state.
config::Config unsettled(const std::filesystem::path& dir) {
  config::Config c = base_config(dir);
  c.set("continuum.cell_size=0.5");
  c.set("run.transient_cycles=0");
  c.set("run.sampled_cycles=2");
  c.set("run.phases_per_cycle=10");
  return c;
}

TEST(RunLog, KeepsTheConfigurationTheSummaryAndTheWarnings) {
  const auto dir = test_directory();
  ASSERT_EQ(run(unsettled(dir)), 0);
  const RunRecord r = read_run_file(dir / "run.h5");
  const double periodicity = r.series.column("periodicity_last_two_cycles").back();
  std::printf("periodicity after 2 cycles from the initial state: %.3g\n", periodicity);
  ASSERT_GT(periodicity, 0.01);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].rfind("far from periodic", 0), 0u) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find(fmt::format("{:.3g}", periodicity)), std::string::npos) << r.warnings[0];
  const std::string log = text_of(dir / "run.log");
  EXPECT_NE(log.find(std::string("# shaker ") + program_version()), std::string::npos);
  EXPECT_NE(log.find("cell_size = 0.5"), std::string::npos);  // the effective configuration
  EXPECT_NE(log.find("shaker continuum: 2 cycles to t ="), std::string::npos);  // the summary
  EXPECT_NE(log.find("warning: " + r.warnings[0]), std::string::npos);
}

TEST(RunLog, ALogIsNotKeptWhenAskedNotTo) {
  const auto dir = test_directory();
  config::Config c = unsettled(dir);
  c.set("run.log=false");
  ASSERT_EQ(run(c), 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "run.h5"));
  EXPECT_FALSE(std::filesystem::exists(dir / "run.log"));
}

TEST(RunWarnings, AFloorAboveTheLayersTemperatureIsAWarningWithItsShare) {
  const auto dir = test_directory();
  config::Config c = unsettled(dir);
  c.set("continuum.temperature_floor=1.0");
  ASSERT_EQ(run(c), 0);
  const RunRecord r = read_run_file(dir / "run.h5");
  const double uses = r.series.column("temperature_floor_uses").back();
  const double cells = static_cast<double>(continuum_case(c).grid.interior_cells());
  const double updates = cells * r.series.column("steps").back();
  std::printf("at the last stored phase: floor uses %.0f of %.0f cell updates\n", uses, updates);
  ASSERT_GT(uses / updates, 1e-3);
  // The warning counts to the end of the run, a little past the last stored phase.
  const auto warning = std::find_if(r.warnings.begin(), r.warnings.end(), [](const std::string& w) {
    return w.rfind("leans on the temperature floor: ", 0) == 0;
  });
  ASSERT_NE(warning, r.warnings.end()) << fmt::format("{}", fmt::join(r.warnings, " | "));
  double warned_uses = 0, warned_updates = 0, warned_share = 0;
  ASSERT_EQ(std::sscanf(warning->c_str(), "leans on the temperature floor: %lf of %lf cell updates (%lf)",
                        &warned_uses, &warned_updates, &warned_share), 3) << *warning;
  EXPECT_GE(warned_uses, uses);
  EXPECT_GE(warned_updates, updates);
  EXPECT_NEAR(warned_share, warned_uses / warned_updates, 1e-3 * warned_share);
  EXPECT_NEAR(warned_share, uses / updates, 0.05 * warned_share);
}

}  // namespace
}  // namespace shaker::continuum::testing

namespace shaker::continuum::testing {
namespace {

// A NaN injected by an external source at one cell stops the run with an error naming the
// time and the cell, and the solver keeps the last good state.
TEST(Failure, NamesTimeAndCellAndKeepsTheLastGoodState) {
  const Grid g = column(50, 10.0);
  PhysicsSettings physics;
  physics.terms.frame_force = false;
  TimeIntegrator solver(g, physics, IntegratorSettings{});
  for (int k = 0; k < g.nz; ++k)
    store_primitive(solver.state(), g.index(0, 0, k), Primitive{number_density(0.2), 0, 0, 0, 1.0});
  solver.op().external_source = [](double t, double, double, double z, double* out) {
    if (t > 0.05 && z > 3.0 && z < 3.2) out[energy] = std::nan("");
  };
  solver.advance_to(0.05);
  const State good = solver.state();
  const double t_good = solver.time();
  std::string message;
  try {
    solver.step(1.0);
  } catch (const StepFailure& failure) {
    message = failure.what();
  }
  std::printf("failure message: %s\n", message.c_str());
  EXPECT_NE(message.find("t = "), std::string::npos);
  EXPECT_NE(message.find("(0, 0, 15)"), std::string::npos);
  EXPECT_EQ(solver.time(), t_good);
  std::size_t differing = 0;
  for (int v = 0; v < variable_count; ++v)
    for (int k = 0; k < g.nz; ++k)
      differing += good.q[v][g.index(0, 0, k)] != solver.state().q[v][g.index(0, 0, k)];
  EXPECT_EQ(differing, 0u);
}

}  // namespace
}  // namespace shaker::continuum::testing

namespace shaker::continuum::testing {
namespace {

// A small 3D run through the program: profiles at every phase, full fields at the chosen
// phases (listed out of order) in time order, in the lab frame, with the run file's root
// attributes and units, and an XDMF sidecar naming them. (Every value through an XDMF reader:
// check_fields_xdmf.py.)
TEST(Output3D, ProfilesFieldsAndXdmf) {
  const auto dir = test_directory();
  config::Config c;
  c.set("run.output=" + (dir / "run3d.h5").string());
  c.set("continuum.dimension=3");
  c.set("continuum.cell_size=0.5");
  c.set("continuum.box_width=2");
  c.set("continuum.ceiling=10");
  c.set("layer.particles=1000");
  c.set("run.transient_cycles=0");
  c.set("run.sampled_cycles=1");
  c.set("run.phases_per_cycle=4");
  c.set("continuum.field_phases=[0.5, 0.25]");
  ASSERT_EQ(run(c), 0);
  const RunRecord r = read_run_file(dir / "run3d.h5");
  EXPECT_EQ(r.profiles.size(), 4u);
  EXPECT_EQ(r.profiles[0].size(), 20u);
  EXPECT_NE(r.configuration.find("dimension = 3"), std::string::npos);
  ASSERT_TRUE(std::filesystem::exists(dir / "run3d.fields.h5"));
  ASSERT_TRUE(std::filesystem::exists(dir / "run3d.fields.xdmf"));
  {
    const h5::Handle file = h5::open_file(dir / "run3d.fields.h5");
    EXPECT_EQ(h5::read_integer_attribute(file.id(), "schema_version"), output_schema_version);
    EXPECT_EQ(h5::read_string_attribute(file.id(), "configuration"), r.configuration);
    EXPECT_EQ(h5::read_string_attribute(file.id(), "solver"), "continuum");
    EXPECT_EQ(h5::read_string_attribute(file.id(), "model_variant"), r.model_variant);
    EXPECT_EQ(h5::read_string_attribute(file.id(), "git_commit"), r.git_commit);
    EXPECT_EQ(h5::read_string_attribute(file.id(), "kind"), fields_file_kind);
    EXPECT_EQ(h5::members(file.id()),
              (std::vector<std::string>{"hexahedra", "snapshot_000", "snapshot_001"}));
    // Snapshot s is the profile row of its phase: the same instant and plate.
    for (const auto& [group_name, k] : {std::pair{"snapshot_000", 1}, std::pair{"snapshot_001", 2}}) {
      SCOPED_TRACE(group_name);
      const h5::Handle group = h5::open_group(file.id(), group_name);
      EXPECT_EQ(h5::read_double_attribute(group.id(), "phase"), 0.25 * k);
      EXPECT_EQ(h5::read_double_attribute(group.id(), "time"), r.profiles[k].time);
      const double plate_z = h5::read_double_attribute(group.id(), "plate_z");
      EXPECT_EQ(plate_z, r.profiles[k].plate_z);
      EXPECT_EQ(h5::read_double_attribute(group.id(), "plate_v"), r.profiles[k].plate_v);
      EXPECT_NE(plate_z, 0.0);
      const auto points = h5::read_doubles(group.id(), "points");
      ASSERT_EQ(points.size(), 3u * 5 * 5 * 21);
      EXPECT_EQ(points[2], plate_z);                          // corner (0, 0, 0)
      EXPECT_EQ(points.back(), 20 * 0.5 + plate_z);           // corner (4, 4, 20)
      EXPECT_EQ(points[points.size() - 3], 4 * 0.5);
      // One sampled cycle: the profile is the horizontal mean of these fields.
      const auto n = h5::read_doubles(group.id(), "n");
      ASSERT_EQ(n.size(), 4u * 4 * 20);
      for (int cell = 0; cell < 20; cell += 7) {
        double sum = 0;
        for (int column = 0; column < 16; ++column) sum += n[static_cast<std::size_t>(cell * 16 + column)];
        EXPECT_NEAR(sum / 16, r.profiles[k].n[static_cast<std::size_t>(cell)], 1e-12 * sum);
      }
      for (const auto& [name, units] : {std::pair{"n", "1/sigma^3"}, std::pair{"uz", "sqrt(g sigma)"},
                                        std::pair{"T", "g sigma"}, std::pair{"points", "sigma"}}) {
        const h5::Handle set(H5Dopen2(group.id(), name, H5P_DEFAULT));
        EXPECT_EQ(h5::read_string_attribute(set.id(), "units"), units) << name;
      }
    }
  }
  // The fields file is not a run file, and says so.
  try {
    read_run_file(dir / "run3d.fields.h5");
    ADD_FAILURE() << "the fields file was read as a run file";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("'shaker continuum fields' file"), std::string::npos)
        << error.what();
  }
  std::ifstream xdmf(dir / "run3d.fields.xdmf");
  const std::string text((std::istreambuf_iterator<char>(xdmf)), std::istreambuf_iterator<char>());
  std::size_t grids = 0;
  for (std::size_t at = text.find("GridType=\"Uniform\""); at != std::string::npos;
       at = text.find("GridType=\"Uniform\"", at + 1))
    ++grids;
  EXPECT_EQ(grids, 2u);
  EXPECT_NE(text.find("run3d.fields.h5:/snapshot_001/T"), std::string::npos);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

/// The densities of the cells the initial layer fills completely, in a 3D box 4 x 6 (cell
/// 0.5) holding the base case's mass per area, at perturbation p and seed `seed`.
std::vector<double> filled_layer_densities(double p, std::uint64_t seed, double* mass_per_area = nullptr) {
  const Grid g = make_grid(3, 4.0, 6.0, 20.0, 0.5);
  LayerSpecification layer;
  layer.perturbation = p;
  layer.seed = seed;
  State state;
  state.resize(g.size());
  const double top = flat_layer(g, layer, state);
  std::vector<double> n;
  double mass = 0.0;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const double cell = state.q[density][g.index(i, j, k)];
        mass += cell * g.cell_volume();
        if ((k + 1) * g.h <= top) n.push_back(cell);
      }
  if (mass_per_area) *mass_per_area = mass / (g.nx * g.h * g.ny * g.h);
  return n;
}

TEST(InitialPerturbation, HasTheAskedAmplitudeAndIsReproducibleFromTheSeed) {
  // continuum.perturbation: each cell of the layer drawn at (1 + p u) times the layer's
  // density, u uniform in [-1, 1], then all scaled to restore the mass per area; the seed is
  // run.seed. The spread max / min of the filled cells is then at most (1 + p) / (1 - p), and
  // over 20 rows of 8 x 12 cells it comes within 1 % of that.
  const double p = 0.05;
  double mass = 0.0;
  const std::vector<double> a = filled_layer_densities(p, 3, &mass), again = filled_layer_densities(p, 3);
  const std::vector<double> other = filled_layer_densities(p, 4), flat = filled_layer_densities(0.0, 3);
  const auto [lo, hi] = std::minmax_element(a.begin(), a.end());
  const double spread = *hi / *lo, bound = (1 + p) / (1 - p);
  std::printf("%zu filled cells: spread %.6f of the bound %.6f; mass per area %.15g\n", a.size(), spread, bound, mass);
  ASSERT_GT(a.size(), 1000u);
  EXPECT_LE(spread, bound);
  EXPECT_GT(spread, 0.99 * bound);
  EXPECT_NEAR(mass, LayerSpecification{}.mass_per_area, 1e-12 * mass);
  EXPECT_EQ(a, again);
  EXPECT_NE(a, other);
  const auto [flat_lo, flat_hi] = std::minmax_element(flat.begin(), flat.end());
  EXPECT_EQ(*flat_lo, *flat_hi);  // 0: the flat layer, every filled cell alike
  EXPECT_EQ(*flat_lo, number_density(LayerSpecification{}.volume_fraction));
}

}  // namespace
}  // namespace shaker::continuum::testing
