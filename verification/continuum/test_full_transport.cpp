// The `full` transport variant (all terms of mu and kappa, stiff in the dilute gas) runs
// through the implicit diffusion step: that step conserves mass and total energy, and the
// base case runs with steps set by the advective limit, not by the explicit diffusive one.
#include <cmath>
#include <random>

#include "continuum/implicit_diffusion.hpp"
#include "continuum/setup.hpp"
#include "support.hpp"

namespace shaker::continuum::testing {
namespace {

TEST(ImplicitDiffusion, ConservesMassAndEnergy) {
  for (int dimension : {1, 3}) {
    Grid g = column(40, 20.0, dimension, dimension == 3 ? 4 : 1);
    PhysicsSettings physics;
    physics.transport = model::Transport::full;
    Operator op(g, physics);
    State U;
    U.resize(g.size());
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> r(0.0, 1.0);
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i)
          store_primitive(U, g.index(i, j, k),
                          Primitive{number_density(1e-4 + 0.5 * r(random)), r(random) - 0.5,
                                    r(random) - 0.5, r(random) - 0.5, 0.1 + r(random)});
    const double mass = total(g, U, density), total_energy = total(g, U, energy);
    ImplicitDiffusion implicit(g);
    implicit.advance(op, U, 0.5);
    const double mass_change = std::abs(total(g, U, density) - mass) / mass;
    const double energy_change = std::abs(total(g, U, energy) - total_energy) / total_energy;
    std::printf("%dD implicit diffusion step: relative change of mass %.3e, of energy %.3e\n",
                dimension, mass_change, energy_change);
    EXPECT_EQ(mass_change, 0.0);
    EXPECT_LT(energy_change, 1e-10);
  }
}

TEST(FullTransport, BaseCaseRunsAtTheAdvectiveStep) {
  config::Config c;
  c.set("continuum.transport=full");
  c.set("continuum.cell_size=0.5");
  const ContinuumCase cc = continuum_case(c);
  TimeIntegrator solver = make_solver(cc);
  // the explicit diffusive limit of the initial state
  State probe = solver.state(), rate = solver.state();
  solver.op().rhs(0.0, probe, rate);
  const double explicit_step = solver.op().diffusive_step();
  const double period = cc.parameters.shaker.period();
  const double m0 = total(cc.grid, solver.state(), density);
  solver.advance_to(period);
  const double m1 = total(cc.grid, solver.state(), density);
  const double explicit_steps = period / explicit_step;
  std::printf("full transport, one cycle at h = 0.5: %lld steps (%lld rejected); the explicit "
              "diffusive limit would need %.3g; mass change %.3e; floor uses %lld\n",
              static_cast<long long>(solver.counters().steps),
              static_cast<long long>(solver.counters().rejected_steps), explicit_steps,
              (m1 - m0) / m0, static_cast<long long>(solver.counters().temperature_floor_uses));
  // At least an order of magnitude fewer steps than the explicit diffusive limit would take.
  EXPECT_LT(static_cast<double>(solver.counters().steps), 0.1 * explicit_steps);
  EXPECT_LT(std::abs(m1 - m0) / m0, 1e-13);
}

}  // namespace
}  // namespace shaker::continuum::testing
