// Normal shock: a uniform granular gas falling at speed U onto the plate (no gravity, no
// collisional loss, no transport: the granular equation of state with the Riemann flux). The reflected shock's
// speed and the state behind it must satisfy the Rankine–Hugoniot relations of the model's
// equation of state, solved numerically here (the dense case has no closed form).
#include <cmath>

#include "support.hpp"

namespace shaker::continuum::testing {
namespace {

struct Upstream {
  double n, T, U, e;
};
struct Downstream {
  double n, T, speed;
};

// Wall frame, gas at rest behind the shock: mass n1 U = s (n2 - n1); energy
// (E1 + p1) U = s (E2 - E1); momentum p2 = p1 + n1 U (U + s). The first two give n2 and T2
// for a trial s; bisection on the momentum residual gives s.
Downstream rankine_hugoniot(const Upstream& a) {
  const double p1 = model::pressure(a.n, a.T, a.e);
  const double E1 = a.n * (1.5 * a.T + 0.5 * a.U * a.U);
  auto state = [&](double s) {
    const double n2 = a.n * (s + a.U) / s;
    const double T2 = (E1 + (E1 + p1) * a.U / s) / (1.5 * n2);
    return Downstream{n2, T2, s};
  };
  auto residual = [&](double s) {
    const Downstream d = state(s);
    if (!(volume_fraction(d.n) < nu_max)) return 1e300;  // too slow: over-compressed
    return model::pressure(d.n, d.T, a.e) - p1 - a.n * a.U * (a.U + s);
  };
  double lo = 1e-3, hi = 100.0;
  while (residual(lo) < 0) lo *= 0.5;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (residual(mid) > 0 ? lo : hi) = mid;
  }
  return state(0.5 * (lo + hi));
}

struct Measured {
  double n, T, speed;
};

Measured simulate(const Upstream& a, double h) {
  PhysicsSettings physics;
  physics.e = a.e;
  physics.terms.gravity = physics.terms.frame_force = false;
  physics.terms.collisional_loss = false;
  physics.terms.artificial_dissipation = false;
  // Inviscid: the transport terms give the shock a physical width of a few mean free paths,
  // whose effect on a short run does not vanish with h; the jump conditions concern the
  // equation of state.
  physics.terms.shear_viscosity = physics.terms.bulk_viscosity = physics.terms.conduction = false;
  const double height = 60.0;  // the rarefaction leaving the ceiling must not reach the shock
  const Grid g = column(static_cast<int>(std::lround(height / h)), height);
  TimeIntegrator solver(g, physics, IntegratorSettings{});
  for (int k = 0; k < g.nz; ++k)
    store_primitive(solver.state(), g.index(0, 0, k), Primitive{a.n, 0, 0, -a.U, a.T});
  const Downstream rh = rankine_hugoniot(a);
  const double level = 0.5 * (a.n + rh.n);
  auto shock_position = [&]() {  // lowest height where n falls below the mid level
    for (int k = 0; k < g.nz; ++k)
      if (solver.state().q[density][g.index(0, 0, k)] < level) {
        const double n0 = solver.state().q[density][g.index(0, 0, k - 1)];
        const double n1 = solver.state().q[density][g.index(0, 0, k)];
        return g.center(k - 1) + g.h * (n0 - level) / (n0 - n1);
      }
    return height;
  };
  const double t1 = 1.5, t2 = 3.5;
  solver.advance_to(t1);
  const double z1 = shock_position();
  solver.advance_to(t2);
  const double z2 = shock_position();
  // Downstream plateau: away from the wall (wall heating) and from the shock.
  double n_sum = 0, T_sum = 0;
  int count = 0;
  for (int k = 0; k < g.nz; ++k)
    if (g.center(k) > 0.3 * z2 && g.center(k) < 0.7 * z2) {
      const Primitive w = to_primitive(solver.state(), g.index(0, 0, k));
      n_sum += w.n;
      T_sum += w.T;
      ++count;
    }
  return {n_sum / count, T_sum / count, (z2 - z1) / (t2 - t1)};
}

class NormalShock : public ::testing::TestWithParam<double> {};

TEST_P(NormalShock, SatisfiesRankineHugoniotOfTheModel) {
  const Upstream upstream{number_density(GetParam()), 1.0, 2.0, 0.9};
  const Downstream rh = rankine_hugoniot(upstream);
  std::printf("upstream nu = %.3f: Rankine-Hugoniot nu2 = %.5f, T2 = %.5f, shock speed %.5f\n",
              GetParam(), volume_fraction(rh.n), rh.T, rh.speed);
  std::vector<double> worst;
  for (double h : {0.2, 0.1, 0.05}) {
    const Measured m = simulate(upstream, h);
    const double en = std::abs(m.n - rh.n) / rh.n, eT = std::abs(m.T - rh.T) / rh.T,
                 es = std::abs(m.speed - rh.speed) / rh.speed;
    std::printf("h = %.3f: nu2 %.5f (%.2e), T2 %.5f (%.2e), speed %.5f (%.2e)\n", h,
                volume_fraction(m.n), en, m.T, eT, m.speed, es);
    worst.push_back(std::max({en, eT, es}));
  }
  // Stated tolerance, shrinking with resolution: 2% at h = 0.2, halved with each halving of h
  // (the first-order error of a captured shock).
  for (std::size_t i = 0; i < worst.size(); ++i)
    EXPECT_LT(worst[i], 0.02 / std::pow(2.0, static_cast<double>(i))) << "level " << i;
}

INSTANTIATE_TEST_SUITE_P(DiluteAndDense, NormalShock, ::testing::Values(0.05, 0.3));

}  // namespace
}  // namespace shaker::continuum::testing
