#include "common/case_parameters.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "common/errors.hpp"

namespace shaker {

CaseParameters CaseParameters::from(const config::Config& c) {
  CaseParameters p;
  p.name = c.text("case.name");
  p.shaker = ShakerKinematics{c.real("shaker.gamma"), c.real("shaker.frequency")};
  p.restitution = Restitution{restitution_kind_from_string(c.text("material.restitution")),
                              c.real("material.e")};
  p.particles = c.integer("layer.particles");
  p.md_box_width = c.real("md.box_width");
  p.md_box_depth = c.real("md.box_depth") > 0.0 ? c.real("md.box_depth") : p.md_box_width;
  p.run.kind = c.text("run.protocol") == "single_shock" ? RunProtocol::Kind::single_shock
                                                        : RunProtocol::Kind::periodic;
  p.run.transient_cycles = c.integer("run.transient_cycles");
  p.run.sampled_cycles = c.integer("run.sampled_cycles");
  p.run.phases_per_cycle = c.integer("run.phases_per_cycle");
  p.run.switch_phase = c.real("run.switch_phase");
  p.run.after_switch = Restitution{restitution_kind_from_string(c.text("run.switch_restitution")),
                                   c.real("run.switch_e")};
  p.run.seed = static_cast<std::uint64_t>(c.integer("run.seed"));
  p.run.output = c.text("run.output");
  p.run.log = c.boolean("run.log");
  // The switch lies run.switch_phase (in [-1, 0)) before the recorded cycle, i.e. inside the
  // transient: without a transient cycle it would lie before the start of the run.
  if (p.run.kind == RunProtocol::Kind::single_shock && static_cast<double>(p.run.transient_cycles) + p.run.switch_phase < 0.0)
    throw InputError(fmt::format(
        "run.transient_cycles = {} with run.protocol = \"single_shock\" puts the switch at "
        "run.switch_phase = {} cycles, before the start of the run; allowed: run.transient_cycles "
        ">= 1 for a single shock", p.run.transient_cycles, p.run.switch_phase));
  return p;
}

std::vector<std::int64_t> stored_phase_indices(const config::Config& config, const std::string& key,
                                               std::int64_t phases) {
  const std::vector<double>& listed = config.real_list(key);
  const std::string given = fmt::format("{} = {}", key, config.value_text(key));
  const auto K = static_cast<double>(phases);
  std::string grid;
  for (std::int64_t k = 0; k < phases; ++k) {
    if (phases > 12 && k == 3) {
      grid += ", ...";
      k = phases - 1;
    }
    grid += fmt::format("{}{}", k == 0 ? "" : ", ", static_cast<double>(k) / K);
  }
  const std::string allowed = fmt::format(
      "allowed: the stored phases k / {} (run.phases_per_cycle = {}), each at most once: {}",
      phases, phases, grid);
  std::vector<std::int64_t> indices;
  for (const double phase : listed) {
    const double k = std::round(phase * K);
    if (std::abs(phase * K - k) > 1e-9 || k >= K)
      throw InputError(fmt::format("{}: {} is not a stored phase; {}", given, phase, allowed));
    const auto index = static_cast<std::int64_t>(k);
    if (std::find(indices.begin(), indices.end(), index) != indices.end())
      throw InputError(fmt::format("{}: the stored phase {} is listed twice; {}", given,
                                   static_cast<double>(index) / K, allowed));
    indices.push_back(index);
  }
  std::sort(indices.begin(), indices.end());
  return indices;
}

std::vector<std::int64_t> cycle_indices(const config::Config& c, const std::string& key, const RunProtocol& run) {
  const std::int64_t cycles = run.cycles();
  const std::string given = fmt::format("{} = [{}]", key, fmt::join(c.real_list(key), ", "));
  const std::string allowed = fmt::format(
      "allowed: whole numbers from {} to {}, each cycle at most once (the run has {} cycles: "
      "run.transient_cycles = {} and {}; counted from 0, negative from the end)", -cycles, cycles - 1, cycles,
      run.transient_cycles, run.kind == RunProtocol::Kind::single_shock
                                ? std::string("the single shock's recorded cycle")
                                : fmt::format("run.sampled_cycles = {}", run.sampled_cycles));
  std::vector<std::int64_t> indices;
  for (const double listed : c.real_list(key)) {
    if (listed != std::floor(listed) || listed < static_cast<double>(-cycles) || listed >= static_cast<double>(cycles))
      throw InputError(fmt::format("{}: {} is not a cycle of this run; {}", given, listed, allowed));
    const auto cycle = static_cast<std::int64_t>(listed) + (listed < 0.0 ? cycles : 0);
    if (std::find(indices.begin(), indices.end(), cycle) != indices.end())
      throw InputError(fmt::format("{}: cycle {} is listed twice; {}", given, cycle, allowed));
    indices.push_back(cycle);
  }
  std::sort(indices.begin(), indices.end());
  return indices;
}


}  // namespace shaker
