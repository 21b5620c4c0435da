#include "common/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <utility>

#include "common/errors.hpp"
#include "common/terminal_log.hpp"

namespace shaker {
namespace {
// A terminal need not be repainted at every stored phase; twice a second reads as live.
constexpr double live_refresh_seconds = 0.5;
}  // namespace

void ProgressSettings::validate() const {
  if (!progress_interval_range.contains(interval_seconds))
    throw InputError(fmt::format("--progress-interval = {} seconds; allowed: {}", interval_seconds,
                                 progress_interval_range.describe()));
}

std::string duration_text(double seconds) {
  if (seconds < 120.0) return fmt::format("{:.3g} s", seconds);
  if (seconds < 7200.0) return fmt::format("{:.1f} min", seconds / 60.0);
  return fmt::format("{:.1f} h", seconds / 3600.0);
}

ProgressReport::ProgressReport(std::string label, std::string rate_unit, std::function<double()> work,
                               const ProgressSettings& settings)
    : ProgressReport(std::move(label), std::move(rate_unit), std::move(work), settings, stderr,
                     ::isatty(::fileno(stderr)) != 0) {}

ProgressReport::ProgressReport(std::string label, std::string rate_unit, std::function<double()> work,
                               const ProgressSettings& settings, std::FILE* stream, bool live)
    : label_(std::move(label)),
      rate_unit_(std::move(rate_unit)),
      work_(std::move(work)),
      settings_(settings),
      stream_(stream),
      live_(live),
      work_at_start_(work_()) {}

void ProgressReport::at_phase(const PhaseInstant& instant) {
  cycles_ = instant.cycles;
  resumed_at_ = instant.resumed_at;
  // Nothing done yet gives neither a rate nor a time left.
  if (settings_.quiet || instant.cycles_done() <= instant.resumed_at) return;
  if (since_line_.seconds() < (live_ ? live_refresh_seconds : settings_.interval_seconds)) return;
  write(instant.cycles_done(), instant.cycle + 1, instant.cycles, instant.t);
}

void ProgressReport::at_run_end(double t) {
  if (settings_.quiet || cycles_ == 0) return;
  const double cycles = static_cast<double>(cycles_);
  if (live_ || since_line_.seconds() >= settings_.interval_seconds) write(cycles, cycles_, cycles_, t);
  if (live_) fmt::print(stream_, "\n");  // ends the live line; the log has it already
}

void ProgressReport::write(double cycles_done, std::int64_t cycle, std::int64_t cycles, double t) {
  since_line_ = Stopwatch();
  const double elapsed = run_.seconds();
  const double rate = (work_() - work_at_start_) / elapsed;
  // A continued run's pace is that of the cycles this process ran.
  const double left = elapsed / (cycles_done - resumed_at_) * (static_cast<double>(cycles) - cycles_done);
  const std::string line = fmt::format("{}: cycle {} of {}, t = {:.6g}, {:.3g} {}, {} left", label_,
                                       cycle, cycles, t, rate, rate_unit_, duration_text(left));
  // The spaces clear what a longer previous live line left behind.
  if (live_) {
    fmt::print(stream_, "\r{}   ", line);
    std::fflush(stream_);
    if (since_logged_.seconds() >= settings_.interval_seconds || cycles_done >= static_cast<double>(cycles)) {
      since_logged_ = Stopwatch();
      terminal_log::to_log(line + "\n");
    }
  } else {
    terminal_log::print(stream_, line + "\n");
  }
}

}  // namespace shaker
