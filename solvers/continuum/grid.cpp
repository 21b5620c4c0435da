#include "continuum/grid.hpp"

#include <fmt/format.h>

#include <cmath>

#include "common/errors.hpp"
#include "common/memory.hpp"

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

Grid make_grid(int dimension, double width, double depth, double height, double h, int processes) {
  if (dimension != 1 && dimension != 3)
    throw InputError(fmt::format("continuum.dimension = {}: allowed values are 1 and 3", dimension));
  // A grid that cannot fit even when split evenly over the processes is refused before its
  // cell counts (ints) are formed; the run checks its exact need per machine later.
  const double cells = (height / h) * (dimension == 3 ? (width / h) * (depth / h) : 1.0);
  check_memory(cells * solver_bytes_per_cell / processes,
               fmt::format("a {}D grid of {:.3g} cells (continuum.cell_size = {}, continuum.ceiling "
                           "= {}{}){}", dimension, cells, h, height,
                           dimension == 3 ? fmt::format(", continuum.box_width = {}, continuum.box_depth = {}", width, depth) : "",
                           processes > 1 ? fmt::format(", split evenly over {} processes,", processes) : ""),
               "allowed: a larger continuum.cell_size or a smaller box");
  Grid g;
  g.dimension = dimension;
  g.h = h;
  g.nz = cells_fitting(height, h, "continuum.ceiling");
  if (dimension == 3) {
    g.nx = cells_fitting(width, h, "continuum.box_width");
    g.ny = cells_fitting(depth, h, "continuum.box_depth");
  }
  return g;
}

}  // namespace shaker::continuum
