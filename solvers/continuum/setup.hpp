#pragma once
// The typed, validated continuum configuration of a case (continuum.* keys and the shared
// case keys). Every inconsistency is an InputError naming the key and the allowed range.
#include "common/case_parameters.hpp"
#include "common/config.hpp"
#include "continuum/initial_state.hpp"
#include "continuum/time_integrator.hpp"

namespace shaker::continuum {

struct ContinuumCase {
  CaseParameters parameters;
  Grid grid;
  PhysicsSettings physics;
  IntegratorSettings integration;
  LayerSpecification layer;
  std::vector<double> field_phases;
};

ContinuumCase continuum_case(const config::Config& config);

/// A solver at the case's initial state (flat layer) at t = 0.
TimeIntegrator make_solver(const ContinuumCase& c);

}  // namespace shaker::continuum
