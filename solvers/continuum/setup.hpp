#pragma once
// The typed, validated continuum configuration of a case (continuum.* keys and the shared
// case keys). Every inconsistency is an InputError naming the key and the allowed range.
#include <cstdint>
#include <memory>
#include <string>
#include <algorithm>
#include <vector>

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
  /// Stored phases k of run.phases_per_cycle = K (f t = k / K) whose 3D fields are written in
  /// the last cycle: continuum.field_phases, checked, in increasing order.
  std::vector<std::int64_t> field_phases;
  /// Cycles (of the run's schedule, from 0) in which they are written: continuum.field_cycles,
  /// checked, in increasing order; empty: the last cycle.
  std::vector<std::int64_t> field_cycles;
  /// Field snapshots the run writes.
  std::size_t field_snapshots() const { return field_phases.size() * std::max<std::size_t>(1, field_cycles.size()); }
};

ContinuumCase continuum_case(const config::Config& config);

/// A solver at the case's initial state (flat layer) at t = 0; with a `halo`, this rank's
/// block of it (the root lays out the whole box and scatters it: the same cells as a plain run).
TimeIntegrator make_solver(const ContinuumCase& c, std::shared_ptr<const Halo> halo = nullptr);

}  // namespace shaker::continuum
