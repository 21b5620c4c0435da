// `shaker md CASE.toml`: configuration -> initial state -> protocol -> run file.
#include "md/run_md.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "common/case_parameters.hpp"
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

Simulation make_simulation(const config::Config& config, const CaseParameters& c,
                           const MdSettings& s, const Geometry& g, const CollisionRules& rules) {
  const auto n = static_cast<std::size_t>(c.particles);
  if (s.initial_state == "flat_layer") return Simulation(g, rules, flat_layer(g, n, c.run.seed), s.queue);
  if (s.initial_state == "gas")
    return Simulation(g, rules, homogeneous_gas(g, n, s.gas_volume_fraction, s.gas_temperature, c.run.seed),
                      s.queue);
  if (s.checkpoint.empty())
    throw InputError("md.initial_state = \"checkpoint\" needs md.checkpoint = the file to start from");
  Checkpoint saved = read_checkpoint(s.checkpoint);
  if (saved.data.particles.size() != n)
    throw InputError(fmt::format("layer.particles = {} but the checkpoint {} holds {} particles; "
                                 "allowed: {}", n, s.checkpoint, saved.data.particles.size(),
                                 saved.data.particles.size()));
  // The restart rule (docs/output-schema.md); another box is allowed (see below).
  config::require_same_keys(config, saved.configuration, {"material.restitution", "material.e"},
                            fmt::format("md.checkpoint = \"{}\"", s.checkpoint));
  validate_state(g, saved.data);
  if (saved.width == g.width && saved.height == g.height) return Simulation(g, rules, std::move(saved.data), s.queue);
  // Another box: keep the particles, rebuild cells and events (not a bit-for-bit restart).
  State state{saved.data.time, std::move(saved.data.particles), std::move(saved.data.last_collision)};
  return Simulation(g, rules, state, s.queue);
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
  {
    std::vector<NamedPath> outputs{{"run.output", parameters.run.output}}, read = inputs;
    if (!settings.checkpoint_output.empty())
      outputs.push_back({"md.checkpoint_output", settings.checkpoint_output});
    if (settings.initial_state == "checkpoint") read.push_back({"md.checkpoint", settings.checkpoint});
    check_output_paths(outputs, read);
  }
  check_md_memory(parameters, settings, geometry);
  CollisionRules rules;
  rules.restitution = parameters.restitution;
  rules.tc_guard = settings.tc_guard;
  rules.tc = settings.tc;
  Simulation simulation = make_simulation(config, parameters, settings, geometry, rules);

  ProgressReport progress("shaker md", "collisions/s",
                          [&] { return static_cast<double>(simulation.tally().collisions()); },
                          progress_settings);
  const RunOutcome outcome = run_protocol(simulation, parameters, settings, {&progress});

  RunRecord record;
  record.solver = "md";
  const bool switched = parameters.run.kind == RunProtocol::Kind::single_shock;
  const Restitution& final_restitution = switched ? parameters.run.after_switch : parameters.restitution;
  record.model_variant = variant_name(final_restitution, settings);
  if (switched) record.model_variant += fmt::format(" (switched from {} at f t = {})",
                                                    variant_name(parameters.restitution, settings),
                                                    parameters.run.switch_phase);
  record.configuration = config.to_toml();
  record.e = final_restitution.e;
  record.profiles = outcome.profiles;
  record.samples = outcome.samples;
  record.series = outcome.series;
  write_run_file(parameters.run.output, record);
  if (!settings.checkpoint_output.empty())
    write_checkpoint(settings.checkpoint_output, simulation.save(), geometry, config.to_toml());

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
