#pragma once
// Shared helpers of the continuum tests: building solvers, norms, observed orders.
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "continuum/time_integrator.hpp"
#include "support/convergence.hpp"
#include "support/test_directory.hpp"

namespace shaker::continuum::testing {

/// Physics with only the Euler (Riemann) flux: the dilute ideal gas, gamma = 5/3.
inline PhysicsSettings euler_physics() {
  PhysicsSettings p;
  p.eos = EquationOfState::ideal_gas;
  p.terms = Terms{true, true, false, false, false, false, false, false, false};
  return p;
}

inline Grid column(int cells, double height, int dimension = 1, int horizontal = 1) {
  Grid g;
  g.dimension = dimension;
  g.nz = cells;
  g.h = height / cells;
  if (dimension == 3) g.nx = g.ny = horizontal;
  return g;
}

/// The observed order: fit_order(h, error, finest).order, the least-squares slope of log(error)
/// against log(h) over the `finest` levels with the smallest h.
using shaker::convergence::fit_order;

using shaker::testing::test_directory;

inline double total(const Grid& g, const State& s, int variable) {
  double sum = 0.0;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) sum += s.q[variable][g.index(i, j, k)];
  return sum * g.cell_volume();
}

}  // namespace shaker::continuum::testing
