#pragma once
// How the program stops on a signal: SIGTERM, SIGINT and SIGHUP remove the temporary files of
// outputs in the making and exit with 128 + signal, unless a run defers the stop to its next
// stored phase, where it writes a checkpoint first.
#include <filesystem>
#include <stdexcept>
#include <string>

namespace shaker {

/// Removes the temporary files of every live AtomicOutput when SIGTERM, SIGINT or SIGHUP
/// arrives, says so on stderr and exits with 128 + signal. The registry is signal safe (fixed
/// slots, no allocation in the handler). Installed once by the program's main.
void install_signal_cleanup();

/// While an object of this class lives (a solver's run loop with its checkpoint observer),
/// SIGTERM and SIGINT only record that a stop was asked for: the run polls requested() at its
/// stored phases, writes a checkpoint there and exits. A second such signal, or SIGHUP, stops at
/// once as install_signal_cleanup says.
class DeferredStop {
 public:
  DeferredStop();
  DeferredStop(const DeferredStop&) = delete;
  DeferredStop& operator=(const DeferredStop&) = delete;
  ~DeferredStop();
  /// The signal that asked for the stop, or 0.
  static int requested();
};

/// A run stopped by SIGTERM or SIGINT after writing its checkpoint: the program exits with
/// 128 + signal.
class StopRequested : public std::runtime_error {
 public:
  StopRequested(int signal, const std::string& message) : std::runtime_error(message), signal_(signal) {}
  int exit_code() const { return 128 + signal_; }

 private:
  int signal_;
};

/// Registers a temporary file for removal by the signal handler: its slot, or -1 when the
/// registry is full or the path too long (the file is then still removed on an exception).
int register_for_cleanup(const std::filesystem::path& path);
/// Frees a slot of register_for_cleanup (-1: nothing).
void unregister_for_cleanup(int slot);

}  // namespace shaker
