#pragma once
// The initial state of a run: a flat layer at rest on the plate holding the case's mass per
// unit area at a given volume fraction, under a dilute background gas, all at one temperature;
// in 3D with a small seeded random perturbation of the layer's density (total mass unchanged).
#include <cstdint>

#include "continuum/grid.hpp"
#include "continuum/state.hpp"

namespace shaker::continuum {

struct LayerSpecification {
  double mass_per_area = 9.8425;           ///< particles per unit plate area
  double volume_fraction = 0.5;            ///< of the layer
  double background_volume_fraction = 1e-5;
  double temperature = 1e-2;
  double perturbation = 0.0;               ///< relative amplitude (3D only)
  std::uint64_t seed = 1;
};

/// Fills the interior cells; throws InputError when the layer does not fit under the ceiling.
/// Returns the height of the layer's top.
double flat_layer(const Grid& grid, const LayerSpecification& layer, State& state);

}  // namespace shaker::continuum
