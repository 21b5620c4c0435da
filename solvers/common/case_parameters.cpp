#include "common/case_parameters.hpp"

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
  return p;
}

}  // namespace shaker
