// The horizontal fields of pattern.hpp: the grid's checks and the column-mass and
// centre-of-mass-height fields from particles or from a 3D density.
#include <fmt/format.h>

#include <cmath>

#include "analysis/pattern.hpp"
#include "common/errors.hpp"

namespace shaker::analysis {
namespace {

/// The cell (i, j) holding the point (x, y), the point wrapped into the periodic box first.
std::size_t cell_of(const HorizontalGrid& grid, double x, double y) {
  const auto index = [](double u, double length, std::size_t n) {
    const double wrapped = u - length * std::floor(u / length);
    const auto i = static_cast<std::size_t>(wrapped / length * static_cast<double>(n));
    return i < n ? i : n - 1;  // wrapped == length after rounding
  };
  return index(y, grid.ly, grid.ny) * grid.nx + index(x, grid.lx, grid.nx);
}

void check_particles(const ParticlePositions& p) {
  if (p.x.size() != p.y.size() || p.x.size() != p.z.size())
    throw InputError(fmt::format("particle positions: {} x, {} y and {} z coordinates; allowed: "
                                 "one of each per particle", p.x.size(), p.y.size(), p.z.size()));
  for (std::size_t i = 0; i < p.x.size(); ++i)
    if (!std::isfinite(p.x[i]) || !std::isfinite(p.y[i]) || !std::isfinite(p.z[i]))
      throw InputError(fmt::format("particle {}: position ({}, {}, {}) is not finite", i,
                                   p.x[i], p.y[i], p.z[i]));
}

void check_density(const DensityColumns& d) {
  check_grid(d.grid);
  if (d.nz == 0) throw InputError("density field: nz = 0 cells in z; allowed: nz >= 1");
  if (!(d.dz > 0.0) || !std::isfinite(d.dz) || !std::isfinite(d.z_bottom))
    throw InputError(fmt::format("density field: dz = {}, z_bottom = {}; allowed: dz finite and "
                                 "> 0, z_bottom finite", d.dz, d.z_bottom));
  if (d.n.size() != d.grid.cells() * d.nz)
    throw InputError(fmt::format("density field: {} values for {} x {} x {} cells; allowed: "
                                 "exactly nx ny nz", d.n.size(), d.grid.nx, d.grid.ny, d.nz));
  for (double n : d.n)
    if (!std::isfinite(n) || n < 0.0)
      throw InputError(fmt::format("density field: n = {}; allowed: finite and >= 0", n));
}

/// Divides each cell's weighted sum by its weight; a cell without weight takes the mean over
/// all the weight, so that it adds nothing once the mean is removed.
HorizontalField weighted_means(const HorizontalGrid& grid, const std::vector<double>& sum,
                               const std::vector<double>& weight, const char* what) {
  double all_sum = 0.0, all_weight = 0.0;
  for (std::size_t c = 0; c < sum.size(); ++c) all_sum += sum[c], all_weight += weight[c];
  if (!(all_weight > 0.0))
    throw InputError(fmt::format("{}: no material; allowed: at least one particle or a "
                                 "positive density", what));
  HorizontalField field{grid, std::vector<double>(sum.size())};
  for (std::size_t c = 0; c < sum.size(); ++c)
    field.values[c] = weight[c] > 0.0 ? sum[c] / weight[c] : all_sum / all_weight;
  return field;
}

}  // namespace

void check_grid(const HorizontalGrid& grid) {
  if (grid.nx == 0 || grid.ny == 0)
    throw InputError(fmt::format("pattern grid: {} x {} cells; allowed: nx >= 1 and ny >= 1",
                                 grid.nx, grid.ny));
  if (!(grid.lx > 0.0) || !(grid.ly > 0.0) || !std::isfinite(grid.lx) || !std::isfinite(grid.ly))
    throw InputError(fmt::format("pattern grid: box {} x {} sigma; allowed: Lx and Ly finite "
                                 "and > 0", grid.lx, grid.ly));
}

HorizontalField column_mass_field(const ParticlePositions& particles, const HorizontalGrid& grid) {
  check_grid(grid);
  check_particles(particles);
  HorizontalField field{grid, std::vector<double>(grid.cells(), 0.0)};
  const double per_particle = 1.0 / grid.cell_area();
  for (std::size_t p = 0; p < particles.x.size(); ++p)
    field.values[cell_of(grid, particles.x[p], particles.y[p])] += per_particle;
  return field;
}

HorizontalField center_of_mass_height_field(const ParticlePositions& particles,
                                            const HorizontalGrid& grid) {
  check_grid(grid);
  check_particles(particles);
  std::vector<double> height(grid.cells(), 0.0), count(grid.cells(), 0.0);
  for (std::size_t p = 0; p < particles.x.size(); ++p) {
    const std::size_t c = cell_of(grid, particles.x[p], particles.y[p]);
    height[c] += particles.z[p];
    count[c] += 1.0;
  }
  return weighted_means(grid, height, count, "centre-of-mass height from particles");
}

HorizontalField column_mass_field(const DensityColumns& density) {
  check_density(density);
  const std::size_t cells = density.grid.cells();
  HorizontalField field{density.grid, std::vector<double>(cells, 0.0)};
  for (std::size_t k = 0; k < density.nz; ++k)
    for (std::size_t c = 0; c < cells; ++c) field.values[c] += density.n[k * cells + c] * density.dz;
  return field;
}

HorizontalField center_of_mass_height_field(const DensityColumns& density) {
  check_density(density);
  const std::size_t cells = density.grid.cells();
  std::vector<double> moment(cells, 0.0), mass(cells, 0.0);
  for (std::size_t k = 0; k < density.nz; ++k) {
    const double z = density.z_bottom + (static_cast<double>(k) + 0.5) * density.dz;
    for (std::size_t c = 0; c < cells; ++c) {
      moment[c] += density.n[k * cells + c] * z;
      mass[c] += density.n[k * cells + c];
    }
  }
  return weighted_means(density.grid, moment, mass, "centre-of-mass height from a density");
}

}  // namespace shaker::analysis
