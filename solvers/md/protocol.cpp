#include "md/protocol.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "common/errors.hpp"
#include "common/series_recorder.hpp"
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

/// The running totals of the MD's energy budget (no temperature floor).
EnergyTotals energy_totals(const Tally& tally, double energy) {
  return EnergyTotals{energy, tally.plate_work, tally.pair_loss + tally.wall_loss, std::nullopt};
}

EnergyTotals energy_totals(const Simulation& sim, double t) {
  return energy_totals(sim.tally(), sim.kinetic_energy(t) + sim.potential_energy(t));
}

/// The rows of RunOutcome::series: one at every stored phase and one at the end of the run.
class SeriesObserver final : public RunObserver {
 public:
  SeriesObserver(Simulation& sim, const ShakerKinematics& shaker, const MdSettings& settings,
                 const Tally& at_start, PhaseSnapshot& snapshot)
      : sim_(sim), shaker_(shaker), settings_(settings), at_start_(at_start), snapshot_(snapshot) {
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
    const Tally& tally = sim_.tally();
    rows_.set("t", t);
    rows_.set("phase", shaker_.phase(t));
    rows_.set("plate_z", plate_z);
    rows_.set("com_z", com / static_cast<double>(sim_.size()));
    rows_.set("kinetic_energy", kinetic);
    rows_.set("potential_energy", potential);
    rows_.set_energy(energy_totals(tally, kinetic + potential));
    rows_.set("pair_collisions", static_cast<double>(tally.pair));
    rows_.set("plate_collisions", static_cast<double>(tally.plate));
    rows_.set("ceiling_collisions", static_cast<double>(tally.ceiling));
    rows_.set("cell_crossings", static_cast<double>(tally.cell));
    rows_.set("guard_activations", static_cast<double>(tally.guard_activations));
    rows_.set("overlaps", static_cast<double>(sim_.count_overlaps(r, 1e-9)));
    rows_.set("near_plate", near_plate);
    rows_.set("collisions", static_cast<double>(tally.pair - at_start_.pair));
    rows_.set("queue_consistent", sim_.queue_consistent() ? 1.0 : 0.0);
    const std::vector<std::uint64_t> crossings = sim_.crossings_at(t), distinct = sim_.distinct_particles_at(t);
    for (std::size_t k = 0; k < settings_.crossing_heights.size(); ++k)
      rows_.set(crossing_column(settings_.crossing_heights[k]), static_cast<double>(crossings[k]));
    for (std::size_t k = 0; k < settings_.crossing_heights.size(); ++k)
      rows_.set(distinct_particles_column(settings_.crossing_heights[k]), static_cast<double>(distinct[k]));
    rows_.end_row();
  }

  const Simulation& sim_;
  const ShakerKinematics& shaker_;
  const MdSettings& settings_;
  const Tally& at_start_;
  PhaseSnapshot& snapshot_;
  SeriesRecorder rows_;
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
  const Tally at_start = sim.tally();
  const EnergyTotals start_totals = energy_totals(sim, sim.time());
  PhaseSnapshot snapshot(sim);
  SeriesObserver series(sim, parameters.shaker, settings, at_start, snapshot);
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
  out.budget = balance(start_totals, energy_totals(sim, end));
  out.overlaps = sim.count_overlaps(end, 1e-9);
  out.queue_consistent = sim.queue_consistent();
  const Tally& tally = sim.tally();
  out.at_start = at_start;
  out.collisions = tally.collisions() - at_start.collisions();
  out.events = out.collisions + (tally.cell - at_start.cell) + (tally.stale - at_start.stale) +
               (tally.grazes - at_start.grazes);
  return out;
}

}  // namespace shaker::md
