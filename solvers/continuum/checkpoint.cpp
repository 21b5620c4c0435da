#include "continuum/checkpoint.hpp"

#include <fmt/format.h>

#include <cmath>

#include "common/atomic_output.hpp"
#include "common/checkpoints.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/units.hpp"

namespace shaker::continuum {

namespace {
const char* const names[variable_count] = {"density", "momentum_x", "momentum_y", "momentum_z", "energy"};
// Conserved variables per unit volume (docs/units.md): n, n u, n (|u|^2 + 3 T) / 2.
const char* const units[variable_count] = {"1/sigma^3", "m sqrt(g sigma) / sigma^3", "m sqrt(g sigma) / sigma^3",
                                           "m sqrt(g sigma) / sigma^3", "m g / sigma^2"};
}

void write_checkpoint(const std::filesystem::path& path, const BoxView& box,
                      const SchedulePosition& position, const std::string& configuration_toml) {
  const Grid& g = box.grid;
  write_hdf5_atomically(path, [&](const hid_t file) {
    write_checkpoint_header(file, checkpoint_kind, position, configuration_toml);
    h5::write_attribute(file, "time", box.scalars.time);
    h5::write_attribute(file, "dimension", std::int64_t{g.dimension});
    h5::write_attribute(file, "nx", std::int64_t{g.nx});
    h5::write_attribute(file, "ny", std::int64_t{g.ny});
    h5::write_attribute(file, "nz", std::int64_t{g.nz});
    h5::write_attribute(file, "cell_size", g.h);
    // The e in effect (after a single-shock switch, the switched one): a restart uses it.
    h5::write_attribute(file, "e", box.scalars.e);
    const EnergyBudget& b = box.scalars.budget;
    h5::write(file, "energy_budget", std::vector<double>{b.body_work, b.collisional_loss, b.floor_energy},
              {3}, "m g / sigma");
    const Counters& k = box.scalars.counters;
    h5::write(file, "counters",
              std::vector<std::int64_t>{k.steps, k.rejected_steps, k.temperature_floor_uses,
                                        k.diffusion_stages},
              {4}, "1");
    for (int v = 0; v < variable_count; ++v) {
      std::vector<double> data;
      data.reserve(g.interior_cells());
      for (int kz = 0; kz < g.nz; ++kz)
        for (int j = 0; j < g.ny; ++j)
          for (int i = 0; i < g.nx; ++i) data.push_back(box.state.q[v][g.index(i, j, kz)]);
      h5::write(file, names[v], data, {data.size()}, units[v]);
    }
  });
}

namespace {

/// The dataset `name` with exactly `expected` entries, all finite.
std::vector<double> read_finite(hid_t file, const char* name, std::size_t expected) {
  std::vector<double> data = h5::read_doubles(file, name);
  if (data.size() != expected)
    throw InputError(fmt::format("dataset '{}' has {} entries; allowed: {} (the grid's interior "
                                 "cells, or the fixed length)", name, data.size(), expected));
  for (std::size_t m = 0; m < data.size(); ++m)
    if (!std::isfinite(data[m]))
      throw InputError(fmt::format("dataset '{}' holds {} at entry {}; allowed: finite values", name,
                                   data[m], m));
  return data;
}

/// The whole checkpoint checked before any of it is used: shapes against the grid, finite
/// values, 0 < nu < nu_max, T >= 0 (to round-off), 0 <= e <= 1, a finite time, counters >= 0.
void load_checked(hid_t file, const std::filesystem::path& path, const Grid& g, State& state,
                  RunScalars& scalars) {
  const auto check = [&](const char* key, std::int64_t expected) {
    const std::int64_t found = h5::read_integer_attribute(file, key);
    if (found != expected)
      throw InputError(fmt::format("{}: checkpoint has {} = {}, the configuration needs {}",
                                   restart_source(path), key, found, expected));
  };
  check("dimension", g.dimension);
  check("nx", g.nx);
  check("ny", g.ny);
  check("nz", g.nz);
  if (h5::read_double_attribute(file, "cell_size") != g.h)
    throw InputError(fmt::format("{}: checkpoint has cell size {}, the configuration needs continuum.cell_size = {}",
                                 restart_source(path), h5::read_double_attribute(file, "cell_size"), g.h));
  const double time = h5::read_double_attribute(file, "time");
  if (!std::isfinite(time))
    throw InputError(fmt::format("attribute 'time' = {}; allowed: a finite time", time));
  const double e = h5::read_double_attribute(file, "e");
  if (!(e >= 0.0 && e <= 1.0))
    throw InputError(fmt::format("attribute 'e' = {}; allowed: 0 <= e <= 1", e));
  const std::vector<double> budget = read_finite(file, "energy_budget", 3);
  const auto counters = h5::read_integers(file, "counters");
  if (counters.size() != 4)
    throw InputError(fmt::format("dataset 'counters' has {} entries; allowed: 4", counters.size()));
  for (std::int64_t k : counters)
    if (k < 0)
      throw InputError(fmt::format("dataset 'counters' holds {}; allowed: counts >= 0", k));
  const std::size_t cells = g.interior_cells();
  State interior;
  for (int v = 0; v < variable_count; ++v) interior.q[v] = read_finite(file, names[v], cells);
  for (std::size_t m = 0; m < cells; ++m) {
    const double nu = volume_fraction(interior.q[density][m]);
    if (!(nu > 0.0 && nu < nu_max))
      throw InputError(fmt::format("dataset 'density' holds n = {} (nu = {}) at cell {}; allowed: "
                                   "0 < nu < nu_max = {}", interior.q[density][m], nu, m, nu_max));
    double kinetic = 0.0;
    for (int v : {momentum_x, momentum_y, momentum_z})
      kinetic += 0.5 * interior.q[v][m] * interior.q[v][m] / interior.q[density][m];
    const double internal = interior.q[energy][m] - kinetic;
    if (internal < -1e-9 * std::max(std::fabs(interior.q[energy][m]), kinetic))
      throw InputError(fmt::format("dataset 'energy' holds E = {} at cell {}, below the kinetic "
                                   "energy {}: a negative temperature; allowed: T >= 0",
                                   interior.q[energy][m], m, kinetic));
  }
  // Valid: now the state takes it over.
  for (int v = 0; v < variable_count; ++v) {
    std::size_t m = 0;
    for (int kz = 0; kz < g.nz; ++kz)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) state.q[v][g.index(i, j, kz)] = interior.q[v][m++];
  }
  scalars = RunScalars{time, e, EnergyBudget{budget[0], budget[1], budget[2]},
                       Counters{counters[0], counters[1], counters[2], counters[3]}};
}

}  // namespace

SchedulePosition read_checkpoint(const std::filesystem::path& path, TimeIntegrator& solver) {
  RunScalars scalars;
  const SchedulePosition position = read_checkpoint(path, solver.op().grid(), solver.state(), scalars);
  solver.set_time(scalars.time);
  solver.op().settings().e = scalars.e;
  solver.budget() = scalars.budget;
  solver.counters() = scalars.counters;
  return position;
}

namespace {

/// A 1D column's checkpoint continued as a 3D box of the same cell size and ceiling: every
/// column of the box takes the checkpoint's column (a horizontally uniform state).
void load_extruded(hid_t file, const std::filesystem::path& path, const Grid& box, State& state,
                   RunScalars& scalars) {
  const Grid column = make_grid(1, 1.0, 1.0, box.height(), box.h);
  const auto found = h5::read_integer_attribute(file, "nz");
  if (found != column.nz)
    throw InputError(fmt::format(
        "{}: the 1D column checkpoint has nz = {} cells, the 3D box nz = {} (continuum.ceiling / "
        "continuum.cell_size); allowed: a column of the box's height and cell size",
        restart_source(path), found, column.nz));
  State profile;
  profile.resize(column.size());
  load_checked(file, path, column, profile, scalars);
  for (int v = 0; v < variable_count; ++v)
    for (int k = 0; k < box.nz; ++k)
      for (int j = 0; j < box.ny; ++j)
        for (int i = 0; i < box.nx; ++i) state.q[v][box.index(i, j, k)] = profile.q[v][column.index(0, 0, k)];
}

bool column_into_box(hid_t file, const Grid& grid) {
  return grid.dimension == 3 && h5::read_integer_attribute(file, "dimension") == 1;
}

}  // namespace

SchedulePosition read_checkpoint(const std::filesystem::path& path, const Grid& grid, State& state,
                                 RunScalars& scalars) {
  const h5::Handle file = open_checkpoint(path, checkpoint_kind);
  try {
    const SchedulePosition position = read_schedule_position(file.id());
    if (column_into_box(file.id(), grid))
      load_extruded(file.id(), path, grid, state, scalars);
    else
      load_checked(file.id(), path, grid, state, scalars);
    return position;
  } catch (const std::exception& error) {
    const std::string what = error.what();
    if (what.rfind("run.restart_from", 0) == 0) throw InputError(what);  // a grid mismatch
    throw InputError(fmt::format("{} is not a valid checkpoint: {}", restart_source(path), what));
  }
}

std::string checkpoint_configuration(const std::filesystem::path& path) {
  const h5::Handle file = open_checkpoint(path, checkpoint_kind);
  try {
    return h5::read_string_attribute(file.id(), "configuration");
  } catch (const std::exception& error) {
    throw InputError(fmt::format("{} is not a valid checkpoint: {}", restart_source(path), error.what()));
  }
}

}  // namespace shaker::continuum
