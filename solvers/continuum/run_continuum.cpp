// `shaker continuum CASE.toml`: the run loop of common/run_loop.hpp (the MD's protocols)
// drives the continuum solver; its observers average the profiles at phases k / K over the
// sampled cycles, record the time series, take the 3D field snapshots and report progress.
// The time series carries, besides the common columns (t, phase, plate_z, com_z), mass and
// energies, the container-frame energy budget (frame_energy and the budget's columns of
// common/series_recorder.hpp: drive work, collisional loss, floor energy, residual), the periodicity
// measure of the last two cycles (each phase's centre of mass against the same phase one cycle
// earlier; also printed in the summary) and the restitution in effect at each row.
//
// Under an MPI launcher the 3D box is decomposed over the ranks (halo.hpp, docs/parallel.md):
// every rank advances its block, and at every stored phase the blocks are gathered to the root,
// which alone records, averages and writes, with the serial code, on the gathered box.
#include "continuum/run_continuum.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>

#include "common/atomic_output.hpp"
#include "common/checkpoints.hpp"
#include "common/errors.hpp"
#include "common/memory.hpp"
#include "common/output_paths.hpp"
#include "common/packed_fields.hpp"
#include "common/progress.hpp"
#include "common/ranks.hpp"
#include "common/run_file.hpp"
#include "common/run_loop.hpp"
#include "common/series_recorder.hpp"
#include "common/terminal_log.hpp"
#include "continuum/checkpoint.hpp"
#include "continuum/halo.hpp"
#include "continuum/output.hpp"
#include "continuum/setup.hpp"

namespace shaker::continuum {

namespace {

/// The whole box as the outputs read it. A plain run reads the solver itself; a decomposed run
/// gathers the ranks' blocks to the root at every stored phase and at the end (every rank takes
/// part, in the observers' order, so this observer comes first), and only the root writes.
class Box final : public RunObserver {
 public:
  Box(const TimeIntegrator& solver, const Grid& box_grid)
      : solver_(solver), halo_(solver.op().halo()), grid_(box_grid) {}
  void at_phase(const PhaseInstant&) override { gather(); }
  void at_run_end(double) override { gather(); }
  /// Brings the root's copy up to the solver's state (collective on a decomposed run).
  void gather() {
    if (!halo_) return;
    halo_->gather(solver_.state(), state_);
    // The budget and the floor count are sums of the ranks' shares; the step counts are alike.
    const EnergyBudget& b = solver_.budget();
    Counters counters = solver_.counters();
    std::vector<double> shares{b.body_work, b.collisional_loss, b.floor_energy,
                               static_cast<double>(counters.temperature_floor_uses)};
    halo_->sum(shares);
    counters.temperature_floor_uses = static_cast<std::int64_t>(shares[3]);
    scalars_ = RunScalars{solver_.time(), solver_.op().settings().e,
                          EnergyBudget{shares[0], shares[1], shares[2]}, counters};
  }
  /// This process records and writes: the plain run, or the root.
  bool writer() const { return !halo_ || halo_->root(); }
  BoxView view() const { return halo_ ? BoxView{grid_, state_, scalars_} : view_of(solver_); }

 private:
  const TimeIntegrator& solver_;
  const Halo* halo_;
  Grid grid_;
  State state_;  ///< the root's gathered copy
  RunScalars scalars_;
};

/// The rows of the time series, one at every stored phase.
class Recorder final : public RunObserver {
 public:
  Recorder(const Box& b, const ShakerKinematics& k, std::size_t K) : box_(b), shaker_(k), phases_(K) {}
  void at_phase(const PhaseInstant&) override {
    if (box_.writer()) add(box_.view());
  }
  const TimeSeries& series() const { return rows_.series(); }
  const std::vector<double>& column(const std::string& name) const { return rows_.series().column(name); }
  /// RMS over the last cycle's phases of the change from the previous cycle, / RMS height
  /// (NaN until two whole cycles are recorded).
  double periodicity() const {
    const std::vector<double>& com = column("com_z");  // the row being recorded included
    if (com.size() < 2 * phases_) return std::numeric_limits<double>::quiet_NaN();
    const std::vector<double>& change = column("com_z_change_from_previous_cycle");
    double d2 = 0, h2 = 0;
    for (std::size_t i = com.size() - phases_; i < com.size(); ++i) {
      d2 += change[i] * change[i];
      h2 += com[i] * com[i];
    }
    return std::sqrt(d2 / h2);
  }

 private:
  void add(const BoxView& view) {
    const Diagnostics d = diagnostics(view, shaker_);
    const double t = view.scalars.time;
    const std::size_t row = rows_.rows();
    rows_.set("t", t);
    rows_.set("phase", shaker_.phase(t));
    rows_.set("plate_z", shaker_.position(t));
    rows_.set("com_z", d.center_of_mass);
    rows_.set("total_mass", d.mass);
    rows_.set("kinetic_energy", d.kinetic);
    rows_.set("thermal_energy", d.thermal);
    rows_.set("potential_energy", d.potential);
    rows_.set("collisional_loss_rate", d.loss_rate);
    rows_.set("com_z_change_from_previous_cycle", row >= phases_ ? d.center_of_mass - column("com_z")[row - phases_]
                                                                  : std::numeric_limits<double>::quiet_NaN());
    rows_.set("temperature_floor_uses", static_cast<double>(view.scalars.counters.temperature_floor_uses));
    rows_.set("steps", static_cast<double>(view.scalars.counters.steps));
    const double energy = total_energy(view);
    const EnergyBudget& b = view.scalars.budget;
    rows_.set("frame_energy", energy);
    rows_.set_energy(EnergyTotals{energy, b.body_work, b.collisional_loss, b.floor_energy});
    rows_.set("periodicity_last_two_cycles", periodicity());
    rows_.set("restitution", view.scalars.e);
    rows_.end_row();
  }

  const Box& box_;
  const ShakerKinematics& shaker_;
  std::size_t phases_;
  SeriesRecorder rows_;
};

/// The profiles of the run file: horizontally averaged at each stored phase and averaged over
/// the sampled cycles.
class ProfileAverage final : public RunObserver {
 public:
  ProfileAverage(const Box& box, const ShakerKinematics& shaker, std::size_t phases)
      : box_(box), shaker_(shaker), sums_(phases), cycles_(phases, 0) {}
  void at_phase(const PhaseInstant& instant) override {
    if (!instant.sampled || !box_.writer()) return;
    const auto k = static_cast<std::size_t>(instant.phase);
    add(sums_[k], horizontal_profile(box_.view(), shaker_), cycles_[k]++ == 0);
  }
  /// Phases no sampled cycle reached (a run continued within its last cycle) are left out.
  std::vector<Profile> averages() const {
    std::vector<Profile> out;
    for (std::size_t k = 0; k < sums_.size(); ++k) {
      if (cycles_[k] == 0) continue;
      out.push_back(sums_[k]);
      divide(out.back(), static_cast<double>(cycles_[k]));
    }
    return out;
  }

 private:
  static void add(Profile& sum, const Profile& p, bool first) {
    if (first) {
      sum = p;
      return;
    }
    for (std::size_t i = 0; i < p.size(); ++i) {
      sum.n[i] += p.n[i];
      sum.nu[i] += p.nu[i];
      sum.uz[i] += p.uz[i];
      sum.T[i] += p.T[i];
    }
  }
  static void divide(Profile& p, double count) {
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.n[i] /= count;
      p.nu[i] /= count;
      p.uz[i] /= count;
      p.T[i] /= count;
    }
  }

  const Box& box_;
  const ShakerKinematics& shaker_;
  std::vector<Profile> sums_;
  std::vector<int> cycles_;
};

/// 3D fields at the stored phases of continuum.field_phases, in the last cycle or in those of
/// continuum.field_cycles.
class FieldSnapshots final : public RunObserver {
 public:
  FieldSnapshots(const Box& box, const ShakerKinematics& shaker, const ContinuumCase& c)
      : box_(box), shaker_(shaker), phases_(c.field_phases), cycles_(c.field_cycles) {}
  void at_phase(const PhaseInstant& instant) override {
    if (box_.writer() && instant.selected(phases_, cycles_))
      snapshots.push_back(snapshot(box_.view(), shaker_, instant.cycle));
  }
  std::vector<FieldSnapshot> snapshots;

 private:
  const Box& box_;
  const ShakerKinematics& shaker_;
  std::vector<std::int64_t> phases_, cycles_;  ///< increasing
};

/// The solver as the run loop drives it.
class DrivenIntegrator final : public DrivenSolver {
 public:
  explicit DrivenIntegrator(TimeIntegrator& solver) : solver_(solver) {}
  double time() const override { return solver_.time(); }
  void advance_to(double t) override { solver_.advance_to(t); }
  bool advance_to(double t, const std::function<bool()>& stop) override {
    while (solver_.time() < t) {
      if (stop()) return false;
      solver_.step(t);
    }
    return true;
  }
  void switch_restitution(const Restitution& after) override {
    solver_.op().settings().e = after.e;
    switched = true;
  }
  bool switched = false;

 private:
  TimeIntegrator& solver_;
};

/// A periodic run whose centre of mass still moves from one cycle to the next by more than this
/// fraction of its height (periodicity_last_two_cycles) has not settled into its periodic state.
constexpr double settled_periodicity = 0.01;
/// A run that raised more than this share of its cell updates to the temperature floor is
/// decided by the floor, not by its equations, where the layer thins.
constexpr double floor_share_limit = 1e-3;

/// What the run finds doubtful about its own result, one sentence each (docs/output-schema.md).
std::vector<std::string> doubts_about(const RunProtocol& run, double periodicity, const Counters& counters,
                                      double cells) {
  std::vector<std::string> doubts;
  if (run.kind == RunProtocol::Kind::periodic && periodicity > settled_periodicity)
    doubts.push_back(fmt::format(
        "far from periodic: the centre of mass changed by {:.3g} of its height (RMS) over the last "
        "cycle, above {:g}; run more transient cycles (run.transient_cycles)", periodicity,
        settled_periodicity));
  const double updates = cells * static_cast<double>(counters.steps);
  const double floor_share = updates > 0.0 ? static_cast<double>(counters.temperature_floor_uses) / updates : 0.0;
  if (floor_share > floor_share_limit)
    doubts.push_back(fmt::format(
        "leans on the temperature floor: {} of {:.4g} cell updates ({:.3g}) were raised to "
        "continuum.temperature_floor, above {:g}; the dilute region is decided by the floor",
        counters.temperature_floor_uses, updates, floor_share, floor_share_limit));
  return doubts;
}

/// Where a step failure leaves the last good state: OUTPUT.last_good.h5.
std::filesystem::path last_good_path(const std::filesystem::path& output) {
  return derived_name(output, ".last_good.h5");
}

/// Every file the run may write, none equal to an input or to another (checked before work).
void check_outputs(const ContinuumCase& c, const CheckpointSettings& checkpoints, const std::vector<NamedPath>& inputs) {
  const std::filesystem::path output = c.parameters.run.output;
  std::vector<NamedPath> outputs{{"run.output", output}};
  terminal_log::add_output(outputs, c.parameters.run);
  if (!output.empty()) outputs.push_back({"run.output's last-good checkpoint", last_good_path(output)});
  if (!c.field_phases.empty() && !output.empty()) {
    const std::filesystem::path fields = derived_name(output, ".fields.h5");
    outputs.push_back({"run.output's fields file", fields});
    outputs.push_back({"run.output's fields sidecar", derived_name(fields, ".xdmf")});
  }
  checkpoints.check_paths(outputs, inputs);
}

/// The decomposition of a 3D box under an MPI launcher (any number of ranks), else null.
/// InputError before any work: a 1D column on several ranks, or a box too narrow for them.
std::shared_ptr<const Halo> decomposition(const Grid& grid) {
  if (!launched_by_mpi()) return nullptr;
  const int ranks = Ranks::world().size();
  if (grid.dimension == 3) return std::make_shared<const Halo>(grid, ranks);
  if (ranks > 1)
    throw InputError(fmt::format(
        "continuum.dimension = 1: the 1D column runs on one rank, not on {}: start it without "
        "mpirun, or spread a 3D box (continuum.dimension = 3) over the ranks", ranks));
  return nullptr;
}

/// The run's memory on this machine, checked before anything is allocated (InputError on every
/// rank alike). Each process holds the solver's working set of its cells (its block under a
/// launcher) and its part of the halo's shared window; the writer also the field snapshots
/// and, decomposed, the gathered box. The ranks sharing a machine share its MemAvailable, so
/// their needs add up.
void check_memory_of_run(const ContinuumCase& c, const Halo* halo) {
  const Grid& g = c.grid;
  const double box_cells = static_cast<double>(g.nx) * g.ny * g.nz;
  const double own_cells = halo ? static_cast<double>(halo->block().nx) * halo->block().ny * g.nz : box_cells;
  constexpr double stored_bytes_per_cell = variable_count * sizeof(double);
  const double copies = (halo ? 1.0 : 0.0) + static_cast<double>(c.field_snapshots());
  const bool writer = !halo || halo->root();
  const double mine = own_cells * solver_bytes_per_cell + (halo ? halo->shared_bytes() : 0.0) +
                      (writer ? copies * box_cells * stored_bytes_per_cell : 0.0);
  const auto [machine, ranks_here] = halo ? halo->sum_on_machine(mine) : std::pair<double, int>{mine, 1};
  const std::string grid = fmt::format(
      "a {}D grid of {:.3g} cells (continuum.cell_size = {}, continuum.ceiling = {}{})", g.dimension,
      box_cells, g.h, g.height(),
      g.dimension == 3 ? fmt::format(", continuum.box_width = {}, continuum.box_depth = {}", g.nx * g.h, g.ny * g.h) : "");
  std::string failure;
  try {
    if (halo)
      check_memory(machine, fmt::format("{} over {} ranks, {} of them on this machine (this rank's block: {:.3g} "
                                        "cells; the root also holds a copy of the box)",
                                        grid, halo->size(), ranks_here, own_cells),
                   "allowed: a larger continuum.cell_size, a smaller box, or fewer ranks per machine "
                   "(more machines)");
    else
      check_memory(machine, grid, "allowed: a larger continuum.cell_size or a smaller box");
  } catch (const InputError& error) {
    failure = error.what();
  }
  if (halo ? !halo->agree(failure) : !failure.empty()) throw InputError(failure);
}

/// A checkpoint read by the root and scattered to the ranks of a decomposed run: the same
/// checkpoint continues on any number of ranks. Every rank fails alike on a bad checkpoint.
SchedulePosition read_decomposed_checkpoint(const std::filesystem::path& path, const Halo& halo,
                                            TimeIntegrator& solver) {
  State box;
  RunScalars scalars;
  SchedulePosition position;
  std::string failure;
  if (halo.root()) {
    try {
      box.resize(halo.box().size());
      position = read_checkpoint(path, halo.box(), box, scalars);
    } catch (const std::exception& error) {
      failure = error.what();
    }
  }
  if (!halo.agree(failure)) throw InputError(failure);
  // The root carries the whole box's budget and floor count; the other ranks' shares start at 0.
  Counters counters = scalars.counters;
  if (!halo.root()) counters.temperature_floor_uses = 0;
  const auto shared = std::tie(scalars.time, scalars.e, counters.steps, counters.rejected_steps,
                               counters.diffusion_stages, position.start_time, position.cycle, position.phase,
                               position.phases);
  std::vector<double> values;
  pack_fields(values, shared);
  halo.broadcast(values);
  const double* at = values.data();
  unpack_fields(at, shared);
  halo.scatter(box, solver.state());
  solver.set_time(scalars.time);
  solver.op().settings().e = scalars.e;
  solver.counters() = counters;
  solver.budget() = halo.root() ? scalars.budget : EnergyBudget{};
  return position;
}

/// The continuum's schedule: a new one from t = 0, or the checkpoint's, continued with the
/// checkpoint's state loaded into the solver.
PhaseSchedule starting_schedule(const ContinuumCase& c, const config::Config& config, const std::filesystem::path& restart_from,
                                TimeIntegrator& solver) {
  const RunProtocol& run = c.parameters.run;
  if (restart_from.empty()) return PhaseSchedule::from_start(run, c.parameters.shaker, solver.time());
  const std::string source = restart_source(restart_from);
  const std::string saved = checkpoint_configuration(restart_from);
  config::require_same_keys(config, saved, config::restart_continuum, source);
  const Halo* halo = solver.op().halo();
  const SchedulePosition position = halo ? read_decomposed_checkpoint(restart_from, *halo, solver)
                                         : read_checkpoint(restart_from, solver);
  PhaseSchedule schedule = PhaseSchedule::from_start(run, c.parameters.shaker, position.start_time);
  schedule.resume_at(position, solver.time(), source);
  schedule.check_switch(CaseParameters::from(config::Config::from_toml(saved, source)).run, solver.time(), source);
  return schedule;
}

/// The summary on stdout (and in the log), the warnings on stderr.
void report_run(std::int64_t cycles, double t, double wall_seconds, const Counters& counters, const Recorder& recorder,
                const std::vector<std::string>& warnings, const std::filesystem::path& output) {
  const std::vector<double>& mass = recorder.column("total_mass");
  const std::vector<double>& residual = recorder.column("energy_budget_residual");
  const std::vector<double>& loss = recorder.column("accumulated_collisional_loss");
  terminal_log::say(stdout, "shaker continuum: {} cycles to t = {:.6g}, wall time {}, {} steps ({} rejected), "
             "temperature floor used {} times; mass drift {:.3e}; periodicity (centre of mass, last "
             "two cycles) {:.3e} (series column periodicity_last_two_cycles); energy budget residual "
             "{:.3e} of the accumulated loss {:.6g}\nwrote {}\n",
             cycles, t, duration_text(wall_seconds), counters.steps,
             counters.rejected_steps, counters.temperature_floor_uses,
             (mass.back() - mass.front()) / mass.front(), recorder.periodicity(), residual.back(),
             loss.back() - loss.front(), output.string());
  for (const std::string& doubt : warnings)
    terminal_log::say(stderr, "shaker continuum: warning: {} (kept in the run file's attribute warnings)\n", doubt);
}

int execute(const config::Config& config, const std::vector<NamedPath>& inputs,
            const ProgressSettings& progress_settings) {
  const Stopwatch wall;
  const ContinuumCase c = continuum_case(config);
  const CheckpointSettings checkpoints = CheckpointSettings::from(config);
  check_outputs(c, checkpoints, inputs);
  const std::shared_ptr<const Halo> halo = decomposition(c.grid);
  check_memory_of_run(c, halo.get());
  const RunProtocol& run = c.parameters.run;
  const ShakerKinematics& shaker = c.parameters.shaker;
  TimeIntegrator solver = make_solver(c, halo);
  const PhaseSchedule schedule = starting_schedule(c, config, checkpoints.restart_from, solver);
  const std::string configuration = config.to_toml();
  const std::filesystem::path output = run.output;
  const auto K = static_cast<std::size_t>(schedule.phases());

  Box box(solver, c.grid);
  Recorder recorder(box, shaker, K);
  ProfileAverage profiles(box, shaker, K);
  FieldSnapshots fields(box, shaker, c);
  const double cells = static_cast<double>(c.grid.interior_cells());
  ProgressSettings progress_of_rank = progress_settings;
  progress_of_rank.quiet = progress_settings.quiet || !box.writer();
  ProgressReport progress("shaker continuum", "cell updates/s",
                          [&] { return cells * static_cast<double>(solver.counters().steps); },
                          progress_of_rank);
  // The root writes every checkpoint, of the box gathered at the phase (the Box observer runs
  // first); the ranks of a decomposed run stop together at the phase after any of them got a
  // stop signal.
  const auto write = [&](const std::filesystem::path& path, const SchedulePosition& position) {
    if (box.writer()) write_checkpoint(path, box.view(), position, configuration);
  };
  StopAcrossRanks stop_across_ranks{.writer = box.writer()};
  if (halo) stop_across_ranks.agree = [&](int signal) { return static_cast<int>(halo->max(signal)); };
  stop_across_ranks.before_stop_between = [&] { box.gather(); };
  CheckpointObserver checkpointing(checkpoints, schedule, write, "shaker continuum", stop_across_ranks);
  std::vector<RunObserver*> observers{&box, &recorder, &profiles, &progress, &checkpointing};
  if (!c.field_phases.empty()) observers.insert(observers.end() - 1, &fields);
  DrivenIntegrator driven(solver);
  if (box.writer()) terminal_log::start(run, configuration);  // the inputs are accepted
  try {
    schedule.run(driven, observers, &checkpointing);
  } catch (const StepFailure& failure) {
    // Every rank fails alike (the step's decisions are agreed), so all take part in the gather.
    box.gather();
    if (!box.writer()) return 1;
    const std::filesystem::path last_good = last_good_path(output);
    write(last_good, checkpointing.next());
    terminal_log::say(stderr, "shaker continuum: {}\nThe last good state is in {}\n", failure.what(),
                      last_good.string());
    return 1;
  }
  if (!box.writer()) return 0;

  RunRecord record;
  record.solver = "continuum";
  record.model_variant = fmt::format("{} transport, {}D", model::to_string(c.physics.transport),
                                     c.grid.dimension);
  record.configuration = configuration;
  record.e = driven.switched ? run.after_switch.e : c.parameters.restitution.e;  // e of the recorded cycle
  record.profiles = profiles.averages();
  record.series = recorder.series();
  const Counters counters = box.view().scalars.counters;
  record.warnings = doubts_about(run, recorder.periodicity(), counters, cells);
  if (!fields.snapshots.empty()) {
    write_fields(derived_name(output, ".fields.h5"), c.grid, fields.snapshots, record);
  }
  write_run_file(output, record);
  report_run(schedule.cycles(), solver.time(), wall.seconds(), counters, recorder, record.warnings, output);
  return 0;
}

}  // namespace

int run(const config::Config& config, const std::vector<NamedPath>& inputs,
        const ProgressSettings& progress) {
  return execute(config, inputs, progress);
}

}  // namespace shaker::continuum
