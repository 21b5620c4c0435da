// The automatic-differentiation source terms of mms_source.hpp against an independent
// evaluation: eighth-order central finite differences in long double of the same fields,
// with the stress and heat flux assembled separately here and differentiated numerically.
// Truncation (h = 0.05, wavenumbers <= 1.6) and rounding (long double) are both below 1e-11;
// the stated tolerance is |AD - FD| <= 1e-9 (1 + |R|) for every equation.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "cell_average.hpp"
#include "mms_source.hpp"

namespace mms = shaker::mms;
using shaker::model::Transport;
using LD = long double;
using Point4 = std::array<LD, 4>;  // t, x, y, z

namespace {

constexpr double tolerance = 1e-9;

/// d g / d X[a] by the eighth-order central difference.
template <class G> LD partial(const G& g, const Point4& X, int a, LD step) {
  static constexpr std::array<LD, 4> weight{4.0L / 5.0L, -1.0L / 5.0L, 4.0L / 105.0L,
                                            -1.0L / 280.0L};
  LD sum = 0.0L;
  for (int k = 1; k <= 4; ++k) {
    Point4 plus = X, minus = X;
    plus[a] += static_cast<LD>(k) * step;
    minus[a] -= static_cast<LD>(k) * step;
    sum += weight[k - 1] * (g(plus) - g(minus));
  }
  return sum / step;
}

struct FiniteDifferenceResidual {
  mms::ManufacturedSolution solution;
  mms::Physics physics;
  mms::Terms terms;
  LD step = 0.05L;

  mms::Fields<LD> fields(const Point4& X) const { return solution(X[0], X[1], X[2], X[3]); }
  LD component(const Point4& X, int which) const {  // 0 n, 1-3 u, 4 T
    const auto f = fields(X);
    return which == 0 ? f.n : which == 4 ? f.T : f.u[which - 1];
  }
  LD d(int which, const Point4& X, int a) const {
    return partial([&](const Point4& Y) { return component(Y, which); }, X, a, step);
  }

  LD stress(const Point4& X, int i, int j) const {
    const auto f = fields(X);
    std::array<std::array<LD, 3>, 3> grad{};
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) grad[k][l] = d(k + 1, X, l + 1);
    const LD divergence = grad[0][0] + grad[1][1] + grad[2][2];
    const LD p = terms.pressure ? shaker::model::pressure(f.n, f.T, physics.e) : 0.0L;
    const LD lambda = terms.bulk_viscosity ? shaker::model::bulk_viscosity(f.n, f.T) : 0.0L;
    const LD mu =
        terms.shear_viscosity ? shaker::model::shear_viscosity(f.n, f.T, physics.transport) : 0.0L;
    LD value = mu * (grad[i][j] + grad[j][i]);
    if (i == j) value += -p + (lambda - 2.0L / 3.0L * mu) * divergence;
    return value;
  }
  LD heat_flux(const Point4& X, int j) const {
    if (!terms.conduction) return 0.0L;
    const auto f = fields(X);
    return -shaker::model::thermal_conductivity(f.n, f.T, physics.transport) * d(4, X, j + 1);
  }

  std::array<LD, 5> operator()(double t, const std::array<double, 3>& x) const {
    const Point4 X{t, x[0], x[1], x[2]};
    const auto f = fields(X);
    std::array<LD, 5> r{};  // mass, momentum x, y, z, energy
    if (terms.time_derivative) r[0] += d(0, X, 0);
    LD stress_power = 0.0L;
    for (int j = 0; j < 3; ++j) {
      if (terms.advection)
        r[0] += partial([&](const Point4& Y) { return component(Y, 0) * component(Y, j + 1); }, X,
                        j + 1, step);
    }
    for (int i = 0; i < 3; ++i) {
      if (terms.time_derivative) r[1 + i] += f.n * d(i + 1, X, 0);
      for (int j = 0; j < 3; ++j) {
        if (terms.advection) r[1 + i] += f.n * f.u[j] * d(i + 1, X, j + 1);
        r[1 + i] -= partial([&](const Point4& Y) { return stress(Y, i, j); }, X, j + 1, step);
        stress_power += stress(X, i, j) * d(i + 1, X, j + 1);
      }
    }
    LD body = 0.0L;
    if (terms.gravity) body -= shaker::gravity;
    if (terms.frame_forcing) body -= physics.shaker.acceleration(t);
    r[3] -= f.n * body;
    if (terms.time_derivative) r[4] += 1.5L * f.n * d(4, X, 0);
    for (int j = 0; j < 3; ++j) {
      if (terms.advection) r[4] += 1.5L * f.n * f.u[j] * d(4, X, j + 1);
      r[4] += partial([&](const Point4& Y) { return heat_flux(Y, j); }, X, j + 1, step);
    }
    r[4] -= stress_power;
    if (terms.collisional_loss) r[4] += shaker::model::collisional_loss(f.n, f.T, physics.e);
    return r;
  }
};

std::array<double, 5> as_array(const mms::Residual& r) {
  return {r.mass, r.momentum[0], r.momentum[1], r.momentum[2], r.energy};
}

// Every single term, then all together.
const std::vector<std::string> term_names{"time_derivative", "advection",     "pressure",
                                          "bulk_viscosity",  "shear_viscosity", "conduction",
                                          "collisional_loss", "gravity",      "frame_forcing",
                                          "all"};
mms::Terms only(const std::string& name) {
  if (name == "all") return mms::Terms{};
  mms::Terms t = mms::Terms::none();
  bool* flags[] = {&t.time_derivative, &t.advection,        &t.pressure,
                   &t.bulk_viscosity,  &t.shear_viscosity,  &t.conduction,
                   &t.collisional_loss, &t.gravity,         &t.frame_forcing};
  for (std::size_t k = 0; k + 1 < term_names.size(); ++k)
    if (term_names[k] == name) *flags[k] = true;
  return t;
}

mms::ManufacturedSolution solution_of(int dimension, bool walls = true) {
  mms::ManufacturedSolution s;
  s.dimension = dimension;
  s.wall_compatible = walls;
  return s;
}

const std::vector<std::pair<double, std::array<double, 3>>> sample_points{
    {0.3, {1.7, 4.2, 2.3}}, {7.9, {9.1, 0.6, 6.8}}, {13.4, {5.5, 10.2, 9.4}}};

}  // namespace

using SourceCase = std::tuple<int, Transport, std::string, bool>;
class AdAgainstFiniteDifferences : public ::testing::TestWithParam<SourceCase> {};

TEST_P(AdAgainstFiniteDifferences, PrimitiveResidualAgrees) {
  const auto [dimension, transport, term, walls] = GetParam();
  const mms::Physics physics{0.9, transport, {3.0, 0.095}};
  const FiniteDifferenceResidual fd{solution_of(dimension, walls), physics, only(term)};
  double worst = 0.0, largest = 0.0;
  for (const auto& [t, x] : sample_points) {
    const auto ad = as_array(mms::primitive_residual(fd.solution, physics, fd.terms, t, x));
    const auto reference = fd(t, x);
    for (std::size_t k = 0; k < 5; ++k) {
      const double deviation = std::abs(ad[k] - static_cast<double>(reference[k]));
      worst = std::max(worst, deviation / (1.0 + std::abs(ad[k])));
      largest = std::max(largest, std::abs(ad[k]));
      EXPECT_LE(deviation, tolerance * (1.0 + std::abs(ad[k])))
          << "equation " << k << " at t = " << t << ": AD " << ad[k] << ", FD "
          << static_cast<double>(reference[k]);
    }
  }
  RecordProperty("worst_relative_deviation", fmt::format("{:.3e}", worst));
  // The term is really exercised: some equation has a residual of order one.
  EXPECT_GT(largest, 1e-3) << "term " << term << " contributes nothing";
}

INSTANTIATE_TEST_SUITE_P(
    EveryTerm, AdAgainstFiniteDifferences,
    ::testing::Combine(::testing::Values(1, 3), ::testing::Values(Transport::paper, Transport::full),
                       ::testing::ValuesIn(term_names), ::testing::Values(true)),
    [](const ::testing::TestParamInfo<SourceCase>& param_info) {
      const auto& p = param_info.param;
      // fmt, not operator+: GCC 12 gives a false -Wrestrict on chained string concatenation.
      return fmt::format("d{}_{}_{}", std::get<0>(p), shaker::model::to_string(std::get<1>(p)),
                         std::get<2>(p));
    });

INSTANTIATE_TEST_SUITE_P(
    ShiftedPhases, AdAgainstFiniteDifferences,
    ::testing::Combine(::testing::Values(1, 3), ::testing::Values(Transport::paper, Transport::full),
                       ::testing::Values(std::string("all")), ::testing::Values(false)),
    [](const ::testing::TestParamInfo<SourceCase>& param_info) {
      const auto& p = param_info.param;
      return fmt::format("d{}_{}_not_wall_compatible", std::get<0>(p),
                         shaker::model::to_string(std::get<1>(p)));
    });

// The conservative form is the primitive one recombined with the mass and momentum residuals:
// S_i = R_i + u_i R_n, S_E = R_E + u . R + (|u|^2/2 + 3T/2) R_n, term by term.
TEST(ConservativeSource, IsThePrimitiveResidualRecombined) {
  for (int dimension : {1, 3}) {
    const auto solution = solution_of(dimension);
    const mms::Physics physics{0.9, Transport::full, {3.0, 0.095}};
    for (const auto& term : term_names) {
      const mms::Terms terms = only(term);
      for (const auto& [t, x] : sample_points) {
        const mms::Residual r = mms::primitive_residual(solution, physics, terms, t, x);
        const mms::Residual s = mms::conservative_source(solution, physics, terms, t, x);
        const auto f = solution(t, x[0], x[1], x[2]);
        const double specific_energy =
            0.5 * (f.u[0] * f.u[0] + f.u[1] * f.u[1] + f.u[2] * f.u[2]) + 1.5 * f.T;
        EXPECT_NEAR(s.mass, r.mass, 1e-13);
        double work = 0.0;
        for (int i = 0; i < 3; ++i) {
          EXPECT_NEAR(s.momentum[i], r.momentum[i] + f.u[i] * r.mass, 1e-12)
              << term << " d" << dimension;
          work += f.u[i] * r.momentum[i];
        }
        EXPECT_NEAR(s.energy, r.energy + work + specific_energy * r.mass, 1e-12)
            << term << " d" << dimension;
      }
    }
  }
}

TEST(ManufacturedSolution, SatisfiesTheWallConditionsAtBothWalls) {
  const auto solution = solution_of(3, true);
  const mms::Physics physics;
  double worst_uz = 0.0, worst_gradient = 0.0;
  for (double t : {0.0, 2.1, 8.6})
    for (double x : {0.4, 5.0})
      for (double y : {1.3, 9.9})
        for (double z : {0.0, solution.Lz}) {
          using mms::detail::seed;
          const auto f = solution(seed(t, 0), seed(x, 1), seed(y, 2), seed(z, 3));
          worst_uz = std::max(worst_uz, std::abs(f.u[2].value().value()));
          for (const auto* q : {&f.n, &f.T, &f.u[0], &f.u[1]})
            worst_gradient = std::max(worst_gradient, std::abs(q->derivatives()(3).value()));
        }
  EXPECT_LE(worst_uz, 1e-15);
  EXPECT_LE(worst_gradient, 1e-15);

  const auto shifted = solution_of(3, false);
  EXPECT_GT(std::abs(shifted(1.0, 2.0, 3.0, 0.0).u[2]), 1e-2);
}

// wall_gradients keeps the wall conditions (u_z = 0, zero normal gradient of T) and adds what
// they allow and a mirror ghost lacks: n' != 0 and u_z'' != 0 at both walls.
TEST(ManufacturedSolution, WallGradientsKeepTheWallConditions) {
  mms::ManufacturedSolution s = solution_of(1, true);
  s.wall_gradients = true;
  const double delta = 1e-4;
  for (double t : {0.0, 2.1, 8.6})
    for (double z : {0.0, s.Lz}) {
      const auto at = [&](double dz) { return s(t, 0.0, 0.0, z + dz); };
      const auto centre = at(0.0), up = at(delta), down = at(-delta);
      EXPECT_LE(std::abs(centre.u[2]), 1e-15) << "t " << t << ", z " << z;
      EXPECT_LE(std::abs(up.T - down.T) / (2.0 * delta), 1e-9) << "T', t " << t << ", z " << z;
      EXPECT_GT(std::abs(up.n - down.n) / (2.0 * delta), 1e-2) << "n', t " << t << ", z " << z;
      EXPECT_GT(std::abs(up.u[2] - 2.0 * centre.u[2] + down.u[2]) / (delta * delta), 1e-2)
          << "u_z'', t " << t << ", z " << z;
    }
}

TEST(ManufacturedSolution, StaysInsideTheModelDomain) {
  for (int dimension : {1, 3}) {
    const auto solution = solution_of(dimension);
    double nu_low = 1.0, nu_high = 0.0, T_low = 1e9, T_high = 0.0;
    for (int it = 0; it < 16; ++it)
      for (int ix = 0; ix < 12; ++ix)
        for (int iy = 0; iy < 12; ++iy)
          for (int iz = 0; iz <= 40; ++iz) {
            const auto f = solution(0.9 * it, solution.Lx * ix / 12.0, solution.Ly * iy / 12.0,
                                    solution.Lz * iz / 40.0);
            const double nu = shaker::volume_fraction(f.n);
            nu_low = std::min(nu_low, nu);
            nu_high = std::max(nu_high, nu);
            T_low = std::min(T_low, f.T);
            T_high = std::max(T_high, f.T);
          }
    EXPECT_GE(nu_low, 0.13) << "d" << dimension;
    EXPECT_LE(nu_high, 0.29) << "d" << dimension;  // under 0.45 nu_max
    EXPECT_GE(T_low, 0.55) << "d" << dimension;
    EXPECT_LE(T_high, 1.45) << "d" << dimension;
  }
}

TEST(ManufacturedSolution, ThreeDimensionalFieldsVaryInEveryDirectionAndTime) {
  const auto solution = solution_of(3);
  using mms::detail::seed;
  const auto f = solution(seed(1.1, 0), seed(2.3, 1), seed(3.7, 2), seed(4.9, 3));
  const std::array<const mms::detail::Second*, 5> fields{&f.n, &f.u[0], &f.u[1], &f.u[2], &f.T};
  for (std::size_t k = 0; k < fields.size(); ++k)
    for (int a = 0; a < 4; ++a)
      EXPECT_GT(std::abs(fields[k]->derivatives()(a).value()), 1e-4)
          << "field " << k << " direction " << a;
  // 1D: nothing depends on x or y and the horizontal velocity is zero.
  const auto one = solution_of(1)(seed(1.1, 0), seed(2.3, 1), seed(3.7, 2), seed(4.9, 3));
  EXPECT_EQ(one.n.derivatives()(1).value(), 0.0);
  EXPECT_EQ(one.T.derivatives()(2).value(), 0.0);
  EXPECT_EQ(one.u[0].value().value(), 0.0);
  EXPECT_GT(std::abs(one.u[2].derivatives()(3).value()), 1e-3);
}

TEST(MmsSource, TransportVariantsDiffer) {
  const auto solution = solution_of(1);
  mms::Physics paper{0.9, Transport::paper, {3.0, 0.095}};
  mms::Physics full{0.9, Transport::full, {3.0, 0.095}};
  const std::array<double, 3> x{0.0, 0.0, 3.3};
  const auto a = mms::primitive_residual(solution, paper, mms::Terms{}, 2.0, x);
  const auto b = mms::primitive_residual(solution, full, mms::Terms{}, 2.0, x);
  EXPECT_GT(std::abs(a.energy - b.energy), 1e-3);
  EXPECT_GT(std::abs(a.momentum[2] - b.momentum[2]), 1e-4);
}

// ---- Cell averages (cell_average.hpp) -------------------------------------------------------

TEST(CellAverage, ThreePointGaussIsExactForQuinticsAndSixthOrderForSines) {
  const auto quintic = [](const std::array<double, 3>& x) {
    return 1.0 + x[2] - 2.0 * std::pow(x[2], 3) + 0.5 * std::pow(x[2], 5);
  };
  // Average over [0.5, 1.5] (width 1) from the antiderivative.
  const auto antiderivative = [](double z) {
    return z + z * z / 2.0 - std::pow(z, 4) / 2.0 + std::pow(z, 6) / 12.0;
  };
  const double exact = antiderivative(1.5) - antiderivative(0.5);
  EXPECT_NEAR(mms::cell_average(quintic, {0.0, 0.0, 1.0}, {1.0, 1.0, 1.0}, 1), exact, 1e-14);

  // 3D: average of sin(x) cos(y) sin(z) over a box is a product of 1D averages.
  const auto wave = [](const std::array<double, 3>& x) {
    return std::sin(x[0]) * std::cos(x[1]) * std::sin(x[2]);
  };
  const std::array<double, 3> centre{0.7, -0.4, 1.9};
  std::vector<double> errors;
  for (double h : {0.4, 0.2}) {
    const double ax = (std::cos(centre[0] - h / 2) - std::cos(centre[0] + h / 2)) / h;
    const double ay = (std::sin(centre[1] + h / 2) - std::sin(centre[1] - h / 2)) / h;
    const double az = (std::cos(centre[2] - h / 2) - std::cos(centre[2] + h / 2)) / h;
    errors.push_back(std::abs(mms::cell_average(wave, centre, {h, h, h}, 3) - ax * ay * az));
  }
  EXPECT_LT(errors[0], 1e-8);
  const double order = std::log(errors[0] / errors[1]) / std::log(2.0);
  EXPECT_NEAR(order, 6.0, 0.2) << "errors " << errors[0] << ", " << errors[1];
}

TEST(CellAverage, AveragedSourceApproachesThePointSourceAtSecondOrder) {
  for (int dimension : {1, 3}) {
    const auto solution = solution_of(dimension);
    const mms::Physics physics;
    const std::array<double, 3> centre{3.1, 7.2, 4.4};
    const double t = 2.5;
    const auto point = mms::conservative_source(solution, physics, mms::Terms{}, t, centre);
    std::vector<double> differences;
    for (double h : {0.2, 0.1}) {
      const auto average = mms::average_conservative_source(solution, physics, mms::Terms{}, t,
                                                            centre, {h, h, h});
      differences.push_back(std::abs(average.energy - point.energy));
    }
    EXPECT_NEAR(std::log(differences[0] / differences[1]) / std::log(2.0), 2.0, 0.05)
        << "d" << dimension << ": " << differences[0] << ", " << differences[1];
    const auto fields = mms::average_fields(solution, t, centre, {0.1, 0.1, 0.1});
    const auto exact = solution(t, centre[0], centre[1], centre[2]);
    EXPECT_NEAR(fields.n, exact.n, 1e-3);
    EXPECT_GT(std::abs(fields.n - exact.n), 0.0);
  }
}
