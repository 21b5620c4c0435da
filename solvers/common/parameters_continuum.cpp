// Keys of the continuum solver (physics.md, "Continuum").
#include "common/config.hpp"

namespace shaker::config {

std::vector<ParameterSpec> continuum_parameters() {
  return {
      integer("continuum.dimension", 1, closed(1, 3), "1: vertical column; 3: periodic x, y"),
      real("continuum.cell_size", 0.1, positive(10.0), "grid spacing in every direction"),
      real("continuum.box_width", 11.0, Range{1.0, 1e4, true, false},
           "periodic box edge in x and y (3D)"),
      real("continuum.ceiling", 80.0, positive(1e5), "height of the ceiling above the plate"),
      real("continuum.initial_volume_fraction", 0.5, Range{0.0, 0.65, true, true},
           "volume fraction of the initial flat layer (below nu_max = 0.65)"),
      text("continuum.transport", "paper", {"paper", "full"},
           "paper: 1/G terms dropped plus low-density artificial dissipation; full: all terms"),
      text("continuum.limiter", "mc", {"minmod", "mc", "van_leer"}, "slope limiter"),
      text("continuum.riemann", "hllc", {"hllc", "hll"}, "approximate Riemann solver"),
      real("continuum.cfl", 0.4, positive(1.0), "Courant number of the adaptive step"),
      real("continuum.perturbation", 1e-3, closed(0.0, 0.5),
           "3D: relative amplitude of the seeded random perturbation of the initial layer"),
  };
}

}  // namespace shaker::config
