#include "md/protocol.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "common/errors.hpp"
#include "md/sampling.hpp"

namespace shaker::md {

std::string crossing_column(double height) { return fmt::format("crossings_z{:g}", height); }
std::string distinct_particles_column(double height) { return fmt::format("particles_z{:g}", height); }

MdSettings MdSettings::from(const config::Config& c) {
  MdSettings s;
  s.ceiling = c.real("md.ceiling");
  s.bin_height = c.real("md.bin_height");
  s.initial_state = c.text("md.initial_state");
  s.gas_volume_fraction = c.real("md.gas_volume_fraction");
  s.gas_temperature = c.real("md.gas_temperature");
  s.initial_perturbation = c.real("md.initial_perturbation");
  s.tc_guard = c.text("md.collapse_guard") == "tc";
  s.tc = c.real("md.tc");
  s.queue = c.text("md.event_queue") == "calendar" ? QueueKind::calendar : QueueKind::heap;
  s.initial_file = c.text("md.initial_file");
  s.initial_frame = c.integer("md.initial_frame");
  if (s.initial_state == "file" && s.initial_file.empty())
    throw InputError("md.initial_state = \"file\" but md.initial_file = \"\"; allowed: the path of an H5MD "
                     "particle file (RUN.particles.h5 of an earlier run)");
  const RunProtocol run = CaseParameters::from(c).run;
  s.snapshot_phases = stored_phase_indices(c, "md.snapshot_phases", run.phases_per_cycle);
  s.snapshot_cycles = cycle_indices(c, "md.snapshot_cycles", run);
  if (s.snapshot_phases.empty() != s.snapshot_cycles.empty())
    throw InputError(fmt::format("md.snapshot_phases = [{}] and md.snapshot_cycles = [{}]: a snapshot needs a "
                                 "phase and a cycle; allowed: both lists empty (no snapshots) or both set",
                                 fmt::join(c.real_list("md.snapshot_phases"), ", "),
                                 fmt::join(c.real_list("md.snapshot_cycles"), ", ")));
  s.crossing_heights = c.real_list("md.crossing_heights");
  for (std::size_t k = 0; k < s.crossing_heights.size(); ++k)
    for (std::size_t m = 0; m < k; ++m)
      if (crossing_column(s.crossing_heights[k]) == crossing_column(s.crossing_heights[m]))
        throw InputError(fmt::format("md.crossing_heights = [{}]: the heights {} and {} give the "
                                     "same column name {}; allowed: distinct heights > 0",
                                     fmt::join(s.crossing_heights, ", "), s.crossing_heights[m],
                                     s.crossing_heights[k], crossing_column(s.crossing_heights[k])));
  return s;
}

namespace {

/// Time-series columns, one row per sampling instant.
struct SeriesRows {
  std::vector<std::string> names = {
      "t", "phase", "plate_z", "com_z", "kinetic", "potential", "plate_work",
      "collisional_loss", "energy_closure", "pair_collisions", "plate_collisions",
      "ceiling_collisions", "cell_crossings", "guard_activations", "overlaps", "near_plate",
      "collisions", "queue_consistent"};
  std::vector<std::vector<double>> columns;
  explicit SeriesRows(const std::vector<double>& crossing_heights) {
    for (double h : crossing_heights) names.push_back(crossing_column(h));
    for (double h : crossing_heights) names.push_back(distinct_particles_column(h));
    columns.resize(names.size());
  }
  void add(std::initializer_list<double> row, const std::vector<std::uint64_t>& crossings,
           const std::vector<std::uint64_t>& distinct_particles) {
    std::size_t k = 0;
    for (double x : row) columns[k++].push_back(x);
    for (std::uint64_t c : crossings) columns[k++].push_back(static_cast<double>(c));
    for (std::uint64_t c : distinct_particles) columns[k++].push_back(static_cast<double>(c));
  }
  TimeSeries finish() {
    TimeSeries s;
    for (std::size_t k = 0; k < columns.size(); ++k) s.add(names[k], std::move(columns[k]));
    return s;
  }
};

/// The energy and running totals at the start of the run, from which its budget counts.
struct BudgetOrigin {
  double energy;
  Tally tally;
  EnergyBudget at(const Tally& now, double energy_now) const {
    EnergyBudget b;
    b.plate_work = now.plate_work - tally.plate_work;
    b.collisional_loss = now.pair_loss + now.wall_loss - tally.pair_loss - tally.wall_loss;
    b.energy_change = energy_now - energy;
    const double scale = std::max({std::fabs(b.plate_work), std::fabs(b.collisional_loss), std::fabs(energy_now), 1e-300});
    b.relative_closure = std::fabs(b.energy_change + b.collisional_loss - b.plate_work) / scale;
    return b;
  }
};

/// The rows of RunOutcome::series: one at every stored phase and one at the end of the run.
class SeriesObserver final : public RunObserver {
 public:
  SeriesObserver(Simulation& sim, const ShakerKinematics& shaker, const MdSettings& settings,
                 const BudgetOrigin& origin, PhaseSnapshot& snapshot)
      : sim_(sim), shaker_(shaker), origin_(origin), snapshot_(snapshot), rows_(settings.crossing_heights) {
    sim.start_height_counts(settings.crossing_heights, shaker.frequency());
  }
  void at_phase(const PhaseInstant& instant) override { record(instant.t); }
  void at_run_end(double t) override { record(t); }
  TimeSeries finish() { return rows_.finish(); }

 private:
  void record(double t) {
    snapshot_.take(t);
    const std::vector<Vec3>& r = snapshot_.r();
    const std::vector<Vec3>& v = snapshot_.v();
    double com = 0.0, near_plate = 0.0, kinetic = 0.0;
    const double plate_z = shaker_.position(t);
    for (std::size_t i = 0; i < r.size(); ++i) {
      com += r[i].z;
      kinetic += 0.5 * dot(v[i], v[i]);
      near_plate += r[i].z - 0.5 - plate_z < 0.5 ? 1.0 : 0.0;  // within half a diameter
    }
    const double potential = sim_.geometry().gravity * com;
    const EnergyBudget b = origin_.at(sim_.tally(), kinetic + potential);
    const Tally& tally = sim_.tally();
    rows_.add({t, shaker_.phase(t), plate_z, com / static_cast<double>(sim_.size()), kinetic, potential,
               b.plate_work, b.collisional_loss, b.relative_closure,
               static_cast<double>(tally.pair), static_cast<double>(tally.plate),
               static_cast<double>(tally.ceiling), static_cast<double>(tally.cell),
               static_cast<double>(tally.guard_activations),
               static_cast<double>(sim_.count_overlaps(r, 1e-9)), near_plate,
               static_cast<double>(tally.pair - origin_.tally.pair),
               sim_.queue_consistent() ? 1.0 : 0.0},
              sim_.crossings_at(t), sim_.distinct_particles_at(t));
  }

  const Simulation& sim_;
  const ShakerKinematics& shaker_;
  const BudgetOrigin& origin_;
  PhaseSnapshot& snapshot_;
  SeriesRows rows_;
};

/// Every particle at the stored phases and cycles of MdSettings::snapshot_*, read from the
/// snapshot the other observers share: all at the phase's time.
class ParticleSnapshots final : public RunObserver {
 public:
  ParticleSnapshots(const ShakerKinematics& shaker, const MdSettings& settings, PhaseSnapshot& snapshot)
      : shaker_(shaker), settings_(settings), snapshot_(snapshot) {}
  void at_phase(const PhaseInstant& at) override {
    if (!at.selected(settings_.snapshot_phases, settings_.snapshot_cycles)) return;
    snapshot_.take(at.t);
    frames.push_back(ParticleFrame{at.cycle * at.phases + at.phase, at.cycle, at.t,
                                   static_cast<double>(at.phase) / static_cast<double>(at.phases),
                                   shaker_.position(at.t), shaker_.velocity(at.t), snapshot_.r(), snapshot_.v()});
  }
  std::vector<ParticleFrame> frames;

 private:
  const ShakerKinematics& shaker_;
  const MdSettings& settings_;
  PhaseSnapshot& snapshot_;
};

}  // namespace

RunOutcome run_protocol(Simulation& sim, const CaseParameters& parameters, const MdSettings& settings,
                        const std::vector<RunObserver*>& also) {
  return run_protocol(sim, PhaseSchedule::whole_cycles(parameters.run, parameters.shaker, sim.time()),
                      parameters, settings, also);
}

PhaseSampler make_sampler(const Simulation& sim, const PhaseSchedule& schedule, const MdSettings& settings) {
  return PhaseSampler(static_cast<int>(schedule.phases()), settings.bin_height, settings.ceiling,
                      sim.geometry().width * sim.geometry().depth);
}

RunOutcome run_protocol(Simulation& sim, const PhaseSchedule& schedule, const CaseParameters& parameters,
                        const MdSettings& settings, const std::vector<RunObserver*>& also) {
  PhaseSampler sampler = make_sampler(sim, schedule, settings);
  return run_protocol(sim, schedule, sampler, parameters, settings, also);
}

RunOutcome run_protocol(Simulation& sim, const PhaseSchedule& schedule, PhaseSampler& sampler,
                        const CaseParameters& parameters, const MdSettings& settings,
                        const std::vector<RunObserver*>& also) {
  const BudgetOrigin origin{sim.kinetic_energy(sim.time()) + sim.potential_energy(sim.time()), sim.tally()};
  PhaseSnapshot snapshot(sim);
  SeriesObserver series(sim, parameters.shaker, settings, origin, snapshot);
  SamplingObserver sampling(sampler, snapshot);
  ParticleSnapshots particles(parameters.shaker, settings, snapshot);
  std::vector<RunObserver*> observers{&series, &sampling};
  if (!settings.snapshot_phases.empty()) observers.push_back(&particles);
  observers.insert(observers.end(), also.begin(), also.end());

  const auto start = std::chrono::steady_clock::now();
  DrivenSimulation driven(sim);
  schedule.run(driven, observers);
  RunOutcome out;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const double end = schedule.end();
  out.profiles = sampler.profiles(parameters.shaker);
  out.samples = sampler.samples();
  out.series = series.finish();
  out.frames = std::move(particles.frames);
  out.budget = origin.at(sim.tally(), sim.kinetic_energy(end) + sim.potential_energy(end));
  out.overlaps = sim.count_overlaps(end, 1e-9);
  out.queue_consistent = sim.queue_consistent();
  const Tally& tally = sim.tally();
  out.at_start = origin.tally;
  out.collisions = tally.collisions() - origin.tally.collisions();
  out.events = out.collisions + (tally.cell - origin.tally.cell) + (tally.stale - origin.tally.stale) +
               (tally.grazes - origin.tally.grazes);
  return out;
}

}  // namespace shaker::md
