#include "continuum/setup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/errors.hpp"
#include "common/ranks.hpp"
#include "common/units.hpp"
#include "continuum/halo.hpp"

namespace shaker::continuum {

namespace {

/// continuum.field_phases as stored phases k of K; only a 3D run writes full fields.
std::vector<std::int64_t> field_phase_indices(const config::Config& config, int dimension,
                                              std::int64_t phases) {
  constexpr const char* key = "continuum.field_phases";
  if (config.real_list(key).empty()) return {};
  if (dimension != 3)
    throw InputError(fmt::format("{} = {}: full fields are written only by a 3D run, and "
                                 "continuum.dimension = {}; allowed with it: [] (the default)",
                                 key, config.value_text(key), dimension));
  return stored_phase_indices(config, key, phases);
}

/// continuum.field_cycles, each a cycle of the run with field phases to write in it.
std::vector<std::int64_t> field_cycle_indices(const config::Config& config, const ContinuumCase& c) {
  constexpr const char* key = "continuum.field_cycles";
  if (!config.real_list(key).empty() && c.field_phases.empty())
    throw InputError(fmt::format("{} = {} without continuum.field_phases writes nothing; allowed: [] (the "
                                 "default), or continuum.field_phases set", key, config.value_text(key)));
  return cycle_indices(config, key, c.parameters.run);
}

/// The 3D box's edge in y: continuum.box_depth, or continuum.box_width where that is 0.
double box_depth(const config::Config& config) {
  const double depth = config.real("continuum.box_depth");
  return depth > 0.0 ? depth : config.real("continuum.box_width");
}

/// A 3D layer's cells are drawn up to (1 + p) times the layer's density and then all scaled
/// by the mass correction, at most 1 / (1 - p): both keys together must keep every cell below
/// the clamp at 0.999 nu_max, where the constitutive functions end.
void check_perturbation(const LayerSpecification& l, int dimension) {
  if (dimension != 3) return;
  const double ratio = 0.999 * nu_max / l.volume_fraction;
  const double largest = (ratio - 1.0) / (ratio + 1.0);
  if (l.perturbation >= largest)
    throw InputError(fmt::format(
        "continuum.perturbation = {} with continuum.initial_volume_fraction = {} can put a cell of "
        "the initial layer at nu = {:.4g} (after the mass correction), at or past 0.999 nu_max = {:.4g}; allowed: "
        "0 <= continuum.perturbation < {:.4g} at this volume fraction (or a lower "
        "continuum.initial_volume_fraction)", l.perturbation, l.volume_fraction,
        l.volume_fraction * (1.0 + l.perturbation) / (1.0 - l.perturbation), 0.999 * nu_max, largest));
}
}  // namespace

ContinuumCase continuum_case(const config::Config& config) {
  ContinuumCase c;
  c.parameters = CaseParameters::from(config);
  c.grid = make_grid(static_cast<int>(config.integer("continuum.dimension")),
                     config.real("continuum.box_width"), box_depth(config), config.real("continuum.ceiling"),
                     config.real("continuum.cell_size"), launched_by_mpi() ? Ranks::world().size() : 1);
  PhysicsSettings& p = c.physics;
  p.eos = EquationOfState::granular;
  p.e = c.parameters.restitution.e;
  p.transport = model::transport_from_string(config.text("continuum.transport"));
  p.limiter = limiter_from_string(config.text("continuum.limiter"));
  p.riemann = riemann_from_string(config.text("continuum.riemann"));
  p.shaker = c.parameters.shaker;
  p.artificial = ArtificialDissipation{artificial_form_from_string(config.text("continuum.artificial_dissipation")),
                                       config.real("continuum.artificial_viscosity"),
                                       config.real("continuum.artificial_conductivity"),
                                       config.real("continuum.artificial_volume_fraction")};
  p.plate_energy = wall_energy_from_string("continuum.plate_energy", config.text("continuum.plate_energy"));
  p.ceiling_energy = wall_energy_from_string("continuum.ceiling_energy", config.text("continuum.ceiling_energy"));
  IntegratorSettings& i = c.integration;
  i.order = static_cast<int>(config.integer("continuum.integrator_order"));
  i.stages = static_cast<int>(config.integer("continuum.integrator_stages"));
  if (i.order == 3 && i.stages != 2)
    throw InputError(fmt::format("continuum.integrator_stages = {} needs continuum.integrator_order = 2 "
                                 "(SSP-RK3 is the three-stage Shu-Osher scheme); allowed with order 3: 2, "
                                 "the default", i.stages));
  i.cfl = config.real("continuum.cfl");
  i.diffusion_number = config.real("continuum.diffusion_number");
  i.temperature_floor = config.real("continuum.temperature_floor");
  const std::string diffusion = config.text("continuum.diffusion_integrator");
  if (diffusion == "rkl2")
    i.diffusion = DiffusionIntegrator::rkl2;
  else if (diffusion == "implicit_extrapolated" || (diffusion == "auto" && p.transport == model::Transport::full))
    i.diffusion = DiffusionIntegrator::implicit_extrapolated;
  else if (diffusion == "implicit")
    i.diffusion = DiffusionIntegrator::implicit;
  else
    i.diffusion = DiffusionIntegrator::explicit_rk;
  p.wall_stress = config.text("continuum.wall_stress") == "second_order" ? WallStress::second_order
                                                                          : WallStress::mirror;
  LayerSpecification& l = c.layer;
  l.mass_per_area = c.parameters.mass_per_area();
  l.volume_fraction = config.real("continuum.initial_volume_fraction");
  l.background_volume_fraction = config.real("continuum.background_volume_fraction");
  l.temperature = config.real("continuum.initial_temperature");
  l.perturbation = config.real("continuum.perturbation");
  check_perturbation(l, c.grid.dimension);
  l.seed = c.parameters.run.seed;
  c.field_phases = field_phase_indices(config, c.grid.dimension, c.parameters.run.phases_per_cycle);
  c.field_cycles = field_cycle_indices(config, c);
  // The layer must fit under the ceiling: checked now, before anything runs or is written, on
  // one column of the grid (the check depends on the height alone; a whole 3D box would cost
  // every rank of a decomposed run the memory of the box's state).
  Grid column = c.grid;
  column.dimension = 1;
  column.nx = column.ny = 1;
  State probe;
  probe.resize(column.size());
  flat_layer(column, c.layer, probe);
  return c;
}

TimeIntegrator make_solver(const ContinuumCase& c, std::shared_ptr<const Halo> halo) {
  if (!halo) {
    TimeIntegrator solver(c.grid, c.physics, c.integration);
    flat_layer(c.grid, c.layer, solver.state());
    return solver;
  }
  TimeIntegrator solver(halo->local(), c.physics, c.integration, halo);
  State box;  // the random perturbation is drawn in the box's cell order: only the root draws
  if (halo->root()) {
    box.resize(c.grid.size());
    flat_layer(c.grid, c.layer, box);
  }
  halo->scatter(box, solver.state());
  return solver;
}

}  // namespace shaker::continuum
