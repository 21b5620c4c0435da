#pragma once
// Checkpoints: the interior state, the time, the step counters, the e in effect (after a
// single-shock switch the switched e, which a restart takes over instead of the configured
// one) and the accumulated energy budget, in HDF5 (written atomically). Restarting from one continues bit for bit like the uninterrupted run, since
// the step sequence depends only on the state and the target times.
#include <filesystem>
#include <string>

#include "common/run_loop.hpp"
#include "continuum/output.hpp"
#include "continuum/time_integrator.hpp"

namespace shaker::continuum {

inline constexpr const char* checkpoint_kind = "shaker continuum checkpoint";

void write_checkpoint(const std::filesystem::path& path, const BoxView& box,
                      const SchedulePosition& position, const std::string& configuration_toml);
inline void write_checkpoint(const std::filesystem::path& path, const TimeIntegrator& solver,
                             const SchedulePosition& position, const std::string& configuration_toml) {
  write_checkpoint(path, view_of(solver), position, configuration_toml);
}
/// Loads a checkpoint into the solver and returns its schedule position; throws InputError
/// naming run.restart_from ("not a valid checkpoint: ...") if it is not a continuum checkpoint,
/// does not match the grid or holds a damaged value (the solver is then left unchanged).
/// A 1D column's checkpoint also starts a 3D box of the same cell size and ceiling, every
/// column of the box taking the checkpoint's: the box begins in the column's (periodic) state
/// instead of at rest, without the 3D cost of the transient.
SchedulePosition read_checkpoint(const std::filesystem::path& path, TimeIntegrator& solver);
/// The same into a state of `grid` (interior cells) and `scalars`: what the root of a
/// decomposed run reads before scattering it.
SchedulePosition read_checkpoint(const std::filesystem::path& path, const Grid& grid, State& state,
                                 RunScalars& scalars);
/// The effective configuration (TOML) of the run that wrote the checkpoint.
std::string checkpoint_configuration(const std::filesystem::path& path);

}  // namespace shaker::continuum
