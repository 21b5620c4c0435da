// Exact solutions for the granular model: homogeneous cooling (Haff's
// law, and the integrator's temporal order) and the hydrostatic rest state (spurious
// velocities converge at the scheme's order).
#include <cmath>

#include "support.hpp"

namespace shaker::continuum::testing {
namespace {

struct Scheme {
  int order, stages;
};

double haff_error(const Scheme& scheme, double dt, double t_end, double& T_end) {
  PhysicsSettings physics;
  physics.e = 0.9;
  physics.terms.gravity = physics.terms.frame_force = false;
  IntegratorSettings integration;
  integration.order = scheme.order;
  integration.stages = scheme.stages;
  integration.fixed_dt = dt;
  const Grid g = column(8, 8.0);
  TimeIntegrator solver(g, physics, integration);
  const double nu = 0.3, T0 = 1.0;
  for (int k = 0; k < g.nz; ++k)
    store_primitive(solver.state(), g.index(0, 0, k), Primitive{number_density(nu), 0, 0, 0, T0});
  solver.advance_to(t_end);
  const double exact = model::haff_temperature(t_end, T0, model::G(nu), physics.e);
  double worst = 0.0;
  for (int k = 0; k < g.nz; ++k) {
    T_end = to_primitive(solver.state(), g.index(0, 0, k)).T;
    worst = std::max(worst, std::abs(T_end - exact) / exact);
  }
  return worst;
}

class Haff : public ::testing::TestWithParam<Scheme> {};

TEST_P(Haff, MatchesTheExactCoolingAtTheIntegratorsOrder) {
  const Scheme scheme = GetParam();
  const int order = scheme.order;
  const double nu = 0.3, e = 0.9;
  const double t0 = 1.0 / (4.0 / std::sqrt(pi) * (1 - e * e) * model::G(nu));
  const double t_end = 3.0 * t0;  // T falls to T0 / 16
  std::vector<double> dts, errors, temperatures;
  for (int steps : {25, 50, 100, 200}) {
    double T_end = 0;
    dts.push_back(t_end / steps);
    errors.push_back(haff_error(scheme, t_end / steps, t_end, T_end));
    temperatures.push_back(T_end);
    std::printf("SSP-RK(%d,%d) dt = %.4g: relative error of T %.3e\n", order == 3 ? 3 : scheme.stages,
                order, dts.back(), errors.back());
  }
  const double observed = fit_order(dts, errors).order;
  std::printf("observed temporal order %.3f (design %d)\n", observed, order);
  EXPECT_NEAR(observed, order, 0.1);
  // The limit dt -> 0 is Haff's law itself: the Richardson extrapolation of the two finest
  // steps removes the leading error term and must leave far less than the finest error.
  const double fine = temperatures[3], coarse = temperatures[2];
  const double extrapolated = fine + (fine - coarse) / (std::pow(2.0, order) - 1.0);
  const double exact = model::haff_temperature(t_end, 1.0, model::G(nu), e);
  const double residual = std::abs(extrapolated - exact) / exact;
  std::printf("Richardson-extrapolated relative error %.3e (finest %.3e)\n", residual, errors.back());
  EXPECT_LT(residual, 0.05 * errors.back());
}
// SSP-RK(s,2) for s = 2 (Heun), 4 and 10, and SSP-RK3.
INSTANTIATE_TEST_SUITE_P(Integrators, Haff,
                         ::testing::Values(Scheme{2, 2}, Scheme{3, 2}, Scheme{2, 4}, Scheme{2, 10}),
                         [](const ::testing::TestParamInfo<Scheme>& p) {
                           return p.param.order == 3 ? std::string("SspRk3")
                                                     : "SspRk" + std::to_string(p.param.stages) + "2";
                         });

// Isothermal hydrostatic profile of the model's equation of state: d p / dz = -n g with
// p = n T chi(nu), i.e. dn/dz = -n g / (T (chi + nu dchi/dnu)); integrated with RK4.
struct Hydrostatic {
  double n0, T, e;
  double slope(double n) const {
    const double nu = volume_fraction(n);
    return -n * gravity / (T * (model::chi(nu, e) + nu * model::dchi_dnu(nu, e)));
  }
  /// Average of n over [a, b] by integrating the ODE from z = 0 with fine steps.
  std::vector<double> cell_averages(int cells, double height) const {
    const int sub = 64;
    const double dz = height / (cells * sub);
    std::vector<double> averages(cells, 0.0);
    double n = n0;
    for (int k = 0; k < cells; ++k) {
      double integral = 0.0;
      for (int s = 0; s < sub; ++s) {
        const double k1 = slope(n), k2 = slope(n + 0.5 * dz * k1), k3 = slope(n + 0.5 * dz * k2),
                     k4 = slope(n + dz * k3);
        const double next = n + dz / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        // Simpson on the substep with the RK4 midpoint estimate
        integral += dz / 6 * (n + 4 * (n + 0.5 * dz * k2) + next);
        n = next;
      }
      averages[k] = integral / (height / cells);
    }
    return averages;
  }
};

TEST(HydrostaticRest, SpuriousVelocitiesConvergeAtSecondOrder) {
  const Hydrostatic profile{number_density(0.3), 1.0, 1.0};
  const double height = 10.0, t_end = 4.0;
  PhysicsSettings physics;
  physics.e = 1.0;
  physics.terms.frame_force = false;
  physics.terms.artificial_dissipation = false;
  std::vector<double> h, l1, linf;
  for (int cells : {20, 40, 80, 160, 320}) {
    const Grid g = column(cells, height);
    TimeIntegrator solver(g, physics, IntegratorSettings{});
    const auto n = profile.cell_averages(cells, height);
    for (int k = 0; k < cells; ++k)
      store_primitive(solver.state(), g.index(0, 0, k), Primitive{n[k], 0, 0, 0, profile.T});
    solver.advance_to(t_end);
    double sum = 0, worst = 0, where = 0;
    for (int k = 0; k < cells; ++k) {
      const double u = std::abs(to_primitive(solver.state(), g.index(0, 0, k)).uz);
      sum += u * g.h;
      if (u > worst) {
        worst = u;
        where = g.center(k);
      }
    }
    h.push_back(g.h);
    l1.push_back(sum / height);
    linf.push_back(worst);
    std::printf("hydrostatic h = %.4g: mean |u| %.3e, max |u| %.3e at z = %.4g\n", g.h, l1.back(), worst, where);
  }
  const double order_l1 = fit_order(h, l1, 3).order;
  const double order_linf = fit_order(h, linf, 3).order;
  std::printf("observed orders: L1 %.3f, Linf %.3f (design 2)\n", order_l1, order_linf);
  // At least the design order (the L1 norm converges faster while the transient decays).
  EXPECT_GE(order_l1, 2.0 - 0.1);
  EXPECT_GE(order_linf, 2.0 - 0.1);
}

}  // namespace
}  // namespace shaker::continuum::testing

namespace shaker::continuum::testing {
namespace {

// Smooth flow: an entropy wave (uniform u and p, varying n) is an exact solution of the
// inviscid equations for any equation of state: pure translation. With the granular
// equation of state on a periodic column, one period of travel must reproduce the initial
// density at second order (L1; limiters clip smooth extrema, so Linf may be lower).
class SmoothEntropyWave : public ::testing::TestWithParam<Limiter> {};

TEST_P(SmoothEntropyWave, ConvergesAtSecondOrder) {
  PhysicsSettings physics;
  physics.limiter = GetParam();
  physics.terms = Terms{true, true, false, false, false, false, false, false, false};
  std::vector<double> h, l1, linf;
  const double nu0 = 0.2, speed = 1.0, pressure = 1.0;
  for (int cells : {32, 64, 128, 256, 512}) {
    Grid g = column(cells, 1.0);
    g.z_boundary = ZBoundary::periodic;
    IntegratorSettings integration;
    integration.order = 3;
    TimeIntegrator solver(g, physics, integration);
    const auto n_exact = [&](double z) {  // cell average of n0 (1 + 0.2 sin(2 pi z))
      const double a = z - 0.5 * g.h, b = z + 0.5 * g.h;
      return number_density(nu0) * (1.0 + 0.2 * (std::cos(2 * pi * a) - std::cos(2 * pi * b)) / (2 * pi * g.h));
    };
    for (int k = 0; k < cells; ++k) {
      const double n = n_exact(g.center(k));
      const double T = pressure / (n * model::chi(volume_fraction(n), physics.e));
      store_primitive(solver.state(), g.index(0, 0, k), Primitive{n, 0, 0, speed, T});
    }
    solver.advance_to(1.0 / speed);
    double sum = 0, worst = 0;
    for (int k = 0; k < cells; ++k) {
      const double error = std::abs(solver.state().q[density][g.index(0, 0, k)] - n_exact(g.center(k)));
      sum += error * g.h;
      worst = std::max(worst, error);
    }
    h.push_back(g.h);
    l1.push_back(sum);
    linf.push_back(worst);
    std::printf("entropy wave h = %.5f: L1 %.3e, Linf %.3e\n", g.h, sum, worst);
  }
  const double order_l1 = fit_order(h, l1, 3).order;
  const double order_linf = fit_order(h, linf, 3).order;
  std::printf("observed orders over the 3 finest grids: L1 %.3f, Linf %.3f\n", order_l1, order_linf);
  EXPECT_GE(order_l1, 2.0 - 0.1);
  if (GetParam() == Limiter::none) {
    EXPECT_GE(order_linf, 2.0 - 0.1);
  }
}
INSTANTIATE_TEST_SUITE_P(Limiters, SmoothEntropyWave, ::testing::Values(Limiter::mc, Limiter::none),
                         [](const auto& param_info) {
                           return std::string(param_info.param == Limiter::mc ? "mc" : "none");
                         });

}  // namespace
}  // namespace shaker::continuum::testing
