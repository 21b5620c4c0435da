#include "continuum/initial_state.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <random>

#include "common/errors.hpp"
#include "common/units.hpp"

namespace shaker::continuum {

double flat_layer(const Grid& g, const LayerSpecification& layer, State& state) {
  const double n_layer = number_density(layer.volume_fraction);
  const double n_background = number_density(layer.background_volume_fraction);
  const double height = g.height();
  if (!(n_background < n_layer))
    throw InputError(fmt::format(
        "continuum.background_volume_fraction = {} must be below continuum.initial_volume_fraction = {}",
        layer.background_volume_fraction, layer.volume_fraction));
  // n_layer top + n_background (height - top) = mass per area
  const double top = (layer.mass_per_area - n_background * height) / (n_layer - n_background);
  if (!(n_background * height < layer.mass_per_area))
    throw InputError(fmt::format(
        "continuum.background_volume_fraction = {} fills the height continuum.ceiling = {} with "
        "{:.4g} particles per unit area, more than the layer's {:.4g}; allowed: "
        "continuum.background_volume_fraction < {:.4g} here", layer.background_volume_fraction,
        height, n_background * height, layer.mass_per_area,
        layer.background_volume_fraction * layer.mass_per_area / (n_background * height)));
  if (!(top > 0.0) || top >= height)
    throw InputError(fmt::format(
        "continuum.ceiling = {} is below the initial layer: {} particles per unit area at "
        "nu = {} need a layer {:.4g} high (and the background gas fills the rest)",
        height, layer.mass_per_area, layer.volume_fraction, top));
  std::mt19937_64 random(layer.seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const bool perturb = g.dimension == 3 && layer.perturbation > 0.0;
  double mass = 0.0;
  for (int k = 0; k < g.nz; ++k) {
    const double bottom = k * g.h;
    const double filled = std::clamp((top - bottom) / g.h, 0.0, 1.0);
    const double n = filled * n_layer + (1.0 - filled) * n_background;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const double factor = perturb && filled > 0.0 ? 1.0 + layer.perturbation * uniform(random) : 1.0;
        const double n_cell = std::min(n * factor, number_density(0.999 * nu_max));
        store_primitive(state, g.index(i, j, k), Primitive{n_cell, 0, 0, 0, layer.temperature});
        mass += n_cell;
      }
  }
  if (perturb) {  // restore the exact mass per unit area
    const double scale = layer.mass_per_area * g.nx * g.ny / (mass * g.h);
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) {
          const auto c = g.index(i, j, k);
          for (int v = 0; v < variable_count; ++v) state.q[v][c] *= scale;
        }
  }
  return top;
}

}  // namespace shaker::continuum
