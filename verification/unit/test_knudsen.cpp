// The local Knudsen numbers of a profile (analysis.hpp, knudsen_numbers) on profiles whose
// central differences are known exactly: an exponential density at uniform T and a linear T.
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/analysis.hpp"
#include "common/granular_model.hpp"
#include "common/units.hpp"

namespace {

using namespace shaker;
using namespace shaker::analysis;

Profile column(std::size_t bins, double h, double (*n)(double), double (*T)(double)) {
  Profile p;
  p.bin_height = h;
  for (std::size_t i = 0; i < bins; ++i) {
    const double z = (static_cast<double>(i) + 0.5) * h;
    p.z.push_back(z);
    p.n.push_back(n(z));
    p.nu.push_back(volume_fraction(n(z)));
    p.T.push_back(T(z));
    p.uz.push_back(0.0);
  }
  return p;
}

constexpr double decay_length = 3.0;
double exponential(double z) { return 0.5 * std::exp(-z / decay_length); }
double uniform(double) { return 2.0; }
double linear(double z) { return 1.0 + 0.25 * z; }

TEST(KnudsenNumbers, OfAnExponentialDensityAreTheMeanFreePathOverItsDecayLength) {
  const double h = 0.5;
  const Profile p = column(40, h, exponential, uniform);
  const KnudsenNumbers kn = knudsen_numbers(p);
  for (std::size_t i = 1; i + 1 < p.size(); ++i) {
    // The central difference of exp(-z/L) is exp(-z/L) sinh(h/L) / h exactly.
    const double expected = model::mean_free_path(p.n[i]) * std::sinh(h / decay_length) / h;
    EXPECT_NEAR(kn.density[i] / expected, 1.0, 1e-12) << "bin " << i;
    EXPECT_EQ(kn.temperature[i], 0.0) << "bin " << i;
  }
  // One-sided at the ends: (1 - exp(-h/L)) / h relative to the end bin.
  const double bottom = model::mean_free_path(p.n[0]) * (1.0 - std::exp(-h / decay_length)) / h;
  EXPECT_NEAR(kn.density[0] / bottom, 1.0, 1e-12);
  // Kn grows with height as the gas thins: xi ~ 1 / n.
  EXPECT_GT(kn.density[38], 100.0 * kn.density[1]);
}

TEST(KnudsenNumbers, OfALinearTemperatureAreItsSlopeTimesXiOverT) {
  const Profile p = column(20, 1.0, uniform, linear);
  const KnudsenNumbers kn = knudsen_numbers(p);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double expected = model::mean_free_path(2.0) * 0.25 / linear(p.z[i]);
    EXPECT_NEAR(kn.temperature[i] / expected, 1.0, 1e-12) << "bin " << i;
    EXPECT_EQ(kn.density[i], 0.0) << "bin " << i;
  }
}

TEST(KnudsenNumbers, AreUndefinedWithoutMaterialAndOneSidedBesideIt) {
  Profile p = column(10, 1.0, uniform, linear);
  p.n[4] = p.nu[4] = 0.0;
  p.T[4] = 0.0;
  const KnudsenNumbers kn = knudsen_numbers(p);
  EXPECT_TRUE(std::isnan(kn.density[4]));
  EXPECT_TRUE(std::isnan(kn.temperature[4]));
  // Bin 3 takes the one-sided difference to bin 2: T' = 0.25 still.
  EXPECT_NEAR(kn.temperature[3] / (model::mean_free_path(2.0) * 0.25 / linear(p.z[3])), 1.0, 1e-12);
  // A bin with material between two empty ones has no gradient.
  p.n[2] = p.nu[2] = 0.0;
  EXPECT_TRUE(std::isnan(knudsen_numbers(p).density[3]));
}

TEST(KnudsenMassFraction, CountsTheMaterialAboveTheLimit) {
  // Four bins of equal density but one with a steep temperature rise: only the two bins that
  // see it (it and its lower neighbour, by the central difference) exceed the limit.
  Profile p = column(4, 1.0, uniform, uniform);
  p.T = {1.0, 1.0, 1.0, 3.0};
  const KnudsenNumbers kn = knudsen_numbers(p);
  const double xi = model::mean_free_path(2.0);
  EXPECT_NEAR(kn.temperature[2], xi * 1.0 / 1.0, 1e-15);  // (3 - 1) / 2 sigma over T = 1
  EXPECT_NEAR(kn.temperature[3], xi * 2.0 / 3.0, 1e-15);  // one-sided at the top
  EXPECT_EQ(kn.temperature[0], 0.0);
  EXPECT_DOUBLE_EQ(knudsen_mass_fraction(p, kn, 0.5 * xi), 0.5);
  EXPECT_DOUBLE_EQ(knudsen_mass_fraction(p, kn, 0.8 * xi), 0.25);
  EXPECT_DOUBLE_EQ(knudsen_mass_fraction(p, kn, 2.0 * xi), 0.0);
}

}  // namespace
