#pragma once
// Horizontally averaged fields in bins at fixed phases of the cycle (docs/models.md, "Sampling"):
// n, u and T pooled over all particles found in a bin at that phase in all sampled cycles.
// The sums of each cycle are kept (common/cycle_samples.hpp) for standard errors and for the
// analysis's jackknife.
#include <limits>
#include <vector>

#include "common/cycle_samples.hpp"
#include "common/profile.hpp"
#include "common/run_loop.hpp"
#include "common/shaker_kinematics.hpp"
#include "md/particles.hpp"
#include "md/simulation.hpp"

namespace shaker::md {

class PhaseSampler {
 public:
  /// Bins of bin_height from z = 0 (the plate's lowest point) up to `top`, lab frame.
  PhaseSampler(int phases, double bin_height, double top, double box_area);

  /// Adds one snapshot of phase index k (0 <= k < phases) taken at time t.
  void add(int k, double t, const std::vector<Vec3>& r, const std::vector<Vec3>& v);

  /// One profile per phase with at least one snapshot, averaged over the snapshots added.
  std::vector<Profile> profiles(const ShakerKinematics& shaker) const;
  /// The per-cycle sums behind the profiles, restricted to the phases with a snapshot.
  CycleSamples samples() const;
  /// Every phase's sums so far, also mid-cycle (what a checkpoint keeps).
  const CycleSamples& store() const { return samples_; }
  /// Takes up the sums of a run continued from a checkpoint (`saved`: a store() of the same
  /// phases and bins), whose first snapshot at phase k was taken at first_times[k].
  void resume(CycleSamples saved, const std::vector<double>& first_times);

 private:
  int phases_;
  std::size_t bins_;
  double bin_height_;
  CycleSamples samples_;
  std::vector<double> first_time_;   // per phase
  std::vector<int> cycles_;          // snapshots per phase
  std::vector<BinSums> scratch_;     // one snapshot
};

/// Positions and velocities of every particle at one time, computed once for all the
/// observers that read them (the run loop's times increase strictly, so a time names a state).
class PhaseSnapshot {
 public:
  explicit PhaseSnapshot(const Simulation& simulation) : simulation_(simulation) {}
  /// Takes the snapshot at t >= the simulation's time, unless it is already at t.
  void take(double t);
  const std::vector<Vec3>& r() const { return r_; }
  const std::vector<Vec3>& v() const { return v_; }

 private:
  const Simulation& simulation_;
  double t_ = std::numeric_limits<double>::quiet_NaN();  ///< NaN: none taken
  std::vector<Vec3> r_, v_;
};

/// A PhaseSampler fed by the run loop: every stored phase of every sampled cycle.
class SamplingObserver final : public RunObserver {
 public:
  SamplingObserver(PhaseSampler& sampler, PhaseSnapshot& snapshot) : sampler_(sampler), snapshot_(snapshot) {}
  void at_phase(const PhaseInstant& instant) override;

 private:
  PhaseSampler& sampler_;
  PhaseSnapshot& snapshot_;
};

}  // namespace shaker::md
