#include "continuum/checkpoint.hpp"

#include <fmt/format.h>

#include "common/errors.hpp"
#include "common/hdf5_file.hpp"

namespace shaker::continuum {

namespace {
const char* const names[variable_count] = {"density", "momentum_x", "momentum_y", "momentum_z", "energy"};
}

void write_checkpoint(const std::filesystem::path& path, const TimeIntegrator& solver,
                      const std::string& configuration_toml) {
  const Grid& g = solver.op().grid();
  AtomicOutput output(path);
  {
    h5::Handle file = h5::create_file(output.temporary_path());
    h5::write_attribute(file.id(), "kind", std::string("shaker continuum checkpoint"));
    h5::write_attribute(file.id(), "time", solver.time());
    h5::write_attribute(file.id(), "dimension", std::int64_t{g.dimension});
    h5::write_attribute(file.id(), "nx", std::int64_t{g.nx});
    h5::write_attribute(file.id(), "ny", std::int64_t{g.ny});
    h5::write_attribute(file.id(), "nz", std::int64_t{g.nz});
    h5::write_attribute(file.id(), "cell_size", g.h);
    // The e in effect (after a single-shock switch, the switched one): a restart uses it.
    h5::write_attribute(file.id(), "e", solver.op().settings().e);
    const EnergyBudget& b = solver.budget();
    h5::write(file.id(), "energy_budget",
              std::vector<double>{b.body_work, b.collisional_loss, b.floor_energy});
    h5::write_attribute(file.id(), "configuration", configuration_toml);
    const Counters& k = solver.counters();
    h5::write(file.id(), "counters",
              std::vector<std::int64_t>{k.steps, k.rejected_steps, k.temperature_floor_uses,
                                        k.diffusion_stages});
    for (int v = 0; v < variable_count; ++v) {
      std::vector<double> data;
      data.reserve(g.interior_cells());
      for (int kz = 0; kz < g.nz; ++kz)
        for (int j = 0; j < g.ny; ++j)
          for (int i = 0; i < g.nx; ++i) data.push_back(solver.state().q[v][g.index(i, j, kz)]);
      h5::write(file.id(), names[v], data);
    }
  }
  output.commit();
}

void read_checkpoint(const std::filesystem::path& path, TimeIntegrator& solver) {
  const Grid& g = solver.op().grid();
  h5::Handle file = h5::open_file(path);
  if (!h5::has_attribute(file.id(), "kind") ||
      h5::read_string_attribute(file.id(), "kind") != "shaker continuum checkpoint")
    throw InputError(fmt::format("continuum.restart = \"{}\" is not a continuum checkpoint", path.string()));
  const auto check = [&](const char* key, std::int64_t expected) {
    const std::int64_t found = h5::read_integer_attribute(file.id(), key);
    if (found != expected)
      throw InputError(fmt::format("continuum.restart = \"{}\": checkpoint has {} = {}, the "
                                   "configuration needs {}", path.string(), key, found, expected));
  };
  check("dimension", g.dimension);
  check("nx", g.nx);
  check("ny", g.ny);
  check("nz", g.nz);
  if (h5::read_double_attribute(file.id(), "cell_size") != g.h)
    throw InputError(fmt::format("continuum.restart = \"{}\": cell size differs from continuum.cell_size = {}",
                                 path.string(), g.h));
  for (int v = 0; v < variable_count; ++v) {
    const std::vector<double> data = h5::read_doubles(file.id(), names[v]);
    std::size_t m = 0;
    for (int kz = 0; kz < g.nz; ++kz)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) solver.state().q[v][g.index(i, j, kz)] = data[m++];
  }
  solver.set_time(h5::read_double_attribute(file.id(), "time"));
  solver.op().settings().e = h5::read_double_attribute(file.id(), "e");
  const std::vector<double> budget = h5::read_doubles(file.id(), "energy_budget");
  if (budget.size() != 3)
    throw InputError(fmt::format("continuum.restart = \"{}\": energy_budget has {} entries, not 3",
                                 path.string(), budget.size()));
  solver.budget() = EnergyBudget{budget[0], budget[1], budget[2]};
  const auto counters = h5::read_integers(file.id(), "counters");
  solver.counters() = Counters{counters[0], counters[1], counters[2], counters[3]};
}

}  // namespace shaker::continuum
