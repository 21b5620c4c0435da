#pragma once
// Progress of a run on stderr, an observer of the run loop: cycle k of n, simulated time, the
// rate of the solver's own unit of work and the time left. On a terminal one live line is
// rewritten in place; otherwise (a batch job's log) a plain line is written every
// `interval_seconds`, checked at each stored phase so that a slow cycle still reports.
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

#include "common/config.hpp"
#include "common/run_loop.hpp"

namespace shaker {

/// The command-line options `--quiet` and `--progress-interval SECONDS` of `shaker md` and
/// `shaker continuum`.
struct ProgressSettings {
  bool quiet = false;              ///< no progress at all
  double interval_seconds = 30.0;  ///< between plain lines (stderr not a terminal)
  /// Throws InputError naming --progress-interval and its allowed range.
  void validate() const;
};
/// The allowed --progress-interval, seconds: 0 writes a line at every stored phase.
inline constexpr config::Range progress_interval_range{0.0, 86400.0, false, false};

/// Wall-clock seconds since construction.
class Stopwatch {
 public:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

class ProgressReport final : public RunObserver {
 public:
  /// `work` counts the solver's work so far (MD collisions, continuum cell updates), whose
  /// rate is printed per second in `rate_unit`; lines start with `label` ("shaker md").
  /// Writes to stderr, live when it is a terminal.
  ProgressReport(std::string label, std::string rate_unit, std::function<double()> work,
                 const ProgressSettings& settings);
  ProgressReport(std::string label, std::string rate_unit, std::function<double()> work,
                 const ProgressSettings& settings, std::FILE* stream, bool live);

  void at_phase(const PhaseInstant& instant) override;
  void at_run_end(double t) override;

 private:
  void write(double cycles_done, std::int64_t cycle, std::int64_t cycles, double t);

  std::string label_, rate_unit_;
  std::function<double()> work_;
  ProgressSettings settings_;
  std::FILE* stream_;
  bool live_;
  Stopwatch run_, since_line_;
  Stopwatch since_logged_;  ///< the run's log takes a live terminal's lines at the interval only
  double work_at_start_;
  std::int64_t cycles_ = 0;  ///< of the run, from the first instant
  double resumed_at_ = 0.0;  ///< PhaseInstant::resumed_at
};

/// A duration for people: "0.42 s", "42 s", "12.5 min", "3.2 h".
std::string duration_text(double seconds);

}  // namespace shaker
