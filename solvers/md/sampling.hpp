#pragma once
// Horizontally averaged fields in bins at fixed phases of the cycle (docs/models.md, "Sampling"):
// n, u and T pooled over all particles found in a bin at that phase in all sampled cycles,
// and the per-cycle values kept for standard errors.
#include <vector>

#include "common/profile.hpp"
#include "common/shaker_kinematics.hpp"
#include "md/particles.hpp"

namespace shaker::md {

class PhaseSampler {
 public:
  /// Bins of bin_height from z = 0 (the plate's lowest point) up to `top`, lab frame.
  PhaseSampler(int phases, double bin_height, double top, double box_width);

  /// Adds one snapshot of phase index k (0 <= k < phases) taken at time t.
  void add(int k, double t, const std::vector<Vec3>& r, const std::vector<Vec3>& v);

  /// One profile per phase, averaged over the snapshots added.
  std::vector<Profile> profiles(const ShakerKinematics& shaker) const;

 private:
  struct Bin {
    double count = 0.0, vx = 0.0, vy = 0.0, vz = 0.0, v2 = 0.0;  // pooled sums
    double n_sum = 0.0, n_sq = 0.0;                             // per-cycle n
    double uz_sum = 0.0, uz_sq = 0.0, uz_cycles = 0.0;          // per-cycle u_z
    double T_sum = 0.0, T_sq = 0.0, T_cycles = 0.0;             // per-cycle T
  };
  int phases_;
  std::size_t bins_;
  double bin_height_, bin_volume_;
  std::vector<Bin> data_;            // phases x bins
  std::vector<double> first_time_;   // per phase
  std::vector<int> cycles_;          // snapshots per phase
  std::vector<Bin> scratch_;         // one snapshot
};

}  // namespace shaker::md
