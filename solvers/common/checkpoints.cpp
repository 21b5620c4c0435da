#include "common/checkpoints.hpp"

#include <fmt/format.h>

#include <cmath>
#include <csignal>
#include <utility>

#include "common/atomic_output.hpp"
#include "common/errors.hpp"
#include "common/output_paths.hpp"
#include "common/signals.hpp"

namespace shaker {

CheckpointSettings CheckpointSettings::from(const config::Config& config) {
  CheckpointSettings s;
  s.restart_from = config.text("run.restart_from");
  s.file = config.text("run.checkpoint");
  s.every = config.integer("run.checkpoint_every");
  s.run_output = config.text("run.output");
  if (s.every > 0 && s.file.empty())
    throw InputError(fmt::format("run.checkpoint_every = {} needs run.checkpoint = the file to write "
                                 "the checkpoints to; allowed: run.checkpoint_every = 0 without "
                                 "run.checkpoint", s.every));
  return s;
}

std::filesystem::path CheckpointSettings::stop_file() const {
  if (!file.empty()) return file;
  return derived_name(run_output, ".checkpoint.h5");
}

std::vector<NamedPath> CheckpointSettings::outputs() const {
  if (!file.empty())
    return {{"run.checkpoint", file}, {"run.checkpoint's previous checkpoint", previous_checkpoint(file)}};
  if (run_output.empty()) return {};  // refused as run.output itself
  return {{"run.output's stop-signal checkpoint", stop_file()},
          {"run.output's previous stop-signal checkpoint", previous_checkpoint(stop_file())}};
}

void CheckpointSettings::check_paths(std::vector<NamedPath> written, const std::vector<NamedPath>& inputs) const {
  const std::vector<NamedPath> own = outputs();
  // The newest checkpoint may replace the one the run continues from (kept as the previous
  // one): all other files are checked against that, then all against the other inputs.
  const bool continues_itself = !own.empty();
  written.insert(written.end(), own.begin() + (continues_itself ? 1 : 0), own.end());
  check_output_paths(written, {{"run.restart_from", restart_from}});
  if (continues_itself) written.push_back(own.front());
  check_output_paths(written, inputs);
}

std::string restart_source(const std::filesystem::path& path) {
  return fmt::format("run.restart_from = \"{}\"", path.string());
}

std::filesystem::path previous_checkpoint(std::filesystem::path file) {
  return derived_name(std::move(file), ".previous.h5");
}

void write_checkpoint_header(hid_t file, const std::string& kind, const SchedulePosition& position,
                             const std::string& configuration) {
  h5::write_attribute(file, "kind", kind);
  h5::write_attribute(file, "configuration", configuration);
  h5::write_attribute(file, "schedule_start_time", position.start_time);
  h5::write_attribute(file, "schedule_cycle", position.cycle);
  h5::write_attribute(file, "schedule_phase", position.phase);
  h5::write_attribute(file, "schedule_phases", position.phases);
}

h5::Handle open_checkpoint(const std::filesystem::path& path, const std::string& kind) {
  if (!std::filesystem::exists(path))
    throw InputError(fmt::format("{}: no such file; allowed: a {} (written by run.checkpoint)",
                                 restart_source(path), kind));
  std::string found;
  h5::Handle file;
  try {
    file = h5::open_file(path);
    if (h5::has_attribute(file.id(), "kind")) found = h5::read_string_attribute(file.id(), "kind");
  } catch (const std::exception& error) {
    throw InputError(fmt::format("{} is not a checkpoint ({}); allowed: a {}", restart_source(path),
                                 error.what(), kind));
  }
  if (found != kind)
    throw InputError(fmt::format("{} is {}; allowed: a {} (written by run.checkpoint)",
                                 restart_source(path), found.empty() ? std::string("not a checkpoint (no attribute 'kind')")
                                                              : "a " + found, kind));
  return file;
}

SchedulePosition read_schedule_position(hid_t file) {
  SchedulePosition p;
  p.start_time = h5::read_double_attribute(file, "schedule_start_time");
  p.cycle = h5::read_integer_attribute(file, "schedule_cycle");
  p.phase = h5::read_integer_attribute(file, "schedule_phase");
  p.phases = h5::read_integer_attribute(file, "schedule_phases");
  if (!std::isfinite(p.start_time))
    throw InputError(fmt::format("attribute 'schedule_start_time' = {}; allowed: a finite time", p.start_time));
  const config::Range phases = config::find_spec("run.phases_per_cycle").range;
  if (!phases.contains(static_cast<double>(p.phases)))
    throw InputError(fmt::format("attribute 'schedule_phases' = {}; allowed: {}", p.phases, phases.describe()));
  if (p.phase < 0 || p.phase >= p.phases)
    throw InputError(fmt::format("attribute 'schedule_phase' = {}; allowed: 0 <= value < {} (schedule_phases)",
                                 p.phase, p.phases));
  // The cycles of a run are at most the sum of the two cycle keys' largest values.
  if (p.cycle < 0 || p.cycle > 2000000)
    throw InputError(fmt::format("attribute 'schedule_cycle' = {}; allowed: 0 <= value <= 2000000", p.cycle));
  return p;
}

namespace {

/// Keeps the checkpoint under `file` as its previous one (atomically, as a hard link where the
/// file system has them), so that a new one may replace it.
void keep_as_previous(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file)) return;
  AtomicOutput previous(previous_checkpoint(file));
  std::error_code no_links;
  std::filesystem::create_hard_link(file, previous.temporary_path(), no_links);
  if (no_links) std::filesystem::copy_file(file, previous.temporary_path());
  previous.commit();
}

}  // namespace

CheckpointObserver::CheckpointObserver(const CheckpointSettings& settings, const PhaseSchedule& schedule,
                                       CheckpointWriter write, std::string label, StopAcrossRanks ranks)
    : settings_(settings),
      schedule_(schedule),
      write_(std::move(write)),
      label_(std::move(label)),
      ranks_(std::move(ranks)),
      next_(schedule.start()),
      deferred_(std::in_place) {}

void CheckpointObserver::at_phase(const PhaseInstant& instant) {
  next_ = instant.phase + 1 < instant.phases ? schedule_.position(instant.cycle, instant.phase + 1)
                                             : schedule_.position(instant.cycle + 1, 0);
  stop_if_asked(instant.t, ranks_.agree(DeferredStop::requested()));
}

void CheckpointObserver::at_cycle_end(const CycleEnd& end) {
  if (settings_.every > 0 && (end.cycle + 1) % settings_.every == 0) save(settings_.file);
}

void CheckpointObserver::at_run_end(double t) {
  next_ = schedule_.position(schedule_.cycles(), 0);
  const int signal = ranks_.agree(DeferredStop::requested());
  if (!settings_.file.empty() && signal == 0) save(settings_.file);
  stop_if_asked(t, signal);
  // A signal that came while the final checkpoint was written stops the run after it.
  if (const int late = ranks_.agree(DeferredStop::requested()); late != 0) {
    if (settings_.file.empty()) stop_if_asked(t, late);
    throw StopRequested(late, !ranks_.writer ? std::string() : fmt::format(
        "{}: stopped by signal {} ({}) while the final checkpoint was written, at t = {:.10g}; the "
        "checkpoint {} is complete (at the end of the run's cycles); no run file was written: to "
        "go on, raise run.sampled_cycles and --set run.restart_from={}", label_, late,
        late == SIGINT ? "SIGINT" : "SIGTERM", t, settings_.file.string(), settings_.file.string()));
  }
  // From here on the run writes its outputs: a signal removes them and exits at once.
  deferred_.reset();
}

bool CheckpointObserver::asked() {
  signal_between_ = ranks_.agree(DeferredStop::requested());
  return signal_between_ != 0;
}

void CheckpointObserver::stop_between(const SchedulePosition& next, double t) {
  next_ = next;
  ranks_.before_stop_between();
  stop_if_asked(t, signal_between_);
  throw std::logic_error("CheckpointObserver::stop_between without a stop signal");
}

void CheckpointObserver::save(const std::filesystem::path& path) const {
  if (!ranks_.writer) return;
  keep_as_previous(path);
  write_(path, next_);
}

void CheckpointObserver::stop_if_asked(double t, int signal) const {
  if (signal == 0) return;
  const std::filesystem::path path = settings_.stop_file();
  save(path);
  if (!ranks_.writer) throw StopRequested(signal, "");  // the writer's message is the run's
  throw StopRequested(signal, fmt::format(
      "{}: stopped by signal {} ({}) at t = {:.10g}; checkpoint written to {} (it continues at "
      "stored phase {} of {} in cycle {}, counted from 0); continue the run with --set "
      "run.restart_from={}", label_, signal, signal == SIGINT ? "SIGINT" : "SIGTERM", t, path.string(),
      next_.phase, next_.phases, next_.cycle, path.string()));
}

}  // namespace shaker
