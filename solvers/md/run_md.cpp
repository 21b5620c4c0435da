// `shaker md CASE.toml`: configuration -> initial state -> protocol -> run file.
#include "md/run_md.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include "common/case_parameters.hpp"
#include "common/checkpoints.hpp"
#include "common/errors.hpp"
#include "common/memory.hpp"
#include "common/progress.hpp"
#include "common/run_file.hpp"
#include "md/checkpoint.hpp"
#include "md/initial_states.hpp"
#include "md/protocol.hpp"

namespace shaker::md {
namespace {

Geometry geometry_of(const CaseParameters& c, const MdSettings& s) {
  Geometry g;
  g.width = c.md_box_width;
  g.height = s.ceiling;
  g.gravity = gravity;
  g.plate = PlateMotion::from(c.shaker);
  // The ceiling must leave room for a particle above the plate at its highest point.
  if (!(s.ceiling > g.plate_top() + 1.0))
    throw InputError(fmt::format(
        "md.ceiling = {} is below the plate's top: it must exceed 2A + 1 = {:.6g} (A = {:.6g} "
        "for shaker.gamma = {} and shaker.frequency = {})",
        s.ceiling, g.plate_top() + 1.0, g.plate.amplitude, c.shaker.Gamma, c.shaker.f));
  return g;
}

std::string variant_name(const Restitution& r, const MdSettings& s) {
  const std::string model = r.kind == Restitution::Kind::constant
                                ? fmt::format("constant e = {}", r.e)
                                : std::string("velocity-dependent e(v_n)");
  const std::string guard = s.tc_guard ? fmt::format("TC guard t_c = {:g}", s.tc) : "no guard";
  return model + ", " + guard;
}

/// The simulation at the case's initial state, or at the checkpoint `restart_from` (whose
/// schedule position goes to `position`).
Simulation make_simulation(const config::Config& config, const CaseParameters& c, const MdSettings& s,
                           const Geometry& g, const CollisionRules& rules,
                           const std::filesystem::path& restart_from, std::optional<SchedulePosition>& position) {
  const auto n = static_cast<std::size_t>(c.particles);
  if (restart_from.empty()) {
    if (s.initial_state == "gas")
      return Simulation(g, rules, homogeneous_gas(g, n, s.gas_volume_fraction, s.gas_temperature, c.run.seed),
                        s.queue);
    return Simulation(g, rules, flat_layer(g, n, c.run.seed), s.queue);
  }
  Checkpoint saved = read_checkpoint(restart_from);
  const std::string source = restart_source(restart_from);
  if (saved.data.particles.size() != n)
    throw InputError(fmt::format("layer.particles = {} but the checkpoint {} holds {} particles; "
                                 "allowed: {}", n, source, saved.data.particles.size(),
                                 saved.data.particles.size()));
  // The restart rule (README); another box is allowed (see below). The schedule's times
  // are counted in the checkpoint's cycles.
  config::require_same_keys(config, saved.configuration, {"material.restitution", "material.e", "shaker.frequency"},
                            source);
  validate_state(g, saved.data);
  position = saved.position;
  if (saved.width == g.width && saved.height == g.height) return Simulation(g, rules, std::move(saved.data), s.queue);
  // Another box: keep the particles, rebuild cells and events (not a bit-for-bit restart).
  State state{saved.data.time, std::move(saved.data.particles), std::move(saved.data.last_collision)};
  return Simulation(g, rules, state, s.queue);
}

/// The MD's schedule: a new one from the simulation's time, or the checkpoint's, continued.
PhaseSchedule schedule_of(const CaseParameters& c, const Simulation& simulation,
                          const std::optional<SchedulePosition>& resume, const std::filesystem::path& restart_from) {
  if (!resume) return PhaseSchedule::whole_cycles(c.run, c.shaker, simulation.time());
  PhaseSchedule schedule = PhaseSchedule::whole_cycles(c.run, c.shaker, resume->start_time);
  schedule.resume_at(*resume, simulation.time(), restart_source(restart_from));
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
  const double rows = std::min(std::floor(g.height), g.plate_top() + 8.0 * n / (g.width * g.width) + 3.0);
  const double cells = std::floor(g.width) * std::floor(g.width) * std::max(rows, 3.0);
  const double bins = std::ceil(s.ceiling / s.bin_height);
  const double phases = static_cast<double>(c.run.phases_per_cycle);
  check_memory(n * per_particle + 4.0 * cells + bins * phases * (13.0 + 18.0) * 8.0,
               fmt::format("the MD run ({} particles, {:.3g} cells, {:.3g} sampling bins x {} phases)",
                           c.particles, cells, bins, c.run.phases_per_cycle),
               "allowed: fewer layer.particles, a larger md.bin_height, a lower md.ceiling or fewer "
               "run.phases_per_cycle");
}

}  // namespace

int run(const config::Config& config, const std::vector<NamedPath>& inputs,
        const ProgressSettings& progress_settings) {
  const Stopwatch wall;
  const CaseParameters parameters = CaseParameters::from(config);
  const MdSettings settings = MdSettings::from(config);
  const Geometry geometry = geometry_of(parameters, settings);
  const CheckpointSettings checkpoints = CheckpointSettings::from(config);
  checkpoints.check_paths({{"run.output", parameters.run.output}}, inputs);
  check_md_memory(parameters, settings, geometry);
  CollisionRules rules;
  rules.restitution = parameters.restitution;
  rules.tc_guard = settings.tc_guard;
  rules.tc = settings.tc;
  std::optional<SchedulePosition> resume;
  Simulation simulation =
      make_simulation(config, parameters, settings, geometry, rules, checkpoints.restart_from, resume);
  const PhaseSchedule schedule = schedule_of(parameters, simulation, resume, checkpoints.restart_from);

  ProgressReport progress("shaker md", "collisions/s",
                          [&] { return static_cast<double>(simulation.tally().collisions()); },
                          progress_settings);
  const std::string configuration = config.to_toml();
  CheckpointObserver checkpointing(
      checkpoints, schedule,
      [&](const std::filesystem::path& path, const SchedulePosition& position) {
        write_checkpoint(path, simulation.save(), geometry, position, configuration);
      },
      "shaker md");
  const RunOutcome outcome = run_protocol(simulation, schedule, parameters, settings, {&progress, &checkpointing});

  RunRecord record;
  record.solver = "md";
  const bool switched = parameters.run.kind == RunProtocol::Kind::single_shock;
  const Restitution& final_restitution = switched ? parameters.run.after_switch : parameters.restitution;
  record.model_variant = variant_name(final_restitution, settings);
  if (switched) record.model_variant += fmt::format(" (switched from {} at f t = {})",
                                                    variant_name(parameters.restitution, settings),
                                                    parameters.run.switch_phase);
  record.configuration = configuration;
  record.e = final_restitution.e;
  record.profiles = outcome.profiles;
  record.samples = outcome.samples;
  record.series = outcome.series;
  write_run_file(parameters.run.output, record);

  const Tally& tally = simulation.tally();
  fmt::print("shaker md: {} particles, {} cycles, t = {:.6g}, wall time {}\n", simulation.size(),
             parameters.run.transient_cycles + (switched ? 1 : parameters.run.sampled_cycles),
             simulation.time(), duration_text(wall.seconds()));
  fmt::print("  collisions: {} (pair {}, plate {}, ceiling {}), {:.4g} collisions/s, {:.4g} events/s\n",
             outcome.collisions, tally.pair, tally.plate, tally.ceiling,
             static_cast<double>(outcome.collisions) / outcome.seconds,
             static_cast<double>(outcome.events) / outcome.seconds);
  fmt::print("  energy budget: plate work {:.10g}, collisional loss {:.10g}, energy change {:.10g}, "
             "relative closure {:.3g}\n", outcome.budget.plate_work, outcome.budget.collisional_loss,
             outcome.budget.energy_change, outcome.budget.relative_closure);
  fmt::print("  collapse guard activations: {}; overlaps at end: {}; event queue consistent: {}\n",
             tally.guard_activations, outcome.overlaps, outcome.queue_consistent ? "yes" : "NO");
  fmt::print("  output: {}\n", parameters.run.output);
  const bool ok = outcome.overlaps == 0 && outcome.queue_consistent &&
                  outcome.budget.relative_closure <= 1e-9;
  if (!ok) fmt::print(stderr, "shaker md: end-of-run invariant check FAILED (see summary)\n");
  return ok ? 0 : 1;
}

}  // namespace shaker::md
