// Keys of the MD solver (docs/models.md, "Molecular dynamics").
#include "common/config.hpp"

namespace shaker::config {

std::vector<ParameterSpec> md_parameters() {
  return {
      real("md.box_width", 20.0, Range{1.0, 1e4, true, false},
           "periodic box edge in x and y (units sigma); must exceed one diameter").in("sigma"),
      real("md.ceiling", 200.0, positive(1e6),
           "height of the fixed ceiling in the lab frame; must lie above the plate's top 2A + 1").in("sigma"),
      real("md.bin_height", 1.0, at_least(1e-3, 10.0),
           "height of the sampling bins (at least 1e-3: finer bins hold no particle)").in("sigma"),
      text("md.initial_state", "flat_layer", {"flat_layer", "gas"},
           "flat_layer: slightly randomised layer at rest on the plate; gas: homogeneous gas "
           "at md.gas_volume_fraction and md.gas_temperature (run.restart_from replaces it)").in("-"),
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
  };
}

}  // namespace shaker::config
