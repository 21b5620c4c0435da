// `shaker md CASE.toml`: configuration -> initial state -> protocol -> run file.
#include "md/run_md.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

#include "common/case_parameters.hpp"
#include "common/checkpoints.hpp"
#include "common/errors.hpp"
#include "common/output_paths.hpp"
#include "common/packed_fields.hpp"
#include "common/progress.hpp"
#include "common/ranks.hpp"
#include "common/run_file.hpp"
#include "common/terminal_log.hpp"
#include "md/checkpoint.hpp"
#include "md/initial_states.hpp"
#include "md/particle_file.hpp"
#include "md/protocol.hpp"
#include "md/setup.hpp"

namespace shaker::md {
namespace {

std::string variant_name(const Restitution& r, const MdSettings& s) {
  const std::string model = r.kind == Restitution::Kind::constant
                                ? fmt::format("constant e = {}", r.e)
                                : std::string("velocity-dependent e(v_n)");
  const std::string guard = s.tc_guard ? fmt::format("TC guard t_c = {:g}", s.tc) : "no guard";
  return model + ", " + guard;
}

/// What a continued run takes from its checkpoint besides the simulation's state.
struct Resumed {
  SchedulePosition position;
  SampledCycles sampled;
  RunProtocol written_by;  ///< the protocol of the run that wrote the checkpoint
};

/// How messages name the particle file a run starts from.
std::string initial_file_source(const MdSettings& s) { return fmt::format("md.initial_file = \"{}\"", s.initial_file); }

/// Frame md.initial_frame of md.initial_file: its particles, at its time. InputError unless the
/// file holds layer.particles particles in a box of md.box_width, all inside this run's box
/// (above its plate at that time) and none overlapping.
State state_from_file(const CaseParameters& c, const MdSettings& s, const Geometry& g) {
  const std::string source = initial_file_source(s);
  StoredFrame stored = read_particle_frame(s.initial_file, s.initial_frame, source);
  const ParticleFrame& frame = stored.frame;
  const std::string which = fmt::format("{} (frame {} of {}, t = {})", source, stored.index, stored.frames, frame.time);
  if (frame.r.size() != static_cast<std::size_t>(c.particles))
    throw InputError(fmt::format("layer.particles = {} but {} holds {} particles; allowed: layer.particles = {}",
                                 c.particles, which, frame.r.size(), frame.r.size()));
  const auto same = [](double edge, double length) { return std::fabs(edge - length) <= 1e-12 * length; };
  if (!same(stored.edges[0], g.width) || !same(stored.edges[1], g.depth))
    throw InputError(fmt::format("md.box_width = {} and md.box_depth = {} but {} was written in a box of {} x {} "
                                 "(particles/all/box/edges); allowed: md.box_width = {} and md.box_depth = {}, "
                                 "the periodic box of the file's particles", g.width, g.depth, which, stored.edges[0],
                                 stored.edges[1], stored.edges[0], stored.edges[1]));
  SimulationData data;
  data.time = frame.time;
  for (std::size_t i = 0; i < frame.r.size(); ++i) data.particles.push_back(Particle{frame.r[i], frame.v[i], frame.time});
  try {
    validate_state(g, data);
  } catch (const InputError& error) {
    throw InputError(fmt::format("{} cannot start this run: {}", which, error.what()));
  }
  return State{data.time, std::move(data.particles), {}};
}

/// The simulation at the case's initial state, or at the checkpoint `restart_from` (whose
/// schedule position and sampled sums go to `resumed`).
Simulation make_simulation(const config::Config& config, const CaseParameters& c, const MdSettings& s,
                           const Geometry& g, const CollisionRules& rules,
                           const std::filesystem::path& restart_from, std::optional<Resumed>& resumed) {
  const auto n = static_cast<std::size_t>(c.particles);
  if (restart_from.empty()) {
    if (s.initial_state == "file") return Simulation(g, rules, state_from_file(c, s, g), s.queue);
    if (s.initial_state == "gas")
      return Simulation(g, rules, homogeneous_gas(g, n, s.gas_volume_fraction, s.gas_temperature, c.run.seed),
                        s.queue);
    return Simulation(g, rules, flat_layer(g, n, c.run.seed, s.initial_perturbation), s.queue);
  }
  Checkpoint saved = read_checkpoint(restart_from);
  const std::string source = restart_source(restart_from);
  if (saved.data.particles.size() != n)
    throw InputError(fmt::format("layer.particles = {} but the checkpoint {} holds {} particles; "
                                 "allowed: {}", n, source, saved.data.particles.size(),
                                 saved.data.particles.size()));
  // The restart rule (README); another box is allowed (see below). The schedule's times
  // are counted in the checkpoint's cycles; the plate's amplitude (shaker.gamma) sets the
  // saved cell grid's lowest row.
  config::require_same_keys(config, saved.configuration, config::restart_md, source);
  try {
    validate_state(g, saved.data);
  } catch (const InputError& error) {
    throw InputError(fmt::format("{} is not a valid checkpoint: {}", source, error.what()));
  }
  resumed = Resumed{saved.position, std::move(saved.sampled),
                    CaseParameters::from(config::Config::from_toml(saved.configuration, source)).run};
  if (saved.width == g.width && saved.depth == g.depth && saved.height == g.height)
    return Simulation(g, rules, std::move(saved.data), s.queue);
  // Another box: keep the particles, rebuild cells and events (not a bit-for-bit restart).
  State state{saved.data.time, std::move(saved.data.particles), std::move(saved.data.last_collision)};
  return Simulation(g, rules, state, s.queue);
}

/// The MD's schedule: a new one from the simulation's time, or the checkpoint's, continued.
PhaseSchedule schedule_of(const CaseParameters& c, const Simulation& simulation,
                          const std::optional<Resumed>& resume, const std::filesystem::path& restart_from) {
  if (!resume) return PhaseSchedule::whole_cycles(c.run, c.shaker, simulation.time());
  PhaseSchedule schedule = PhaseSchedule::whole_cycles(c.run, c.shaker, resume->position.start_time);
  schedule.resume_at(resume->position, simulation.time(), restart_source(restart_from));
  schedule.check_switch(resume->written_by, simulation.time(), restart_source(restart_from));
  return schedule;
}

/// Collisions counted over one span of simulated time.
struct CollisionCounts {
  double pair = 0.0, plate = 0.0, ceiling = 0.0, guard_activations = 0.0;
  double total() const { return pair + plate + ceiling; }
  CollisionCounts& operator+=(const CollisionCounts& o) {
    pair += o.pair, plate += o.plate, ceiling += o.ceiling, guard_activations += o.guard_activations;
    return *this;
  }
};

/// What the root rank needs of a replica: its samples, its time series and the numbers of the
/// summary. Sent between ranks as doubles (counts stay exact below 2^53); the series' column
/// names, the same for every replica, are not sent.

struct ReplicaSummary {
  CycleSamples samples;
  TimeSeries series;
  double time = 0.0, seconds = 0.0, events = 0.0, overlaps = 0.0;
  /// Since the start of this run, and since the start of the run that wrote the first
  /// checkpoint (the same unless this run continues one: the tally is continued).
  CollisionCounts this_run, since_first_start;
  EnergyBalance budget;
  bool queue_consistent = false;

  /// The numbers of the summary, in the order they travel.
  template <class Self> static auto scalars(Self& s) {
    return std::tie(s.time, s.seconds, s.events, s.overlaps, s.this_run.pair, s.this_run.plate, s.this_run.ceiling,
                    s.this_run.guard_activations, s.since_first_start.pair, s.since_first_start.plate,
                    s.since_first_start.ceiling, s.since_first_start.guard_activations, s.budget.drive_work,
                    s.budget.collisional_loss, s.budget.energy_change, s.budget.relative_residual,
                    s.queue_consistent);
  }

  void pack(std::vector<double>& out) const {
    pack_fields(out, scalars(*this));
    out.insert(out.end(), {static_cast<double>(samples.phases()), static_cast<double>(samples.bins()),
                           samples.bin_volume()});
    for (std::size_t k = 0; k < samples.phases(); ++k) {
      out.push_back(static_cast<double>(samples.samples(k)));
      out.insert(out.end(), samples.cycles(k).begin(), samples.cycles(k).end());
      for (const BinSums& b : samples.sums(k)) out.insert(out.end(), {b.count, b.vx, b.vy, b.vz, b.v2});
    }
    // The single shock's replicas run different numbers of cycles: each sends its row count.
    const std::size_t rows = series.columns.empty() ? 0 : series.columns.front().size();
    out.insert(out.end(), {static_cast<double>(series.columns.size()), static_cast<double>(rows)});
    for (const std::vector<double>& column : series.columns) out.insert(out.end(), column.begin(), column.end());
  }
  /// The summary packed at `at`, its series' columns named `names` (replica 0's).
  static ReplicaSummary unpack(const double*& at, const std::vector<std::string>& names) {
    ReplicaSummary r;
    unpack_fields(at, scalars(r));
    const auto phases = static_cast<std::size_t>(*at++), bins = static_cast<std::size_t>(*at++);
    const double bin_volume = *at++;
    std::vector<std::vector<double>> cycles(phases);
    std::vector<std::vector<BinSums>> sums(phases);
    for (std::size_t k = 0; k < phases; ++k) {
      const auto n = static_cast<std::size_t>(*at++);
      cycles[k].assign(at, at + n);
      at += n;
      sums[k].resize(n * bins);
      for (BinSums& b : sums[k]) b = {at[0], at[1], at[2], at[3], at[4]}, at += 5;
    }
    r.samples = CycleSamples::from_arrays(bins, bin_volume, std::move(cycles), std::move(sums));
    const auto columns = static_cast<std::size_t>(*at++), rows = static_cast<std::size_t>(*at++);
    if (columns != names.size())
      throw std::logic_error(fmt::format("a replica's time series has {} columns, replica 0's {}",
                                         columns, names.size()));
    for (const std::string& name : names) {
      r.series.add(name, std::vector<double>(at, at + rows));
      at += rows;
    }
    return r;
  }
};

ReplicaSummary summary_of(const Simulation& simulation, const RunOutcome& outcome) {
  ReplicaSummary r;
  r.samples = outcome.samples;
  r.series = outcome.series;
  r.time = simulation.time();
  r.seconds = outcome.seconds;
  r.events = static_cast<double>(outcome.events);
  const Tally& now = simulation.tally();
  const Tally& start = outcome.at_start;
  const auto counts = [](std::uint64_t pair, std::uint64_t plate, std::uint64_t ceiling, std::uint64_t guard) {
    return CollisionCounts{static_cast<double>(pair), static_cast<double>(plate),
                           static_cast<double>(ceiling), static_cast<double>(guard)};
  };
  r.since_first_start = counts(now.pair, now.plate, now.ceiling, now.guard_activations);
  r.this_run = counts(now.pair - start.pair, now.plate - start.plate, now.ceiling - start.ceiling,
                      now.guard_activations - start.guard_activations);
  r.overlaps = static_cast<double>(outcome.overlaps);
  r.budget = outcome.budget;
  r.queue_consistent = outcome.queue_consistent;
  return r;
}

std::uint64_t count(double x) { return static_cast<std::uint64_t>(x); }

/// The summary of all replicas: sums of the counts, the worst energy closure.
ReplicaSummary combined(const std::vector<ReplicaSummary>& replicas) {
  ReplicaSummary all;
  all.time = replicas.front().time;
  all.queue_consistent = true;
  for (const ReplicaSummary& r : replicas) {
    all.this_run += r.this_run;
    all.since_first_start += r.since_first_start;
    for (auto [into, x] : {std::pair{&all.seconds, r.seconds}, {&all.events, r.events},
                           {&all.overlaps, r.overlaps}, {&all.budget.drive_work, r.budget.drive_work},
                           {&all.budget.collisional_loss, r.budget.collisional_loss},
                           {&all.budget.energy_change, r.budget.energy_change}})
      *into += x;
    all.budget.relative_residual = std::max(all.budget.relative_residual, r.budget.relative_residual);
    all.queue_consistent = all.queue_consistent && r.queue_consistent;
  }
  return all;
}


/// What this rank's replicas leave: their summaries packed for the root, and replica 0's
/// profiles, series and particle snapshots (the run file's own).
struct RankRuns {
  std::vector<double> packed;
  RunRecord first;
  std::vector<ParticleFrame> frames;
};

/// Runs replica r (on its own configuration) and adds its results to `runs`.
void run_replica(const config::Config& config, const MdCase& c, std::int64_t r,
                 const ProgressSettings& progress_settings, RankRuns& runs) {
  const config::Config replica = replica_configuration(config, r);
  const CaseParameters parameters = CaseParameters::from(replica);
  const std::filesystem::path& restart_from = c.checkpoints.restart_from;
  std::optional<Resumed> resume;
  Simulation simulation = make_simulation(replica, parameters, c.settings, c.geometry, c.rules, restart_from, resume);
  const PhaseSchedule schedule = schedule_of(parameters, simulation, resume, restart_from);
  PhaseSampler sampler = make_sampler(simulation, schedule, c.settings);
  if (resume) take_up_samples(sampler, resume->sampled, resume->position, schedule, restart_source(restart_from));
  ProgressReport progress(c.replicas == 1 ? "shaker md" : fmt::format("shaker md replica {}", r), "collisions/s",
                          [&] { return static_cast<double>(simulation.tally().collisions()); }, progress_settings);
  std::vector<RunObserver*> also{&progress};
  // A checkpoint holds one replica (md_case checks it): a signal stops an ensemble at once.
  std::optional<CheckpointObserver> checkpointing;
  if (c.replicas == 1) {
    checkpointing.emplace(
        c.checkpoints, schedule,
        [&](const std::filesystem::path& path, const SchedulePosition& position) {
          write_checkpoint(path, simulation.save(), c.geometry, position, c.configuration,
                           SampledCycles{sampler.store(), schedule.transient_cycles()});
        },
        "shaker md");
    also.push_back(&*checkpointing);
  }
  if (r == 0) terminal_log::start(c.parameters.run, c.configuration);  // the inputs are accepted
  // Replica 0 alone takes particle snapshots (the files hold one run's frames).
  MdSettings settings = c.settings;
  if (r != 0) settings.snapshot_phases.clear(), settings.snapshot_cycles.clear();
  const RunOutcome outcome = run_protocol(simulation, schedule, sampler, parameters, settings, also);
  summary_of(simulation, outcome).pack(runs.packed);
  if (r == 0) {
    runs.first.profiles = outcome.profiles;
    runs.first.series = outcome.series;
    runs.frames = outcome.frames;
  }
}

/// The replicas' summaries in replica order (replica r ran on rank r mod P).
std::vector<ReplicaSummary> replica_summaries(const std::vector<std::vector<double>>& gathered,
                                              std::int64_t replicas, const std::vector<std::string>& names) {
  std::vector<ReplicaSummary> summaries(static_cast<std::size_t>(replicas));
  for (std::size_t rank = 0; rank < gathered.size(); ++rank) {
    const double* at = gathered[rank].data();
    for (std::size_t r = rank; r < summaries.size(); r += gathered.size())
      summaries[r] = ReplicaSummary::unpack(at, names);
  }
  return summaries;
}

/// The run file's record: the replicas pooled, labelled with the model that produced them.
RunRecord pooled_record(const MdCase& c, const RunRecord& first, std::vector<ReplicaSummary>& summaries) {
  std::vector<RunRecord> pooled(summaries.size(), first);
  for (std::size_t r = 0; r < summaries.size(); ++r) pooled[r].samples = summaries[r].samples;
  RunRecord record = pool_runs(pooled);
  // Replica 0's series stays where a single run's is; the others follow in replica order.
  for (std::size_t r = 1; r < summaries.size(); ++r) record.replica_series.push_back(std::move(summaries[r].series));
  record.solver = "md";
  const RunProtocol& run = c.parameters.run;
  const bool switched = run.kind == RunProtocol::Kind::single_shock;
  const Restitution& final_restitution = switched ? run.after_switch : c.parameters.restitution;
  record.model_variant = variant_name(final_restitution, c.settings);
  if (switched)
    record.model_variant += fmt::format(" (switched from {} at f t = {})", variant_name(c.parameters.restitution, c.settings),
                                        run.switch_phase);
  if (c.replicas > 1) record.model_variant += fmt::format(" (pooled over {} replicas)", c.replicas);
  record.configuration = c.configuration;
  record.e = final_restitution.e;
  return record;
}

/// The summary on stdout (and in the log); returns the exit code of the end-of-run check.
int report_run(const MdCase& c, const ReplicaSummary& all, std::size_t frames, double wall_seconds) {
  const RunProtocol& run = c.parameters.run;
  const bool switched = run.kind == RunProtocol::Kind::single_shock;
  terminal_log::say(stdout, "shaker md: {} particles, {} cycles, t = {:.6g}, wall time {}\n", c.parameters.particles,
                    run.transient_cycles + (switched ? 1 : run.sampled_cycles), all.time, duration_text(wall_seconds));
  if (c.replicas > 1)
    terminal_log::say(stdout, "  {} replicas on {} rank(s); counts below are summed over replicas, the closure "
                      "is the worst\n", c.replicas, Ranks::world().size());
  // A continued run's tally holds the running totals of the runs before it: each count is
  // printed once over this run and once over all, labelled, so that no total mixes the two.
  const bool continued = !c.checkpoints.restart_from.empty();
  const std::string here = continued ? " in this continuation" : "";
  const auto print_counts = [](const std::string& span, const CollisionCounts& n) {
    terminal_log::say(stdout, "  collisions{}: {} (pair {}, plate {}, ceiling {}), collapse guard activations {}\n",
                      span, count(n.total()), count(n.pair), count(n.plate), count(n.ceiling),
                      count(n.guard_activations));
  };
  print_counts(here, all.this_run);
  if (continued) print_counts(" since the start of the run that wrote the first checkpoint", all.since_first_start);
  terminal_log::say(stdout, "  rates{}: {:.4g} collisions/s, {:.4g} events/s\n", here,
                    all.this_run.total() / all.seconds, all.events / all.seconds);
  terminal_log::say(stdout, "  energy budget{}: plate work {:.10g}, collisional loss {:.10g}, energy change {:.10g}, "
                    "relative closure {:.3g}\n", here, all.budget.drive_work, all.budget.collisional_loss,
                    all.budget.energy_change, all.budget.relative_residual);
  terminal_log::say(stdout, "  overlaps at end: {}; event queue consistent: {}\n", count(all.overlaps),
                    all.queue_consistent ? "yes" : "NO");
  terminal_log::say(stdout, "  output: {}\n", run.output);
  if (frames > 0)
    terminal_log::say(stdout, "  particle snapshots: {} frames in {} and {}\n", frames,
                      particle_h5_path(run.output).string(), particle_xyz_path(run.output).string());
  const bool ok = all.overlaps == 0 && all.queue_consistent && all.budget.relative_residual <= 1e-9;
  if (!ok) terminal_log::say(stderr, "shaker md: end-of-run invariant check FAILED (see summary)\n");
  return ok ? 0 : 1;
}

}  // namespace

int run(const config::Config& config, const std::vector<NamedPath>& inputs,
        const ProgressSettings& progress_settings) {
  const Stopwatch wall;
  const MdCase c = md_case(config, inputs);
  // Replica r runs on rank r mod P, and the root pools them in replica order, so the file does
  // not depend on P.
  const Ranks& ranks = Ranks::world();
  ProgressSettings progress_of_rank = progress_settings;
  progress_of_rank.quiet = progress_settings.quiet || !ranks.root();
  RankRuns mine;
  for (std::int64_t r = ranks.rank(); r < c.replicas; r += ranks.size())
    run_replica(config, c, r, progress_of_rank, mine);
  const std::vector<std::vector<double>> gathered = ranks.gather(mine.packed);
  if (!ranks.root()) return 0;

  std::vector<ReplicaSummary> summaries = replica_summaries(gathered, c.replicas, mine.first.series.names);
  const ReplicaSummary all = combined(summaries);
  const RunRecord record = pooled_record(c, mine.first, summaries);
  if (!mine.frames.empty())
    write_particle_files(c.parameters.run.output, mine.frames, ParticleBox{c.geometry.width, c.geometry.depth, c.geometry.height},
                         record);
  write_run_file(c.parameters.run.output, record);
  return report_run(c, all, mine.frames.size(), wall.seconds());
}

}  // namespace shaker::md
