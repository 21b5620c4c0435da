// The artificial dissipation forms and the inelastic walls' energy loss (operator.hpp), each on
// a state whose right-hand side is known exactly: only the term under test is on.
#include <cmath>

#include "common/granular_model.hpp"
#include "support.hpp"

namespace shaker::continuum::testing {
namespace {

/// Every physical term off; the artificial dissipation and the walls' loss stay available.
PhysicsSettings only_artificial(ArtificialForm form, double coefficient) {
  PhysicsSettings p;
  p.eos = EquationOfState::ideal_gas;
  p.terms = Terms{false, true, false, false, false, false, false, false, true};
  p.artificial.form = form;
  p.artificial.viscosity = coefficient;
  p.artificial.volume_fraction = 0.01;
  return p;
}

void set_column(const Grid& g, State& U, const std::function<Primitive(double z)>& at) {
  U.resize(g.size());
  for (int k = 0; k < g.nz; ++k) store_primitive(U, g.index(0, 0, k), at(g.center(k)));
}

TEST(SecondDifferenceDissipation, DiffusesADiluteDensityWaveAtItsDiffusivity) {
  Grid g = column(64, 16.0);
  g.z_boundary = ZBoundary::periodic;
  const double coefficient = 0.3, n0 = 1e-4, amplitude = 0.1, T = 2.0, k = 2.0 * pi / 16.0;
  Operator op(g, only_artificial(ArtificialForm::second_difference, coefficient));
  State U, dU;
  set_column(g, U, [&](double z) { return Primitive{n0 * (1.0 + amplitude * std::sin(k * z)), 0, 0, 0, T}; });
  dU.resize(g.size());
  op.rhs(0.0, U, dU);
  // D = coefficient h c s(nu): c of the ideal gas at rest, s within 1e-8 of 1 at nu ~ 5e-5.
  const double D = coefficient * g.h * std::sqrt(5.0 / 3.0 * T);
  const double discrete_decay = D * 4.0 / (g.h * g.h) * std::pow(std::sin(k * g.h / 2.0), 2);
  double worst_n = 0.0, worst_energy = 0.0, sum_n = 0.0, sum_E = 0.0;
  for (int i = 0; i < g.nz; ++i) {
    const std::ptrdiff_t c = g.index(0, 0, i);
    const double expected = -discrete_decay * n0 * amplitude * std::sin(k * g.center(i));
    worst_n = std::max(worst_n, std::abs(dU.q[density][c] - expected) / (discrete_decay * n0 * amplitude));
    // At uniform T the energy follows the density, E = 3/2 n T: T stays put (to rounding: the
    // second differences of E and n cancel to ~1e-12 of the wave's; a form that diffused T or
    // e instead would miss by O(1)).
    worst_energy = std::max(worst_energy, std::abs(dU.q[energy][c] - 1.5 * T * dU.q[density][c]) /
                                              (discrete_decay * n0 * amplitude));
    sum_n += dU.q[density][c];
    sum_E += dU.q[energy][c];
  }
  EXPECT_LT(worst_n, 1e-6);
  EXPECT_LT(worst_energy, 1e-10);
  EXPECT_LT(std::abs(sum_n), 1e-15);
  EXPECT_LT(std::abs(sum_E), 1e-14);
  // The explicit step it allows: h^2 / (2 D) (uniform D, to the switch's 1e-8).
  EXPECT_NEAR(op.artificial_step() * 2.0 * D / (g.h * g.h), 1.0, 1e-6);
}

TEST(SecondDifferenceDissipation, IsSwitchedOffInTheDenseLayer) {
  // A dense layer whose density rises quadratically, moving at uniform u_z: each face diffuses n
  // with D = C h (|u_z| + c) s(nu_face), s(0.3) ~ 1.2e-6, so the cells' rates are the formula's
  // and a millionth of what the unswitched form would give.
  Grid g = column(32, 8.0);
  const double C = 1.0, T = 1.0, uz = 0.1;
  const auto n_at = [](double z) { return number_density(0.3 * (1.0 + 0.01 * z + 0.005 * z * z)); };
  Operator op(g, only_artificial(ArtificialForm::second_difference, C));
  State U, dU;
  set_column(g, U, [&](double z) { return Primitive{n_at(z), 0, 0, uz, T}; });
  dU.resize(g.size());
  op.rhs(0.0, U, dU);
  const double speed = uz + std::sqrt(5.0 / 3.0 * T);
  const auto face_D = [&](double z_face, bool unswitched) {
    const double x = volume_fraction(0.5 * (n_at(z_face - 0.5 * g.h) + n_at(z_face + 0.5 * g.h))) / 0.01;
    return C * g.h * speed * (unswitched ? 1.0 : 1.0 / (1.0 + x * x * x * x));
  };
  double worst = 0.0, largest = 0.0, largest_unswitched = 0.0;
  for (int i = 1; i < g.nz - 1; ++i) {
    const double z = g.center(i), below = z - 0.5 * g.h, above = z + 0.5 * g.h;
    const auto rate = [&](bool unswitched) {
      return (face_D(above, unswitched) * (n_at(z + g.h) - n_at(z)) -
              face_D(below, unswitched) * (n_at(z) - n_at(z - g.h))) / (g.h * g.h);
    };
    const double got = dU.q[density][g.index(0, 0, i)];
    worst = std::max(worst, std::abs(got - rate(false)));
    largest = std::max(largest, std::abs(got));
    largest_unswitched = std::max(largest_unswitched, std::abs(rate(true)));
  }
  EXPECT_LT(worst, 1e-6 * largest);
  EXPECT_LT(largest, 1e-5 * largest_unswitched);
  double sum_n = 0.0, sum_E = 0.0;
  for (int i = 0; i < g.nz; ++i) {
    sum_n += dU.q[density][g.index(0, 0, i)];
    sum_E += dU.q[energy][g.index(0, 0, i)];
  }
  EXPECT_LT(std::abs(sum_n), 1e-15);  // no mass and no energy through the walls
  EXPECT_LT(std::abs(sum_E), 1e-15);
}

TEST(VonNeumannRichtmyerPressure, PushesBackAFlowIntoTheWallAndNothingElse) {
  // A uniform dilute gas falling at V onto the plate: only the plate face is in compression
  // (its mirror ghost rises at V), where q = C n (2 V)^2 s(nu); the ceiling face expands.
  Grid g = column(16, 4.0);
  const double C = 2.0, n = 1e-3, V = 0.7;
  Operator op(g, only_artificial(ArtificialForm::von_neumann_richtmyer, C));
  State U, dU;
  set_column(g, U, [&](double) { return Primitive{n, 0, 0, -V, 1.0}; });
  dU.resize(g.size());
  op.rhs(0.0, U, dU);
  const double x = volume_fraction(n) / 0.01, s = 1.0 / (1.0 + x * x * x * x);
  const double q = C * n * 4.0 * V * V * s;
  EXPECT_NEAR(dU.q[momentum_z][g.index(0, 0, 0)] * g.h / q, 1.0, 1e-13);
  for (int i = 1; i < g.nz; ++i) EXPECT_EQ(dU.q[momentum_z][g.index(0, 0, i)], 0.0) << "cell " << i;
  // The wall face's energy flux is q u_face = 0: nothing heats or cools.
  for (int i = 0; i < g.nz; ++i) EXPECT_EQ(dU.q[energy][g.index(0, 0, i)], 0.0) << "cell " << i;
  EXPECT_NEAR(op.artificial_step() / (g.h * g.h / (2.0 * 2.0 * C * g.h * 2.0 * V)), 1.0, 1e-13);
}

TEST(VonNeumannRichtmyerPressure, HeatsACompressionAtItsWork) {
  // Two streams meeting at the column's middle face: q at that face only, and its energy
  // flux carries q u_face with u_face = 0 there, so the energy the pressure adds is the work
  // done on the decelerating gas, equal and opposite in the two cells' kinetic energy.
  Grid g = column(8, 2.0);
  const double C = 1.0, n = 1e-3, V = 0.5;
  Operator op(g, only_artificial(ArtificialForm::von_neumann_richtmyer, C));
  State U, dU;
  set_column(g, U, [&](double z) { return Primitive{n, 0, 0, z < 1.0 ? V : -V, 1.0}; });
  dU.resize(g.size());
  op.rhs(0.0, U, dU);
  const double x = volume_fraction(n) / 0.01, s = 1.0 / (1.0 + x * x * x * x);
  const double q = C * n * 4.0 * V * V * s;
  const std::ptrdiff_t below = g.index(0, 0, 3), above = g.index(0, 0, 4);
  EXPECT_NEAR(dU.q[momentum_z][below] * g.h / -q, 1.0, 1e-13);
  EXPECT_NEAR(dU.q[momentum_z][above] * g.h / q, 1.0, 1e-13);
  EXPECT_EQ(dU.q[energy][below], 0.0);
  EXPECT_EQ(dU.q[energy][above], 0.0);
}

TEST(InelasticWalls, TakeTheKineticTheoryEnergyFluxFromTheWallCells) {
  for (const auto eos : {EquationOfState::ideal_gas, EquationOfState::granular}) {
    Grid g = column(10, 5.0);
    PhysicsSettings p;
    p.eos = eos;
    p.e = 0.8;
    p.terms = Terms{false, true, false, false, false, false, false, false, false};
    p.plate_energy = WallEnergy::inelastic;
    Operator op(g, p);
    State U, dU;
    const double nu = 0.2, T = 1.5;
    set_column(g, U, [&](double) { return Primitive{number_density(nu), 0, 0, 0, T}; });
    dU.resize(g.size());
    op.rhs(0.0, U, dU);
    const double n = number_density(nu);
    const double contact = eos == EquationOfState::ideal_gas ? n : model::pressure(n, T, p.e) / T;
    const double Q = (1.0 - 0.64) * contact * T * std::sqrt(T / (2.0 * pi));
    EXPECT_NEAR(dU.q[energy][g.index(0, 0, 0)] * g.h / -Q, 1.0, 1e-13);
    for (int i = 1; i < g.nz; ++i) EXPECT_EQ(dU.q[energy][g.index(0, 0, i)], 0.0) << "cell " << i;
    // The loss is part of the energy budget (per unit plate area).
    EXPECT_NEAR(op.source_power().loss / Q, 1.0, 1e-13);
    // Both walls when the ceiling is inelastic too.
    p.ceiling_energy = WallEnergy::inelastic;
    Operator both(g, p);
    both.rhs(0.0, U, dU);
    EXPECT_NEAR(dU.q[energy][g.index(0, 0, g.nz - 1)] * g.h / -Q, 1.0, 1e-13);
    EXPECT_NEAR(both.source_power().loss / (2.0 * Q), 1.0, 1e-13);
  }
}

TEST(ArtificialForms, AutomaticFollowsTheTransportVariant) {
  PhysicsSettings p;
  p.transport = model::Transport::paper;
  EXPECT_EQ(effective_artificial_form(p), ArtificialForm::transport_coefficients);
  p.transport = model::Transport::full;
  EXPECT_EQ(effective_artificial_form(p), ArtificialForm::none);
  p.artificial.form = ArtificialForm::von_neumann_richtmyer;
  EXPECT_EQ(effective_artificial_form(p), ArtificialForm::von_neumann_richtmyer);
  p.terms.artificial_dissipation = false;
  EXPECT_EQ(effective_artificial_form(p), ArtificialForm::none);
}

}  // namespace
}  // namespace shaker::continuum::testing
