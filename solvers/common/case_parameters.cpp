#include "common/case_parameters.hpp"

#include <fmt/format.h>

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

}  // namespace shaker
