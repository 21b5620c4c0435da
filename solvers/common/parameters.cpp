// Keys shared by both solvers. Defaults reproduce the paper's base case (docs/models.md).
#include "common/checkpoints.hpp"
#include "common/config.hpp"

namespace shaker::config {

std::vector<ParameterSpec> common_parameters() {
  return {
      text("case.name", "base", {}, "label of the case, carried into reports").in("-"),
      real("shaker.gamma", 3.0, positive(100.0),
           "Gamma = 4 pi^2 f^2 A / g, peak plate acceleration in units of g").in("1")
          .kept_on_restart(restart_md),  // the MD's saved cell grid starts at the plate's lowest point
      real("shaker.frequency", 0.095, positive(10.0),
           "plate frequency f in units of sqrt(g/sigma); omega = 2 pi f").in("sqrt(g/sigma)")
          .kept_on_restart(restart_md | restart_continuum),  // the schedule counts its cycles
      text("material.restitution", "constant", {"constant", "velocity_dependent"},
           "restitution model for pair and wall collisions (docs/models.md)").in("-")
          .kept_on_restart(restart_md | restart_continuum),
      real("material.e", 0.9, closed(0.0, 1.0),
           "coefficient of restitution (the constant model's e; the continuum's e)").in("1")
          .kept_on_restart(restart_md | restart_continuum),
      integer("layer.particles", 3937, closed(1, 1e8),
              "number of particles in the MD box; the continuum holds the same mass per unit "
              "area, layer.particles / md.box_width^2").in("1")
          .kept_on_restart(restart_continuum),  // the MD checks its particles' count itself
      text("run.protocol", "periodic", {"periodic", "single_shock"},
           "periodic: transient then sampled cycles; single_shock: switch restitution at "
           "run.switch_phase after the transient and record the next cycle").in("-"),
      integer("run.transient_cycles", 10, closed(0, 1e6), "cycles run before sampling").in("cycles"),
      integer("run.sampled_cycles", 10, closed(1, 1e6), "cycles whose phases are sampled").in("cycles"),
      integer("run.phases_per_cycle", 50, closed(1, 10000),
              "equally spaced phases f t = k / phases_per_cycle stored per cycle").in("1"),
      real("run.switch_phase", -0.33, Range{-1.0, 0.0, false, true},
           "single_shock: phase f t (relative to the recorded cycle) at which e switches").in("1 (f t)"),
      text("run.switch_restitution", "constant", {"constant", "velocity_dependent"},
           "single_shock: restitution model after the switch").in("-"),
      real("run.switch_e", 0.9, closed(0.0, 1.0), "single_shock: e after the switch").in("1"),
      integer("run.seed", 1, closed(0, 9.0e15), "seed of every random choice of the run").in("-"),
      text("run.output", "run.h5", {}, "HDF5 output file (written atomically)").in("-"),
      boolean("run.log", true,
              "keep what the terminal shows (configuration, progress, summary, warnings, the "
              "message of a stop or failure) in OUTPUT.log beside run.output, written as the run "
              "goes").in("-"),
      text("run.restart_from", "", {},
           "checkpoint to continue from (empty: the solver's initial state): the run continues the "
           "checkpoint's schedule, its cycles counted from that run's start, up to "
           "run.transient_cycles + run.sampled_cycles; a 1D continuum column's checkpoint also "
           "starts a 3D box of the same cell size and ceiling, every column of the box taking "
           "its state").in("-"),
      text("run.checkpoint", "", {},
           "checkpoint file written (atomically) at the end of the run, every "
           "run.checkpoint_every cycles and on SIGTERM or SIGINT; the one it replaces is kept as "
           "NAME.previous.h5 (empty: none, and a stop signal's checkpoint goes to "
           "OUTPUT.checkpoint.h5)").in("-"),
      integer("run.checkpoint_every", 0, checkpoint_every_range,
              "cycles between periodic checkpoints to run.checkpoint (0: none)").in("cycles"),
  };
}

}  // namespace shaker::config
