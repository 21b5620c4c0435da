#pragma once
// An MD run: the run loop of common/run_loop.hpp (transient then sampled cycles, or the
// paper's single shock) drives the simulation, and the MD's observers record the profiles
// (PhaseSampler) and the time series. Recording never changes the trajectory: it reads
// particle states at the sampling instants without touching the particles.
#include <string>
#include <vector>

#include "common/case_parameters.hpp"
#include "common/config.hpp"
#include "common/profile.hpp"
#include "common/run_loop.hpp"
#include "common/series_recorder.hpp"
#include "md/particle_file.hpp"
#include "md/sampling.hpp"
#include "md/simulation.hpp"

namespace shaker::md {

/// The md.* keys, typed.
struct MdSettings {
  double ceiling = 200.0;
  double bin_height = 1.0;
  std::string initial_state = "flat_layer";
  double gas_volume_fraction = 0.1, gas_temperature = 1.0;
  double initial_perturbation = 0.0;  ///< flat layer: largest random lift of a column of sites
  bool tc_guard = false;
  double tc = 1e-5;
  QueueKind queue = QueueKind::calendar;
  std::vector<double> crossing_heights{80.0};
  std::string initial_file;         ///< md.initial_state = "file": the H5MD particle file
  std::int64_t initial_frame = -1;  ///< and its frame (negative: from the end)
  /// md.snapshot_phases as stored phases k and md.snapshot_cycles as cycles from 0, both
  /// increasing; both empty (the default): no particle snapshots.
  std::vector<std::int64_t> snapshot_phases, snapshot_cycles;
  /// InputError for a snapshot phase that is not a stored phase, a cycle the run does not have,
  /// or only one of the two lists given.
  static MdSettings from(const config::Config& config);
};

/// Name of the time-series column counting upward crossings of `height`: crossings_z80.
std::string crossing_column(double height);
/// Name of the time-series column counting distinct particles per cycle at or above `height`:
/// particles_z80.
std::string distinct_particles_column(double height);

struct RunOutcome {
  std::vector<Profile> profiles;
  CycleSamples samples;  ///< the per-cycle sums behind the profiles
  /// One row per sampling instant (every phase of every cycle, and the end of the run):
  /// t, phase, plate_z, com_z (centre of mass), kinetic_energy, potential_energy (g z, lab
  /// frame), the energy budget's columns (SeriesRecorder::set_energy: the drive is the plate,
  /// the loss that of pair and wall collisions), pair/plate/ceiling_collisions and
  /// cell_crossings (running totals), guard_activations, overlaps (pairs closer than 1 - 1e-9), near_plate (particles
  /// less than half a diameter above the plate), collisions (pair collisions since the start
  /// of this run), queue_consistent (1 if the event queue passes Simulation::queue_consistent
  /// at the row's time, else 0: the soak test's per-cycle check), crossings_z<h> for each h of
  /// md.crossing_heights (upward crossings of the
  /// lab-frame height h by any particle since the start of this run, exact: each free flight
  /// is checked at the particle's updates, flights under way up to the row's time), and
  /// particles_z<h> for each h (summed over the cycles since the start of this run: the
  /// distinct particles at or above h at some instant of the cycle, exact in the same way; the
  /// difference between the rows at two consecutive cycle boundaries is that cycle's count).
  TimeSeries series;
  EnergyBalance budget;  ///< from the start of this run to its end
  std::size_t overlaps = 0;  ///< at the end of the run
  bool queue_consistent = false;
  /// Every particle at the stored phases MdSettings::snapshot_phases of its snapshot_cycles,
  /// in time order (empty without snapshots).
  std::vector<ParticleFrame> frames;
  double seconds = 0.0;      ///< wall-clock time of the event loop
  std::uint64_t collisions = 0, events = 0;  ///< in this run
  /// The simulation's running totals when this run started: zero, or those of the checkpoint
  /// it continues (the tally is continued across checkpoints).
  Tally at_start;
};

/// The simulation as the run loop drives it.
class DrivenSimulation final : public DrivenSolver {
 public:
  explicit DrivenSimulation(Simulation& simulation) : simulation_(simulation) {}
  double time() const override { return simulation_.time(); }
  void advance_to(double t) override { simulation_.advance_to(t); }
  void switch_restitution(const Restitution& after) override { simulation_.set_restitution(after); }

 private:
  Simulation& simulation_;
};

/// Runs the case's protocol from the simulation's state; `also` observe the run besides the
/// MD's own recorders (progress, checkpoints), after them.
RunOutcome run_protocol(Simulation& simulation, const CaseParameters& parameters,
                        const MdSettings& settings, const std::vector<RunObserver*>& also = {});
/// The same on a given schedule (a continued run's).
RunOutcome run_protocol(Simulation& simulation, const PhaseSchedule& schedule, const CaseParameters& parameters,
                        const MdSettings& settings, const std::vector<RunObserver*>& also = {});
/// The same, sampling into `sampler` (which a continued run takes up from its checkpoint, and
/// whose sums the checkpoints keep).
RunOutcome run_protocol(Simulation& simulation, const PhaseSchedule& schedule, PhaseSampler& sampler,
                        const CaseParameters& parameters, const MdSettings& settings,
                        const std::vector<RunObserver*>& also = {});
/// The sampler of a run of `schedule` in the simulation's box.
PhaseSampler make_sampler(const Simulation& simulation, const PhaseSchedule& schedule, const MdSettings& settings);

}  // namespace shaker::md
