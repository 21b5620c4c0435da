#pragma once
// Checkpoints: the complete SimulationData (particles with their local times, pending events,
// collision counters, cell lists, running totals) in an HDF5 file written atomically. A run
// continued from a checkpoint replays the events of an uninterrupted run bit for bit.
#include <filesystem>
#include <string>

#include "common/cycle_samples.hpp"
#include "common/run_loop.hpp"
#include "md/geometry.hpp"
#include "md/simulation.hpp"

namespace shaker::md {

/// The profile sums of the sampled cycles before a checkpoint, for every stored phase (a
/// checkpoint written mid-cycle holds one more cycle at the phases already reached), so that
/// a continued run ends with the profiles of the uninterrupted run. Each phase holds the cycles
/// from first_cycle to the checkpoint's position.
struct SampledCycles {
  CycleSamples sums;
  std::int64_t first_cycle = 0;  ///< the run's first sampled cycle (its run.transient_cycles)
};

struct Checkpoint {
  SimulationData data;
  std::string configuration;  ///< effective configuration of the run that wrote it
  double width = 0.0, depth = 0.0, height = 0.0;  ///< geometry the cell lists belong to
  SchedulePosition position;         ///< where in its run's schedule it was written
  SampledCycles sampled;             ///< no sums before the first sampled cycle
};

inline constexpr const char* checkpoint_kind = "shaker md checkpoint";

void write_checkpoint(const std::filesystem::path& path, const SimulationData& data,
                      const Geometry& geometry, const SchedulePosition& position,
                      const std::string& configuration, const SampledCycles& sampled = {});
/// Throws InputError naming run.restart_from if the file is missing, not an MD checkpoint or
/// malformed (sampled sums included: finite, counts >= 0).
Checkpoint read_checkpoint(const std::filesystem::path& path);

class PhaseSampler;

/// A run continued from a checkpoint at `at` past its first sampled cycle takes up the
/// checkpoint's sums of the cycles sampled before it (`sampled`) into its sampler, so that its
/// profiles are those of the uninterrupted run. InputError (naming `source`) if the sums are
/// not those cycles' in this run's phases and bins.
void take_up_samples(PhaseSampler& sampler, const SampledCycles& sampled, const SchedulePosition& at,
                     const PhaseSchedule& schedule, const std::string& source);

/// Throws InputError naming the particle(s) if a particle lies outside the box (below the
/// plate, above the ceiling, outside [0, width) horizontally) or two particles overlap by more
/// than `tolerance` at time data.time (of a checkpoint, or of a run's initial particles).
void validate_state(const Geometry& geometry, const SimulationData& data, double tolerance = 1e-9);

}  // namespace shaker::md
