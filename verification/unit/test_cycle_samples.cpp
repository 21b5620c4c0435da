// The MD profiles formed from per-cycle sums (common/cycle_samples.hpp) on hand-made sums:
// exact values where they are defined, NaN where they are not (a bin without particles has no
// u_z, one with fewer than two no T, a spread needs two samples), n = 0 in an empty bin, and
// the same rule in the leave-one-out profiles of the jackknife.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "analysis/run_analysis.hpp"
#include "common/cycle_samples.hpp"
#include "common/profile.hpp"
#include "common/units.hpp"

namespace {

using shaker::BinSums;
using shaker::CycleSamples;
using shaker::Profile;

/// Sums of particles with the given vertical velocities (vx = vy = 0).
BinSums particles(const std::vector<double>& vz) {
  BinSums s;
  for (double v : vz) {
    s.count += 1.0;
    s.vz += v;
    s.v2 += v * v;
  }
  return s;
}

// Four bins over three cycles: bin 0 holds two particles every cycle, bin 1 none ever, bin 2
// one particle in one cycle, bin 3 three particles in the last cycle only.
constexpr double bin_volume = 2.0;
CycleSamples four_bins() {
  CycleSamples s(1, 4, bin_volume);
  s.add_cycle(0, {particles({1.0, 3.0}), {}, {}, {}});
  s.add_cycle(0, {particles({2.0, 4.0}), {}, particles({5.0}), {}});
  s.add_cycle(0, {particles({0.0, 6.0}), {}, {}, particles({-1.0, 0.0, 4.0})});
  return s;
}

TEST(CycleSamples, UndefinedValuesAreNaNAndAnEmptyBinHasZeroDensity) {
  Profile p;
  four_bins().pool(0, p);
  // Bin 0: six velocities 1, 3, 2, 4, 0, 6: mean 8/3; per cycle u_z = 2, 3, 3.
  EXPECT_DOUBLE_EQ(p.n[0], 6.0 / (3.0 * bin_volume));
  EXPECT_DOUBLE_EQ(p.uz[0], 16.0 / 6.0);
  EXPECT_DOUBLE_EQ(p.T[0], (66.0 / 6.0 - (16.0 / 6.0) * (16.0 / 6.0)) / 3.0);
  EXPECT_NEAR(p.uz_se[0], std::sqrt(1.0 / 3.0 / 3.0), 1e-15);  // spread of 2, 3, 3
  EXPECT_EQ(p.n_se[0], 0.0);  // two particles every cycle: no spread in n
  EXPECT_TRUE(std::isfinite(p.T_se[0]));

  // Bin 1, empty: zero density (defined), no velocity, no temperature, no spreads of them.
  EXPECT_EQ(p.n[1], 0.0);
  EXPECT_EQ(p.nu[1], 0.0);
  EXPECT_EQ(p.samples[1], 0.0);
  EXPECT_EQ(p.n_se[1], 0.0);
  EXPECT_TRUE(std::isnan(p.uz[1]));
  EXPECT_TRUE(std::isnan(p.T[1]));
  EXPECT_TRUE(std::isnan(p.uz_se[1]));
  EXPECT_TRUE(std::isnan(p.T_se[1]));

  // Bin 2, one particle: its velocity, but no temperature; one sample with a particle has
  // no spread.
  EXPECT_DOUBLE_EQ(p.n[2], 1.0 / (3.0 * bin_volume));
  EXPECT_EQ(p.uz[2], 5.0);
  EXPECT_TRUE(std::isnan(p.T[2]));
  EXPECT_TRUE(std::isnan(p.uz_se[2]));
  EXPECT_TRUE(std::isnan(p.T_se[2]));

  // Bin 3, three particles in one cycle: u_z and T defined, their spreads over cycles not.
  EXPECT_DOUBLE_EQ(p.uz[3], 1.0);
  EXPECT_DOUBLE_EQ(p.T[3], (17.0 / 3.0 - 1.0) / 3.0);
  EXPECT_TRUE(std::isnan(p.uz_se[3]));
  EXPECT_TRUE(std::isnan(p.T_se[3]));
  EXPECT_TRUE(std::isfinite(p.n_se[3]));
}

TEST(CycleSamples, ABinEmptiedByLeavingOutASampleBecomesUndefined) {
  shaker::RunRecord run;
  run.samples = four_bins();
  run.profiles.resize(1);
  run.samples.pool(0, run.profiles[0]);
  // Leaving out the last cycle empties bin 3, the middle one bin 2 loses its particle.
  const Profile without_last = shaker::analysis::profiles_without(run, 2).front();
  EXPECT_EQ(without_last.n[3], 0.0);
  EXPECT_TRUE(std::isnan(without_last.uz[3]));
  EXPECT_TRUE(std::isnan(without_last.T[3]));
  EXPECT_EQ(without_last.uz[2], 5.0);
  const Profile without_middle = shaker::analysis::profiles_without(run, 1).front();
  EXPECT_EQ(without_middle.n[2], 0.0);
  EXPECT_TRUE(std::isnan(without_middle.uz[2]));
  // Bin 0 keeps its defined values: cycles 1 and 3, velocities 1, 3, 0, 6.
  EXPECT_DOUBLE_EQ(without_middle.uz[0], 2.5);
  EXPECT_DOUBLE_EQ(without_middle.T[0], (46.0 / 4.0 - 6.25) / 3.0);
}

}  // namespace
