// Keys of the MD solver (docs/models.md, "Molecular dynamics").
#include "common/config.hpp"

namespace shaker::config {

std::vector<ParameterSpec> md_parameters() {
  return {
      real("md.box_width", 20.0, Range{1.0, 1e4, true, false},
           "periodic box edge in x (units sigma); must exceed one diameter").in("sigma")
          .kept_on_restart(restart_continuum),  // the continuum's mass per area; the MD may change its box
      real("md.box_depth", 0.0, closed(0.0, 1e4),
           "periodic box edge in y; 0 (the default): equal to md.box_width, a square box. "
           "Otherwise at least 3 (three cells of the cell list across the box)").in("sigma")
          .kept_on_restart(restart_continuum),
      real("md.ceiling", 200.0, positive(1e6),
           "height of the fixed ceiling in the lab frame; must lie above the plate's top 2A + 1").in("sigma"),
      real("md.bin_height", 1.0, at_least(1e-3, 10.0),
           "height of the sampling bins (at least 1e-3: finer bins hold no particle)").in("sigma"),
      text("md.initial_state", "flat_layer", {"flat_layer", "gas", "file"},
           "flat_layer: slightly randomised layer at rest on the plate; gas: homogeneous gas "
           "at md.gas_volume_fraction and md.gas_temperature; file: the particles of frame "
           "md.initial_frame of the H5MD particle file md.initial_file, the run starting at that "
           "frame's time (run.restart_from replaces it)").in("-"),
      text("md.initial_file", "", {},
           "md.initial_state = \"file\": an H5MD particle file (RUN.particles.h5 of an earlier "
           "run, docs/output-schema.md) holding layer.particles particles in a box of width "
           "md.box_width, all above the plate and below md.ceiling at the frame's time, none "
           "overlapping").in("-"),
      integer("md.initial_frame", -1, closed(-1e9, 1e9),
              "md.initial_state = \"file\": the frame of md.initial_file to start from, counted "
              "from 0; negative counts from the end (-1, the default, is the last)").in("1"),
      real("md.initial_perturbation", 0.0, closed(0.0, 10.0),
           "flat_layer: each vertical column of the layer's sites is raised by its own uniform "
           "random height in [0, this) drawn from run.seed, a seed of horizontal patterns; 0 (the "
           "default): the flat layer without it").in("sigma"),
      real("md.gas_volume_fraction", 0.1, Range{0.0, 0.55, true, false},
           "gas initial state: volume fraction").in("1"),
      real("md.gas_temperature", 1.0, positive(1e6), "gas initial state: temperature").in("g sigma"),
      integer("md.replicas", 1, closed(1, 100000),
              "independent replicas of the case, pooled into one run file (profiles and "
              "standard errors over all replicas' samples; every replica's time series, replica "
              "0's in /timeseries, the others' in /replica_timeseries). Replica r "
              "of the periodic protocol takes seed run.seed + r; of the single shock, "
              "run.transient_cycles + r from run.seed. Spread over the ranks of `mpirun -np P "
              "shaker md`; the file is the same for every P. Without checkpoints only "
              "(run.restart_from, run.checkpoint, run.checkpoint_every)").in("1"),
      text("md.collapse_guard", "off", {"off", "tc"},
           "off: stop with an error when inelastic collapse starts; tc: collisions within "
           "md.tc of a particle's previous collision are elastic (TC model)").in("-"),
      real("md.tc", 1e-5, positive(1.0), "TC model contact duration t_c").in("sqrt(sigma/g)"),
      text("md.event_queue", "calendar", {"heap", "calendar"},
           "future-event list: indexed binary heap or bounded calendar queue; both give the "
           "same trajectory bit for bit").in("-"),
      real_list("md.crossing_heights", {80.0}, positive(),
                "lab-frame heights h > 0 whose upward crossings by any particle are counted in "
                "the time-series columns crossings_z<h>, and the distinct particles at or above h "
                "in each cycle in particles_z<h> (both cumulative since the start of the run)").in("sigma"),
      real_list("md.snapshot_phases", {}, Range{0.0, 1.0, false, true},
                "phases f t, each a stored phase k / run.phases_per_cycle at most once, at which "
                "every particle is written (RUN.particles.h5, H5MD, and RUN.particles.xyz, "
                "extended XYZ) in each cycle of md.snapshot_cycles; both lists empty (the "
                "default) or both set").in("1 (f t)"),
      real_list("md.snapshot_cycles", {}, Range{-1e9, 1e9, false, false},
                "cycles of the run, whole numbers counted from 0 at its start (a run continued "
                "from a checkpoint: the start of the checkpoint's run; negative counts from the "
                "end, -1 is the last cycle), at whose md.snapshot_phases the particles are "
                "written; each at most once").in("1"),
  };
}

}  // namespace shaker::config
