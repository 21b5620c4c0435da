#include "continuum/setup.hpp"

#include <fmt/format.h>

#include "common/errors.hpp"

namespace shaker::continuum {

ContinuumCase continuum_case(const config::Config& config) {
  ContinuumCase c;
  c.parameters = CaseParameters::from(config);
  c.grid = make_grid(static_cast<int>(config.integer("continuum.dimension")),
                     config.real("continuum.box_width"), config.real("continuum.ceiling"),
                     config.real("continuum.cell_size"));
  PhysicsSettings& p = c.physics;
  p.eos = EquationOfState::granular;
  p.e = c.parameters.restitution.e;
  p.transport = model::transport_from_string(config.text("continuum.transport"));
  p.limiter = limiter_from_string(config.text("continuum.limiter"));
  p.riemann = riemann_from_string(config.text("continuum.riemann"));
  p.shaker = c.parameters.shaker;
  p.artificial = ArtificialDissipation{config.real("continuum.artificial_viscosity"),
                                       config.real("continuum.artificial_conductivity"),
                                       config.real("continuum.artificial_volume_fraction")};
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
  LayerSpecification& l = c.layer;
  l.mass_per_area = c.parameters.mass_per_area();
  l.volume_fraction = config.real("continuum.initial_volume_fraction");
  l.background_volume_fraction = config.real("continuum.background_volume_fraction");
  l.temperature = config.real("continuum.initial_temperature");
  l.perturbation = config.real("continuum.perturbation");
  l.seed = c.parameters.run.seed;
  c.field_phases = config.real_list("continuum.field_phases");
  // The layer must fit under the ceiling: checked now, before anything runs or is written.
  State probe;
  probe.resize(c.grid.size());
  flat_layer(c.grid, c.layer, probe);
  return c;
}

TimeIntegrator make_solver(const ContinuumCase& c) {
  TimeIntegrator solver(c.grid, c.physics, c.integration);
  flat_layer(c.grid, c.layer, solver.state());
  return solver;
}

}  // namespace shaker::continuum
