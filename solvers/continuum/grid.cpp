#include "continuum/grid.hpp"

#include <fmt/format.h>

#include <cmath>

#include "common/errors.hpp"

namespace shaker::continuum {

namespace {
int cells_fitting(double length, double h, const char* key) {
  const double ratio = length / h;
  const double cells = std::round(ratio);
  if (cells < 4 || std::abs(ratio - cells) > 1e-9 * ratio)
    throw InputError(fmt::format(
        "continuum.cell_size = {} does not fit {} = {}: the length must be a whole number "
        "(at least 4) of cells",
        h, key, length));
  return static_cast<int>(cells);
}
}  // namespace

Grid make_grid(int dimension, double width, double height, double h) {
  if (dimension != 1 && dimension != 3)
    throw InputError(fmt::format("continuum.dimension = {}: allowed values are 1 and 3", dimension));
  Grid g;
  g.dimension = dimension;
  g.h = h;
  g.nz = cells_fitting(height, h, "continuum.ceiling");
  if (dimension == 3) {
    g.nx = cells_fitting(width, h, "continuum.box_width");
    g.ny = g.nx;
  }
  return g;
}

}  // namespace shaker::continuum
