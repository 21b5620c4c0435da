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
#include "common/memory.hpp"
#include "common/progress.hpp"
#include "common/ranks.hpp"
#include "common/run_file.hpp"
#include "common/terminal_log.hpp"
#include "md/checkpoint.hpp"
#include "md/initial_states.hpp"
#include "md/particle_file.hpp"
#include "md/protocol.hpp"

namespace shaker::md {
namespace {

Geometry geometry_of(const CaseParameters& c, const MdSettings& s) {
  Geometry g;
  g.width = c.md_box_width;
  g.depth = c.md_box_depth;
  g.height = s.ceiling;
  g.gravity = gravity;
  g.plate = c.shaker;
  // The ceiling must leave room for a particle above the plate at its highest point.
  if (!(s.ceiling > g.plate_top() + 1.0))
    throw InputError(fmt::format(
        "md.ceiling = {} is below the plate's top: it must exceed 2A + 1 = {:.6g} (A = {:.6g} "
        "for shaker.gamma = {} and shaker.frequency = {})",
        s.ceiling, g.plate_top() + 1.0, g.plate.amplitude(), c.shaker.gamma(), c.shaker.frequency()));
  return g;
}

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
  config::require_same_keys(config, saved.configuration,
                            {"material.restitution", "material.e", "shaker.frequency", "shaker.gamma"}, source);
  try {
    validate_state(g, saved.data);
  } catch (const InputError& error) {
    throw InputError(fmt::format("{} is not a valid checkpoint: {}", source, error.what()));
  }
  resumed = Resumed{saved.position, std::move(saved.sampled),
                    CaseParameters::from(config::Config::from_toml(saved.configuration, source)).run};
  if (saved.width == g.width && saved.depth == g.depth && saved.height == g.height) return Simulation(g, rules, std::move(saved.data), s.queue);
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

/// The memory of the particles, the cell list and the phase sampler, before any is allocated.
void check_md_memory(const CaseParameters& c, const MdSettings& s, const Geometry& g) {
  const double n = static_cast<double>(c.particles);
  // Per particle: its state, event, last collision, cell links, queue node, sampled r and v,
  // the flat layer's site list, and the last cycle counted at each crossing height; per cell a
  // list head; per sampling bin and phase the pooled sums (13 doubles) and the profile's
  // fields written out (2 x 9 doubles).
  const double per_particle = sizeof(Particle) + sizeof(Event) + 8.0 + 16.0 + 64.0 + 2.0 * sizeof(Vec3) + 16.0 +
                              4.0 * static_cast<double>(s.crossing_heights.size());
  const double rows = std::min(std::floor(g.height), g.plate_top() + 8.0 * n / (g.width * g.depth) + 3.0);
  const double cells = std::floor(g.width) * std::floor(g.depth) * std::max(rows, 3.0);
  const double bins = std::ceil(s.ceiling / s.bin_height);
  const double phases = static_cast<double>(c.run.phases_per_cycle);
  // Each particle snapshot: r and v kept until the end, and its lines of the XYZ text.
  const double frames = static_cast<double>(s.snapshot_phases.size() * s.snapshot_cycles.size());
  check_memory(n * per_particle + 4.0 * cells + bins * phases * (13.0 + 18.0) * 8.0 + frames * n * (48.0 + 160.0),
               fmt::format("the MD run ({} particles, {:.3g} cells, {:.3g} sampling bins x {} phases, {} "
                           "particle snapshots)", c.particles, cells, bins, c.run.phases_per_cycle, frames),
               "allowed: fewer layer.particles, a larger md.bin_height, a lower md.ceiling, fewer "
               "run.phases_per_cycle or fewer particle snapshots (md.snapshot_phases x md.snapshot_cycles)");
}

/// Every file the run may write, none equal to an input (md.initial_file among them) or to
/// another (checked before work).
void check_paths(const CaseParameters& c, const MdSettings& s, const CheckpointSettings& checkpoints,
                 std::vector<NamedPath> inputs) {
  const std::filesystem::path output = c.run.output;
  std::vector<NamedPath> outputs{{"run.output", output}};
  terminal_log::add_output(outputs, c.run);
  if (!s.snapshot_phases.empty() && !output.empty()) {
    outputs.push_back({"run.output's particle file", particle_h5_path(output)});
    outputs.push_back({"run.output's particle XYZ file", particle_xyz_path(output)});
  }
  if (s.initial_state == "file" && checkpoints.restart_from.empty()) {
    inputs.push_back({"md.initial_file", s.initial_file});
    check_input_file(inputs.back());
  }
  checkpoints.check_paths(outputs, inputs);
}

/// Replica r of the case (md.replicas): the periodic protocol takes seed run.seed + r, the
/// single shock starts r cycles later from run.seed, as repeats of one single shock are pooled.
const char* replica_key(const config::Config& config) {
  return config.text("run.protocol") == "single_shock" ? "run.transient_cycles" : "run.seed";
}

config::Config replica_configuration(const config::Config& config, std::int64_t r) {
  config::Config replica = config;
  replica.set_value("md.replicas", std::int64_t{1});
  replica.set_value(replica_key(config), config.integer(replica_key(config)) + r);
  return replica;
}

void check_replicas(const config::Config& config, const CheckpointSettings& checkpoints) {
  const std::int64_t replicas = config.integer("md.replicas");
  if (replicas == 1) return;
  if (!checkpoints.restart_from.empty() || !checkpoints.file.empty())
    throw InputError(fmt::format("md.replicas = {} with a checkpoint (run.restart_from = \"{}\", "
                                 "run.checkpoint = \"{}\"): a checkpoint holds one replica; "
                                 "allowed: md.replicas = 1 with run.restart_from or run.checkpoint",
                                 replicas, checkpoints.restart_from.string(), checkpoints.file.string()));
  if (config.text("md.initial_state") == "file" && config.text("run.protocol") == "periodic")
    throw InputError(fmt::format("md.replicas = {} with md.initial_state = \"file\" and run.protocol = "
                                 "\"periodic\": every replica would start from the same particles and run "
                                 "the same trajectory; allowed: md.replicas = 1 with md.initial_state = \"file\" "
                                 "(or the single shock, whose replicas differ in their transient)", replicas));
  const auto& spec = config::find_spec(replica_key(config));
  const double last = static_cast<double>(config.integer(spec.key) + replicas - 1);
  if (!spec.range.contains(last))
    throw InputError(fmt::format("md.replicas = {}: replica {} would need {} = {}; allowed: {} "
                                 "{}", replicas, replicas - 1, spec.key, last, spec.key,
                                 spec.range.describe()));
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
  EnergyBudget budget;
  bool queue_consistent = false;

  void pack(std::vector<double>& out) const {
    out.insert(out.end(), {time, seconds, events, overlaps});
    for (const CollisionCounts& c : {this_run, since_first_start})
      out.insert(out.end(), {c.pair, c.plate, c.ceiling, c.guard_activations});
    out.insert(out.end(), {budget.plate_work, budget.collisional_loss, budget.energy_change,
                           budget.relative_closure, queue_consistent ? 1.0 : 0.0,
                           static_cast<double>(samples.phases()), static_cast<double>(samples.bins()),
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
    for (double* x : {&r.time, &r.seconds, &r.events, &r.overlaps})
      *x = *at++;
    for (CollisionCounts* c : {&r.this_run, &r.since_first_start})
      for (double* x : {&c->pair, &c->plate, &c->ceiling, &c->guard_activations}) *x = *at++;
    for (double* x : {&r.budget.plate_work, &r.budget.collisional_loss, &r.budget.energy_change,
                      &r.budget.relative_closure})
      *x = *at++;
    r.queue_consistent = *at++ != 0.0;
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
                           {&all.overlaps, r.overlaps}, {&all.budget.plate_work, r.budget.plate_work},
                           {&all.budget.collisional_loss, r.budget.collisional_loss},
                           {&all.budget.energy_change, r.budget.energy_change}})
      *into += x;
    all.budget.relative_closure = std::max(all.budget.relative_closure, r.budget.relative_closure);
    all.queue_consistent = all.queue_consistent && r.queue_consistent;
  }
  return all;
}

}  // namespace

int run(const config::Config& config, const std::vector<NamedPath>& inputs,
        const ProgressSettings& progress_settings) {
  const Stopwatch wall;
  const CaseParameters parameters = CaseParameters::from(config);
  const MdSettings settings = MdSettings::from(config);
  const Geometry geometry = geometry_of(parameters, settings);
  const CheckpointSettings checkpoints = CheckpointSettings::from(config);
  check_paths(parameters, settings, checkpoints, inputs);
  check_replicas(config, checkpoints);
  check_md_memory(parameters, settings, geometry);
  CollisionRules rules;
  rules.restitution = parameters.restitution;
  rules.tc_guard = settings.tc_guard;
  rules.tc = settings.tc;

  // Replica r runs on rank r mod P, and the root pools them in replica order, so the file does
  // not depend on P.
  const Ranks& ranks = Ranks::world();
  const std::int64_t replicas = config.integer("md.replicas");
  ProgressSettings progress_of_rank = progress_settings;
  progress_of_rank.quiet = progress_settings.quiet || !ranks.root();
  std::vector<double> mine;
  RunRecord record;
  std::vector<ParticleFrame> frames;  // replica 0's
  const std::string configuration = config.to_toml();
  for (std::int64_t r = ranks.rank(); r < replicas; r += ranks.size()) {
    const config::Config replica = replica_configuration(config, r);
    const CaseParameters replica_parameters = CaseParameters::from(replica);
    std::optional<Resumed> resume;
    Simulation simulation =
        make_simulation(replica, replica_parameters, settings, geometry, rules, checkpoints.restart_from, resume);
    const PhaseSchedule schedule = schedule_of(replica_parameters, simulation, resume, checkpoints.restart_from);
    PhaseSampler sampler = make_sampler(simulation, schedule, settings);
    if (resume)
      take_up_samples(sampler, resume->sampled, resume->position, schedule, restart_source(checkpoints.restart_from));
    ProgressReport progress(replicas == 1 ? "shaker md" : fmt::format("shaker md replica {}", r),
                            "collisions/s",
                            [&] { return static_cast<double>(simulation.tally().collisions()); },
                            progress_of_rank);
    std::vector<RunObserver*> also{&progress};
    // A checkpoint holds one replica (check_replicas): a signal stops an ensemble at once.
    std::optional<CheckpointObserver> checkpointing;
    if (replicas == 1) {
      checkpointing.emplace(
          checkpoints, schedule,
          [&](const std::filesystem::path& path, const SchedulePosition& position) {
            write_checkpoint(path, simulation.save(), geometry, position, configuration,
                             SampledCycles{sampler.store(), schedule.transient_cycles()});
          },
          "shaker md");
      also.push_back(&*checkpointing);
    }
    if (r == 0) terminal_log::start(parameters.run, configuration);  // the inputs are accepted
    // Replica 0 alone takes particle snapshots (the files hold one run's frames).
    MdSettings replica_settings = settings;
    if (r != 0) {
      replica_settings.snapshot_phases.clear();
      replica_settings.snapshot_cycles.clear();
    }
    const RunOutcome outcome = run_protocol(simulation, schedule, sampler, replica_parameters, replica_settings, also);
    summary_of(simulation, outcome).pack(mine);
    if (r == 0) {
      record.profiles = outcome.profiles;
      record.series = outcome.series;
      frames = outcome.frames;
    }
  }
  const std::vector<std::vector<double>> gathered = ranks.gather(mine);
  if (!ranks.root()) return 0;

  std::vector<ReplicaSummary> summaries(static_cast<std::size_t>(replicas));
  for (std::size_t rank = 0; rank < gathered.size(); ++rank) {
    const double* at = gathered[rank].data();
    for (std::size_t r = rank; r < summaries.size(); r += gathered.size())
      summaries[r] = ReplicaSummary::unpack(at, record.series.names);
  }
  std::vector<RunRecord> pooled(summaries.size(), record);
  for (std::size_t r = 0; r < summaries.size(); ++r) pooled[r].samples = summaries[r].samples;
  record = pool_runs(pooled);
  // Replica 0's series stays where a single run's is; the others follow in replica order.
  for (std::size_t r = 1; r < summaries.size(); ++r)
    record.replica_series.push_back(std::move(summaries[r].series));
  const ReplicaSummary all = combined(summaries);

  record.solver = "md";
  const bool switched = parameters.run.kind == RunProtocol::Kind::single_shock;
  const Restitution& final_restitution = switched ? parameters.run.after_switch : parameters.restitution;
  record.model_variant = variant_name(final_restitution, settings);
  if (switched) record.model_variant += fmt::format(" (switched from {} at f t = {})",
                                                    variant_name(parameters.restitution, settings),
                                                    parameters.run.switch_phase);
  if (replicas > 1) record.model_variant += fmt::format(" (pooled over {} replicas)", replicas);
  record.configuration = configuration;
  record.e = final_restitution.e;
  if (!frames.empty())
    write_particle_files(parameters.run.output, frames, ParticleBox{geometry.width, geometry.depth, geometry.height}, record);
  write_run_file(parameters.run.output, record);

  terminal_log::say(stdout, "shaker md: {} particles, {} cycles, t = {:.6g}, wall time {}\n", parameters.particles,
             parameters.run.transient_cycles + (switched ? 1 : parameters.run.sampled_cycles),
             all.time, duration_text(wall.seconds()));
  if (replicas > 1)
    terminal_log::say(stdout, "  {} replicas on {} rank(s); counts below are summed over replicas, the closure "
               "is the worst\n", replicas, ranks.size());
  // A continued run's tally holds the running totals of the runs before it: each count is
  // printed once over this run and once over all, labelled, so that no total mixes the two.
  const bool continued = !checkpoints.restart_from.empty();
  const std::string here = continued ? " in this continuation" : "";
  const auto print_counts = [](const std::string& span, const CollisionCounts& c) {
    terminal_log::say(stdout, "  collisions{}: {} (pair {}, plate {}, ceiling {}), collapse guard activations {}\n",
               span, count(c.total()), count(c.pair), count(c.plate), count(c.ceiling),
               count(c.guard_activations));
  };
  print_counts(here, all.this_run);
  if (continued) print_counts(" since the start of the run that wrote the first checkpoint", all.since_first_start);
  terminal_log::say(stdout, "  rates{}: {:.4g} collisions/s, {:.4g} events/s\n", here, all.this_run.total() / all.seconds,
             all.events / all.seconds);
  terminal_log::say(stdout, "  energy budget{}: plate work {:.10g}, collisional loss {:.10g}, energy change {:.10g}, "
             "relative closure {:.3g}\n", here, all.budget.plate_work, all.budget.collisional_loss,
             all.budget.energy_change, all.budget.relative_closure);
  terminal_log::say(stdout, "  overlaps at end: {}; event queue consistent: {}\n", count(all.overlaps),
             all.queue_consistent ? "yes" : "NO");
  terminal_log::say(stdout, "  output: {}\n", parameters.run.output);
  if (!frames.empty())
    terminal_log::say(stdout, "  particle snapshots: {} frames in {} and {}\n", frames.size(),
               particle_h5_path(parameters.run.output).string(), particle_xyz_path(parameters.run.output).string());
  const bool ok = all.overlaps == 0 && all.queue_consistent && all.budget.relative_closure <= 1e-9;
  if (!ok) terminal_log::say(stderr, "shaker md: end-of-run invariant check FAILED (see summary)\n");
  return ok ? 0 : 1;
}

}  // namespace shaker::md
