#include "md/setup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/errors.hpp"
#include "common/memory.hpp"
#include "common/terminal_log.hpp"
#include "md/particle_file.hpp"

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

/// The key a replica's number is added to (replica_configuration).
const char* replica_key(const config::Config& config) {
  return config.text("run.protocol") == "single_shock" ? "run.transient_cycles" : "run.seed";
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

}  // namespace

config::Config replica_configuration(const config::Config& config, std::int64_t r) {
  config::Config replica = config;
  replica.set_value("md.replicas", std::int64_t{1});
  replica.set_value(replica_key(config), config.integer(replica_key(config)) + r);
  return replica;
}

MdCase md_case(const config::Config& config, const std::vector<NamedPath>& inputs) {
  MdCase c{CaseParameters::from(config), MdSettings::from(config), {}, CheckpointSettings::from(config),
           {}, config.integer("md.replicas"), config.to_toml()};
  c.geometry = geometry_of(c.parameters, c.settings);
  check_paths(c.parameters, c.settings, c.checkpoints, inputs);
  check_replicas(config, c.checkpoints);
  check_md_memory(c.parameters, c.settings, c.geometry);
  c.rules.restitution = c.parameters.restitution;
  c.rules.tc_guard = c.settings.tc_guard;
  c.rules.tc = c.settings.tc;
  return c;
}

}  // namespace shaker::md
