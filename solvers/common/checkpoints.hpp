#pragma once
// Checkpoints of both solvers as an observer of the run loop, in the manner of progress: the
// periodic ones (every run.checkpoint_every cycles), the final one, and the one a stop signal
// (SIGTERM, SIGINT) asks for, after which the program exits with 128 + signal. Every
// checkpoint records its schedule position, so a run continued from it (run.restart_from)
// meets the target times of the run that wrote it. Each file is written atomically; the one a
// new checkpoint replaces is kept as NAME.previous.h5, so the last two are always on disk.
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "common/hdf5_file.hpp"
#include "common/output_paths.hpp"
#include "common/run_loop.hpp"
#include "common/signals.hpp"

namespace shaker {

/// The allowed run.checkpoint_every, cycles: 0 writes no periodic checkpoint.
inline constexpr config::Range checkpoint_every_range{0.0, 1e6, false, false};

/// The run.* keys of checkpoints, typed.
struct CheckpointSettings {
  std::filesystem::path restart_from;  ///< run.restart_from: the checkpoint to continue from
  std::filesystem::path file;          ///< run.checkpoint: where checkpoints go (empty: none)
  std::int64_t every = 0;              ///< run.checkpoint_every, cycles
  std::filesystem::path run_output;    ///< run.output
  /// Throws InputError for periodic checkpoints without a file to write them to.
  static CheckpointSettings from(const config::Config& config);
  /// Where a stop signal's checkpoint goes: run.checkpoint, else OUTPUT.checkpoint.h5.
  std::filesystem::path stop_file() const;
  /// Every file checkpoints may write, named for check_output_paths.
  std::vector<NamedPath> outputs() const;
  /// Checks `written` (the solver's other outputs) and the checkpoint files against each other
  /// and against `inputs` and run.restart_from; the newest checkpoint alone may be the file the
  /// run continues from (which is then kept as the previous checkpoint).
  void check_paths(std::vector<NamedPath> written, const std::vector<NamedPath>& inputs) const;
};

/// How messages name the checkpoint read: run.restart_from = "PATH".
std::string restart_source(const std::filesystem::path& path);

/// The name the checkpoint before the newest is kept under: NAME.previous.h5.
std::filesystem::path previous_checkpoint(std::filesystem::path file);

/// The root attributes every checkpoint carries besides its solver's state.
void write_checkpoint_header(hid_t file, const std::string& kind, const SchedulePosition& position,
                             const std::string& configuration);
/// Opens run.restart_from = `path` for reading; InputError naming the key if it is missing, not
/// HDF5, or not a checkpoint of `kind` ("shaker md checkpoint"), e.g. of the other solver.
h5::Handle open_checkpoint(const std::filesystem::path& path, const std::string& kind);
/// The position a checkpoint records; InputError if absent or out of range.
SchedulePosition read_schedule_position(hid_t file);

/// Writes the solver's checkpoint of `position` to a file (atomically).
using CheckpointWriter = std::function<void(const std::filesystem::path&, const SchedulePosition&)>;

/// How the ranks of one decomposed run stop together. A launcher delivers a stop signal to its
/// ranks at different steps (or to one rank only), so at each stored phase every rank takes the
/// signal any rank received (`agree`: a reduction over the ranks, called by all alike), and
/// all stop there; only the `writer` touches checkpoint files. One process: the defaults.
struct StopAcrossRanks {
  std::function<int(int)> agree = [](int signal) { return signal; };
  bool writer = true;
  /// Called by every rank before the checkpoint of a stop between stored phases (a decomposed
  /// run gathers its blocks there, as it does at every stored phase).
  std::function<void()> before_stop_between = [] {};
};

/// Besides the stored phases, the observer is asked before each solver step whether to stop
/// (StopBetweenPhases): a solver that can end between phases (the continuum, at a step) stops
/// within a step of the signal, well inside a launcher's grace before it kills the ranks.
class CheckpointObserver final : public RunObserver, public StopBetweenPhases {
 public:
  /// `label` starts the stop message ("shaker md"). While the observer lives, SIGTERM and SIGINT
  /// are deferred to the next stored phase (DeferredStop).
  CheckpointObserver(const CheckpointSettings& settings, const PhaseSchedule& schedule,
                     CheckpointWriter write, std::string label, StopAcrossRanks ranks = {});

  void at_phase(const PhaseInstant& instant) override;
  void at_cycle_end(const CycleEnd& end) override;
  void at_run_end(double t) override;
  bool asked() override;
  [[noreturn]] void stop_between(const SchedulePosition& next, double t) override;
  /// The stored phase the run reaches next: where a failure's last good state continues.
  const SchedulePosition& next() const { return next_; }

 private:
  void save(const std::filesystem::path& path) const;
  /// Throws StopRequested after writing the checkpoint if `signal` (agreed) is not 0.
  void stop_if_asked(double t, int signal) const;
  int signal_between_ = 0;  ///< agreed by asked()

  CheckpointSettings settings_;
  const PhaseSchedule& schedule_;
  CheckpointWriter write_;
  std::string label_;
  StopAcrossRanks ranks_;
  SchedulePosition next_;
  std::optional<DeferredStop> deferred_;
};

}  // namespace shaker
