// Unit tests of the analysis library (solvers/analysis/analysis.hpp) on synthetic profiles
// whose answers are known: tanh temperature shocks of known centre and width, layers with
// known crossings, densities with a closed-form centre of mass, profiles with no shock (clean
// and with MD-like noise), and the agreement metrics on inputs with known differences.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "analysis/analysis.hpp"
#include "analysis/run_analysis.hpp"
#include "common/granular_model.hpp"
#include "common/units.hpp"
#include "test_support.hpp"

namespace {

using namespace shaker;
using namespace shaker::analysis;
using Field = std::function<double(double)>;

/// A profile on bins of height h with centres z0 + (i + 1/2) h, from fields of height.
Profile make_profile(const Field& nu, const Field& T, const Field& uz, std::size_t bins = 60,
                     double h = 1.0, double z0 = 0.0) {
  Profile p;
  p.bin_height = h;
  for (std::size_t i = 0; i < bins; ++i) {
    const double z = z0 + (static_cast<double>(i) + 0.5) * h;
    p.z.push_back(z);
    p.nu.push_back(nu(z));
    p.n.push_back(number_density(nu(z)));
    p.T.push_back(T(z));
    p.uz.push_back(uz(z));
  }
  return p;
}

/// 1 well below zs, 0 well above, a tanh step of width w.
double step_down(double z, double zs, double w) { return 0.5 * (1.0 - std::tanh((z - zs) / w)); }

// The shock of physics.md: a dense compressed layer moving with the plate below zs, a less
// dense layer falling onto it above; T rises with height in both (slope 0.05) and drops by
// 5 in the shock. The layer ends 14 above the shock. The falling layer comes in at
// `inflow_speed` relative to the plate, supersonic as in the base case (Ma 3-11 at the bottom
// of the undisturbed region from f t = 0.12 to 0.32, MD and continuum): Ma about 2.4 here.
constexpr double temperature_slope = 0.05, temperature_jump = 5.0, inflow_speed = 7.0;
Profile shock_profile(double zs, double w, double plate_v = 1.0) {
  const auto layer_top = [zs](double z) { return step_down(z, zs + 14.0, 1.5); };
  Profile p = make_profile(
      [=](double z) { return (0.2 + 0.3 * step_down(z, zs, w)) * layer_top(z); },
      [=](double z) {
        return 0.5 + temperature_slope * z + temperature_jump * step_down(z, zs, w);
      },
      [=](double z) {
        return plate_v * step_down(z, zs, w) + (plate_v - inflow_speed) * (1.0 - step_down(z, zs, w));
      });
  p.plate_v = plate_v;
  return p;
}

/// Distance between the temperature maximum and minimum of the continuous tanh profile.
double continuous_shock_width(double w) {
  // dT/dz = slope - jump / (2 w) sech^2(x / w) = 0
  return 2.0 * w * std::acosh(1.0 / std::sqrt(2.0 * w * temperature_slope / temperature_jump));
}

// ---- the shock ------------------------------------------------------------------------------

TEST(FindShock, LocatesATanhShockToAFractionOfABin) {
  // The steepest drop between bin centres alone would be half a bin off at worst; the
  // parabola through the three largest drops is within these fractions of a bin, and the
  // better the shock is resolved the closer (the parabola's error falls like (h / w)^2).
  const std::vector<std::pair<double, double>> width_and_bound{{0.5, 0.2}, {1.0, 0.1}, {2.0, 0.04}};
  for (const auto& [w, bound] : width_and_bound) {
    double worst = 0.0;
    for (double zs : {10.0, 12.3, 14.5, 15.77, 18.2, 18.45, 18.6}) {
      SCOPED_TRACE(::testing::Message() << "centre " << zs << ", width " << w);
      const Profile p = shock_profile(zs, w);
      const auto shock = find_shock(p);
      ASSERT_TRUE(shock.has_value());
      worst = std::max(worst, std::abs(shock->location - zs) / p.bin_height);
      EXPECT_LT(shock->compressed_top, zs);
      EXPECT_GT(shock->undisturbed_bottom, zs);
      EXPECT_DOUBLE_EQ(shock->width, shock->undisturbed_bottom - shock->compressed_top);
      // The mean free path is taken at the shock location, n interpolated linearly there.
      const auto k = static_cast<std::size_t>(shock->location / p.bin_height - 0.5);
      const double s = (shock->location - p.z[k]) / p.bin_height;
      EXPECT_NEAR(shock->mean_free_path,
                  model::mean_free_path((1.0 - s) * p.n[k] + s * p.n[k + 1]), 1e-12);
      EXPECT_DOUBLE_EQ(shock->width_over_mfp(), shock->width / shock->mean_free_path);
    }
    std::printf("[measured] tanh width %.1f bins: largest location error %.3f bins\n", w, worst);
    EXPECT_LE(worst, bound) << "width " << w;
  }
}

TEST(FindShock, LocationMovesContinuouslyWithTheShock) {
  // A grid study needs a location that follows the shock between bins: shifting a shock two
  // bins wide by a tenth of a bin must move the location by a tenth, up to twice the 0.04-bin
  // bound above (a bin-centred location would stand still, then jump by a whole bin).
  double previous = find_shock(shock_profile(14.0, 2.0))->location;
  for (int step = 1; step <= 10; ++step) {
    const double zs = 14.0 + 0.1 * step;
    const auto shock = find_shock(shock_profile(zs, 2.0));
    ASSERT_TRUE(shock.has_value()) << zs;
    EXPECT_NEAR(shock->location - previous, 0.1, 0.08) << "shock at " << zs;
    previous = shock->location;
  }
}

TEST(FindShock, WidthGrowsWithTheTanhWidth) {
  double previous = 0.0;
  for (double w : {0.5, 1.0, 2.0, 3.0}) {
    const auto shock = find_shock(shock_profile(14.0, w));
    ASSERT_TRUE(shock.has_value()) << "w = " << w;
    EXPECT_GT(shock->width, previous) << "w = " << w;
    // Each end of the discrete region lies within half a bin of the continuous extremum.
    EXPECT_NEAR(shock->width, continuous_shock_width(w), 1.0) << "w = " << w;
    std::printf("[measured] tanh width %.1f: d = %.2f (continuous %.2f)\n", w, shock->width,
                continuous_shock_width(w));
    previous = shock->width;
  }
}

TEST(FindShock, CountsAShockWhoseCompressedRegionIsThinnerThanABin) {
  // The temperature maximum sits in the lowest bin above the plate (physics.md).
  const auto shock = find_shock(shock_profile(1.0, 0.3));
  ASSERT_TRUE(shock.has_value());
  EXPECT_EQ(shock->compressed_top, 0.5);
  EXPECT_EQ(shock->location, 1.0);
}

TEST(FindShock, CountsTheLowestBinAboveThePlateEvenWhenThePlateCutsIt) {
  // MD bins are fixed in the lab frame: the plate at 2.3 leaves 0.7 of the bin [2, 3] open,
  // so that bin's density is under-counted below the layer threshold. Its temperature
  // maximum still marks a forming shock (physics.md).
  Profile p = shock_profile(4.0, 0.5, 1.0);
  p.plate_z = 2.3;
  for (std::size_t i = 0; i < 2; ++i) {
    p.n[i] = p.nu[i] = 0.0;  // below the plate: no particles, so no T and no u_z
    p.T[i] = p.uz[i] = std::numeric_limits<double>::quiet_NaN();
  }
  p.nu[2] = 0.02;
  p.n[2] = number_density(0.02);
  p.T[2] = 30.0;
  const auto shock = find_shock(p);
  ASSERT_TRUE(shock.has_value());
  EXPECT_EQ(shock->compressed_top, 2.5);
}

TEST(FindShock, ReportsNoneWhenTheFlowIsNotDeceleratedAcrossTheDrop) {
  // The temperature structure of a shock, but the material below moves as fast towards the
  // plate as the material above: nothing has stopped it, so it is not a shock.
  Profile p = shock_profile(14.0, 1.0);
  ASSERT_TRUE(find_shock(p).has_value());
  std::fill(p.uz.begin(), p.uz.end(), -2.0);
  EXPECT_FALSE(find_shock(p).has_value());
}

TEST(FindShock, TheShockLeavesTheLayerWhenItsSteepestDropIsAboveTheLayerTop) {
  // The layer ends 14 above the shock in shock_profile; cut it just above the shock instead.
  Profile inside = shock_profile(14.0, 1.0);
  Profile outside = inside;
  for (std::size_t i = 0; i < inside.size(); ++i) {
    if (inside.z[i] > 15.0) inside.nu[i] = inside.n[i] = 0.02;
    if (outside.z[i] > 13.0) outside.nu[i] = outside.n[i] = 0.02;
  }
  EXPECT_TRUE(find_shock(inside).has_value());
  EXPECT_FALSE(find_shock(outside).has_value());
}

TEST(FindShock, TheSyntheticShockHasASupersonicInflow) {
  const Profile p = shock_profile(14.0, 1.0);
  const auto shock = find_shock(p);
  ASSERT_TRUE(shock.has_value());
  const auto k = static_cast<std::size_t>(shock->undisturbed_bottom / p.bin_height);
  ASSERT_DOUBLE_EQ(p.z[k], shock->undisturbed_bottom);
  const double ma = mach_number(p, 0.9)[k];
  EXPECT_GT(ma, 2.0);
  EXPECT_LT(ma, 12.0);
  std::printf("[measured] synthetic shock: Ma at the bottom of the undisturbed region %.2f\n", ma);
}

/// The continuum's gap gas (base case, full transport, cell 0.25, f t = 0.94): dilute gas
/// (nu 0.018) between the plate (moving down at 1.9) and the falling layer (nu 0.3 above
/// z = 12), hot at the plate (T 2.3) and falling into the cold layer (T 0.06); the gas is
/// dragged down towards the plate, the layer falls at 0.9 relative to it. gas_nu = 0.018 is
/// the run's value; a larger value turns the gap into layer material.
Profile gap_gas_profile(double gas_nu) {
  const double plate_v = -1.9;
  Profile p = make_profile(
      [=](double z) { return gas_nu + (0.3 - gas_nu) * (1.0 - step_down(z, 11.0, 1.5)); },
      [](double z) {
        const double above = std::max(0.0, z - 14.0);
        return 0.06 + 2.4 * step_down(z, 3.0, 2.0) + 0.02 * above * above;
      },
      [=](double z) {
        const double in_gas = step_down(z, 11.0, 1.5);
        return plate_v - in_gas * 2.5 * (1.0 - std::exp(-z / 2.0)) - (1.0 - in_gas) * 0.9;
      },
      80, 0.5);
  p.plate_v = plate_v;
  return p;
}

TEST(FindShock, ReportsNoneForTheGasSqueezedBetweenThePlateAndAFallingLayer) {
  // T falls steeply from the hot gap gas into the layer, and the flow relative to the plate
  // is slower at the plate than in the layer: the temperature and velocity structure of a
  // shock, but in gas below the layer (nu 0.018 < 0.026), not in the layer.
  const Profile gap = gap_gas_profile(0.018);
  EXPECT_GT(find_layer(gap)->bottom, 8.0);  // the layer is still above the plate
  EXPECT_FALSE(find_shock(gap).has_value());
  // Control: the same structure in layer material (nu 0.06) is a forming shock, so it is the
  // material, not the shape, that decides.
  const auto forming = find_shock(gap_gas_profile(0.06));
  ASSERT_TRUE(forming.has_value());
  EXPECT_LT(forming->location, 5.0);
}

TEST(FindShock, ReportsNoneForAMonotoneTemperature) {
  const Profile p =
      make_profile([](double z) { return 0.55 * step_down(z, 12.0, 2.0); },
                   [](double z) { return 0.2 + 0.1 * z; }, [](double) { return 0.0; });
  EXPECT_FALSE(find_shock(p).has_value());
  // Also when it falls monotonically with height (a layer heated from above is not a shock).
  const Profile falling =
      make_profile([](double z) { return 0.55 * step_down(z, 12.0, 2.0); },
                   [](double z) { return 8.0 - 0.1 * z; }, [](double) { return 0.0; });
  EXPECT_FALSE(find_shock(falling).has_value());
}

double gaussian_layer(double z) { return 0.4 * std::exp(-0.5 * std::pow((z - 25.0) / 4.0, 2)); }

TEST(FindShock, ReportsNoneForAUniformlyHotFlyingLayer) {
  EXPECT_FALSE(
      find_shock(make_profile(
                     gaussian_layer, [](double) { return 3.0; }, [](double) { return 1.5; }))
          .has_value());
  // MD style: the empty bins above and below the layer report T = 0.
  const Profile md = make_profile(
      gaussian_layer, [](double z) { return gaussian_layer(z) > 1e-3 ? 3.0 : 0.0; },
      [](double) { return 1.5; });
  EXPECT_FALSE(find_shock(md).has_value());
}

TEST(FindShock, ReportsNoneForTheHotDiluteLowerEdgeOfAFallingLayer) {
  // T is high where the layer is dilute (both edges) and lowest in its dense middle; the fall
  // from the hot lower edge into the dense middle is not a shock.
  const Profile p = make_profile(
      gaussian_layer, [](double z) { return 0.5 + 2.0 * (1.0 - gaussian_layer(z) / 0.4); },
      [](double) { return -3.0; });
  EXPECT_FALSE(find_shock(p).has_value());
}

TEST(FindShock, AStandardErrorLargerThanTheDropMeansNoShock) {
  Profile p = shock_profile(14.0, 1.0);
  ASSERT_TRUE(find_shock(p).has_value());
  // The same profile measured with errors of 2 in every bin: a drop of 5 is < 3 * 2 sqrt(2).
  p.T_se.assign(p.size(), 2.0);
  EXPECT_FALSE(find_shock(p).has_value());
  // Errors of 0.1: the drop of 5 and the rise above the trough (0.05 per bin, 0.42 needed)
  // both stand out of the noise again.
  p.T_se.assign(p.size(), 0.1);
  EXPECT_TRUE(find_shock(p).has_value());
}

/// MD-like sampling noise: the counts of a 20 x 20 box over 10 cycles, per-bin standard errors
/// sqrt(n / samples) for n and T sqrt(2 / (3 samples)) for T, Gaussian noise of that size.
Profile with_md_noise(const Profile& clean, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Profile p = clean;
  p.samples.assign(p.size(), 0.0);
  p.n_se.assign(p.size(), 0.0);
  p.uz_se.assign(p.size(), 0.0);
  p.T_se.assign(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double samples = std::floor(clean.n[i] * 400.0 * p.bin_height * 10.0);
    p.samples[i] = samples;
    if (samples < 2.0) {  // an empty bin: MD has nothing to report
      p.n[i] = p.nu[i] = p.uz[i] = p.T[i] = 0.0;
      continue;
    }
    p.n_se[i] = clean.n[i] / std::sqrt(samples);
    p.T_se[i] = clean.T[i] * std::sqrt(2.0 / (3.0 * samples));
    p.uz_se[i] = std::sqrt(clean.T[i] / samples);
    p.n[i] = std::max(0.0, clean.n[i] + p.n_se[i] * normal(random));
    p.nu[i] = volume_fraction(p.n[i]);
    p.T[i] = std::max(0.0, clean.T[i] + p.T_se[i] * normal(random));
    p.uz[i] = clean.uz[i] + p.uz_se[i] * normal(random);
  }
  return p;
}

TEST(FindShock, MdLikeNoiseDoesNotProduceAShock) {
  const Profile resting =
      make_profile([](double z) { return 0.55 * step_down(z, 12.0, 2.0); },
                   [](double z) { return 0.2 + 0.1 * z; }, [](double) { return 0.0; });
  const Profile flying = make_profile(
      gaussian_layer, [](double) { return 3.0; }, [](double) { return -1.0; });
  const Profile falling = make_profile(
      gaussian_layer, [](double z) { return 0.5 + 2.0 * (1.0 - gaussian_layer(z) / 0.4); },
      [](double) { return -3.0; });
  int spurious = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed)
    for (const Profile* clean : {&resting, &flying, &falling}) {
      const auto shock = find_shock(with_md_noise(*clean, seed));
      if (shock) {
        ++spurious;
        ADD_FAILURE() << "seed " << seed << ": spurious shock at " << shock->location;
      }
    }
  std::printf("[measured] spurious shocks in 600 noisy shock-free profiles: %d\n", spurious);
}

TEST(FindShock, FindsARealShockThroughMdLikeNoise) {
  // Noise can make the neighbouring pair of bins the steepest, so a noisy location may sit on
  // the bin edge next to the nearest one: within one bin of the centre, and mostly within half.
  int found = 0, within_half_bin = 0;
  double worst = 0.0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    const auto shock = find_shock(with_md_noise(shock_profile(13.4, 1.0), seed));
    if (!shock) continue;
    ++found;
    const double error = std::abs(shock->location - 13.4);
    worst = std::max(worst, error);
    if (error <= 0.5) ++within_half_bin;
  }
  EXPECT_EQ(found, 100);
  EXPECT_LT(worst, 1.0);
  EXPECT_GE(within_half_bin, 90);
  std::printf(
      "[measured] noisy tanh shock: found %d / 100, %d within half a bin, worst location "
      "error %.2f\n",
      found, within_half_bin, worst);
}

// ---- layer, centre of mass, Mach number --------------------------------------------------------

TEST(FindLayer, InterpolatesTheThresholdCrossings) {
  // A tent nu = 0.4 - 0.05 |z - 15|, linear between bin centres around both crossings of
  // 0.026: |z - 15| = (0.4 - 0.026) / 0.05 = 7.48.
  const Profile p =
      make_profile([](double z) { return std::max(0.0, 0.4 - 0.05 * std::abs(z - 15.0)); },
                   [](double) { return 1.0; }, [](double) { return 0.0; }, 40);
  const auto layer = find_layer(p);
  ASSERT_TRUE(layer.has_value());
  EXPECT_NEAR(layer->bottom, 15.0 - 7.48, 1e-12);
  EXPECT_NEAR(layer->top, 15.0 + 7.48, 1e-12);
  EXPECT_DOUBLE_EQ(layer_volume_fraction, 0.04 * nu_max);
}

TEST(FindLayer, ALayerTouchingTheEndsOfTheGridAndNoLayer) {
  const Profile full = make_profile([](double) { return 0.3; }, [](double) { return 1.0; },
                                    [](double) { return 0.0; }, 10, 0.5, 2.0);
  const auto layer = find_layer(full);
  ASSERT_TRUE(layer.has_value());
  EXPECT_DOUBLE_EQ(layer->bottom, 2.0);  // the lower edge of the lowest bin
  EXPECT_DOUBLE_EQ(layer->top, 7.0);     // the upper edge of the highest bin
  const Profile gas = make_profile([](double) { return 0.02; }, [](double) { return 1.0; },
                                   [](double) { return 0.0; });
  EXPECT_FALSE(find_layer(gas).has_value());
}

TEST(CenterOfMass, MatchesClosedFormForAnExponentialAtmosphere) {
  // n_i = q^i on centres (i + 1/2) h: sum i q^i / sum q^i in closed form.
  const double L = 3.0, h = 0.5;
  const std::size_t N = 80;
  const Profile p = make_profile([&](double z) { return volume_fraction(std::exp(-z / L)); },
                                 [](double) { return 1.0; }, [](double) { return 0.0; }, N, h);
  const double q = std::exp(-h / L), Nd = static_cast<double>(N);
  const double s0 = (1.0 - std::pow(q, Nd)) / (1.0 - q);
  const double s1 = q * (1.0 - Nd * std::pow(q, Nd - 1.0) + (Nd - 1.0) * std::pow(q, Nd)) /
                    ((1.0 - q) * (1.0 - q));
  EXPECT_NEAR(center_of_mass(p), h * (0.5 + s1 / s0), 1e-12);
  // A uniform slab from 0 to 10 has its centre at 5.
  const Profile slab = make_profile([](double z) { return z < 10.0 ? 0.3 : 0.0; },
                                    [](double) { return 1.0; }, [](double) { return 0.0; }, 30);
  EXPECT_NEAR(center_of_mass(slab), 5.0, 1e-12);
  EXPECT_TRUE(std::isnan(center_of_mass(Profile{})));  // no material, no centre
}

TEST(MachNumber, IsTheSpeedRelativeToThePlateOverTheSoundSpeed) {
  // Sound speeds at (nu, T, e = 0.9) from the 50-digit references of reference_values.inc.
  const double c_dilute = 1.295917251137339270791543;  // nu = 1e-3, T = 1
  const double c_mid = 3.898836954843631951455982;     // nu = 0.3,  T = 1
  const double c_dense = 25.46671270814647921479268;   // nu = 0.6,  T = 0.5
  Profile p;
  p.plate_v = 1.25;
  p.z = {0.5, 1.5, 2.5, 3.5, 4.5, 5.5};
  p.nu = {1e-3, 0.3, 0.6, 0.0, 0.3, 0.3};
  p.T = {1.0, 1.0, 0.5, 1.0, 0.0, 1.0};
  p.uz = {-2.0, 1.25, 3.0, 7.0, 7.0, -0.75};
  for (double nu : p.nu) p.n.push_back(number_density(nu));
  const auto ma = mach_number(p, 0.9);
  ASSERT_EQ(ma.size(), p.size());
  EXPECT_NEAR(ma[0], 3.25 / c_dilute, 1e-12);
  EXPECT_EQ(ma[1], 0.0);  // moving with the plate
  EXPECT_NEAR(ma[2], 1.75 / c_dense, 1e-12);
  EXPECT_TRUE(std::isnan(ma[3]));  // no material
  EXPECT_EQ(ma[4], 0.0);  // no temperature
  EXPECT_NEAR(ma[5], 2.0 / c_mid, 1e-12);
  // Only bins inside the layer count for the maximum (bin 0 is too dilute).
  EXPECT_NEAR(max_mach_in_layer(p, 0.9), 2.0 / c_mid, 1e-12);
}

TEST(MachNumber, AnOverpackedMdBinDoesNotStopTheAnalysis) {
  // An MD bin can hold more than nu_max (ordered layers on the plate reach 0.74). The sound
  // speed diverges as nu -> nu_max, so Ma -> 0 there; the analysis must not throw.
  Profile p;
  p.z = {0.5, 1.5};
  p.nu = {0.70, 0.3};
  p.T = {0.1, 1.0};
  p.uz = {0.5, -0.75};
  p.plate_v = 1.25;
  for (double nu : p.nu) p.n.push_back(number_density(nu));
  std::vector<double> ma;
  ASSERT_NO_THROW(ma = mach_number(p, 0.9));
  EXPECT_EQ(ma[0], 0.0);
  EXPECT_NEAR(ma[1], 2.0 / 3.898836954843631951455982, 1e-12);
  EXPECT_NO_THROW(summarize(p, 0.9));
}

// ---- shock speed ------------------------------------------------------------------------------

// The speed of run_analysis.hpp's shock life, on profiles of a single shock (not periodic)
// stored at f = 0.1.
constexpr double kTestFrequency = 0.1;

Profile at(double time, double plate_z, Profile p) {
  p.time = time;
  p.phase = kTestFrequency * time;
  p.plate_z = plate_z;
  return p;
}

double life_speed(const std::vector<Profile>& profiles) {
  AnalysisOptions o;
  o.periodic = false;
  o.frequency = kTestFrequency;
  const auto r = analyze_profiles(profiles, 0.9, o);
  return r.shock ? r.shock->speed : std::numeric_limits<double>::quiet_NaN();
}

TEST(ShockSpeed, RecoversAKnownSpeedInThePlateFrame) {
  // The shock sits on bin edges z = 10 + k at t = k / 2 while the plate rises by k / 4: the
  // speed relative to the plate is (1 - 1/4) / (1/2) = 1.5 exactly.
  std::vector<Profile> profiles;
  const Profile calm =
      make_profile([](double z) { return 0.55 * step_down(z, 12.0, 2.0); },
                   [](double z) { return 0.2 + 0.1 * z; }, [](double) { return 0.0; });
  profiles.push_back(at(-0.5, 0.0, calm));  // before the shock forms
  for (int k = 0; k < 9; ++k)
    profiles.push_back(at(0.5 * k, 0.25 * k, shock_profile(10.0 + k, 0.6)));
  profiles.push_back(at(4.5, 2.25, calm));  // the shock has left the layer
  profiles.push_back(at(5.0, 2.5, calm));
  profiles.push_back(at(5.5, 2.75, shock_profile(30.0, 0.6)));  // a later one is not averaged
  EXPECT_NEAR(life_speed(profiles), 1.5, 1e-12);

  // Off the bin edges the location is quantised to half a bin; the fitted speed stays close.
  std::vector<Profile> moving;
  for (int k = 0; k < 10; ++k)
    moving.push_back(at(0.5 * k, 0.0, shock_profile(10.3 + 0.85 * k, 0.8)));
  const double fitted = life_speed(moving);
  EXPECT_NEAR(fitted, 1.7, 0.1);
  std::printf("[measured] shock speed 1.7 off the bin edges: fitted %.4f\n", fitted);
  // Fewer than two phases with a shock: no speed.
  EXPECT_TRUE(std::isnan(life_speed({calm, at(1.0, 0.0, shock_profile(12.0, 1.0)), calm})));
}

// ---- agreement metrics ------------------------------------------------------------------------

TEST(SeriesDifference, KnownInputs) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto d = series_difference({1.0, 2.0, 3.0, nan, 7.0}, {1.0, 2.0, 5.0, 4.0, nan});
  EXPECT_EQ(d.count, 3u);  // only where both exist
  EXPECT_NEAR(d.absolute_rms, std::sqrt(4.0 / 3.0), 1e-15);
  EXPECT_NEAR(d.fractional_rms, std::sqrt(4.0 / 30.0), 1e-15);  // / sqrt((1 + 4 + 25) / 3)
  const auto none = series_difference({nan, 1.0}, {2.0, nan});
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(none.absolute_rms, 0.0);
  EXPECT_THROW(series_difference({1.0}, {1.0, 2.0}), std::invalid_argument);
  EXPECT_TRUE(std::isnan(series_difference({1.0}, {0.0}).fractional_rms));
}

TEST(ProfileDifference, KnownInputs) {
  // b is linear in z on a shifted grid, so interpolating it at a's heights is exact.
  const Profile b =
      make_profile([](double z) { return 0.1 + 0.01 * z; }, [](double z) { return 2.0 - 0.03 * z; },
                   [](double) { return 0.0; }, 20, 1.0, 0.25);
  const Profile a = make_profile([](double z) { return 0.12 + 0.01 * z; },
                                 [](double z) { return 2.0 - 0.03 * z + (z < 10.0 ? 0.5 : -1.0); },
                                 [](double) { return 0.0; }, 22, 1.0, 0.0);
  const auto nu = profile_difference(a, b, "nu");
  // a's centres 0.5 .. 21.5, b covers 0.75 .. 19.75: a's 1.5 .. 19.5 count.
  EXPECT_EQ(nu.count, 19u);
  EXPECT_NEAR(nu.l1, 0.02, 1e-14);
  EXPECT_NEAR(nu.l2, 0.02, 1e-14);
  EXPECT_NEAR(nu.linf, 0.02, 1e-14);
  const auto T = profile_difference(a, b, "T");
  // 9 heights below 10 differ by 0.5, 10 above by 1.
  EXPECT_NEAR(T.l1, (9 * 0.5 + 10 * 1.0) / 19.0, 1e-13);
  EXPECT_NEAR(T.l2, std::sqrt((9 * 0.25 + 10 * 1.0) / 19.0), 1e-13);
  EXPECT_NEAR(T.linf, 1.0, 1e-13);
  EXPECT_THROW(profile_difference(a, b, "uz"), std::invalid_argument);
}

RunRecord run_of(const std::vector<Profile>& profiles) {
  RunRecord r;
  r.profiles = profiles;
  return r;
}

std::vector<Profile> shock_run(double shift) {
  std::vector<Profile> profiles;
  for (int k = 0; k < 8; ++k) {
    Profile p =
        k < 6 ? shock_profile(10.0 + k + shift, 0.8)
              : make_profile([](double z) { return 0.55 * step_down(z, 12.0, 2.0); },
                             [](double z) { return 0.2 + 0.1 * z; }, [](double) { return 0.0; });
    p.phase = 0.125 * k;
    p.time = 10.0 + p.phase;
    profiles.push_back(p);
  }
  return profiles;
}

TEST(CompareRuns, ARunComparedWithItselfGivesZeros) {
  const RunRecord a = run_of(shock_run(0.0));
  const auto r = compare_runs(a, a);
  EXPECT_EQ(r.phases.size(), 8u);
  EXPECT_EQ(r.shock_location.count, 6u);
  EXPECT_EQ(r.shock_location.absolute_rms, 0.0);
  EXPECT_EQ(r.shock_location.fractional_rms, 0.0);
  EXPECT_EQ(r.center_of_mass.count, 8u);
  EXPECT_EQ(r.center_of_mass.absolute_rms, 0.0);
  EXPECT_EQ(r.center_of_mass.fractional_rms, 0.0);
  for (std::size_t k = 0; k < r.phases.size(); ++k) {
    EXPECT_EQ(r.nu_norms[k].linf, 0.0);
    EXPECT_EQ(r.T_norms[k].l1, 0.0);
    EXPECT_EQ(r.T_norms[k].count, 60u);
  }
}

TEST(CompareRuns, AShockDisplacedByOneBinGivesThatDifference) {
  const RunRecord a = run_of(shock_run(1.0)), b = run_of(shock_run(0.0));
  const auto r = compare_runs(a, b);
  EXPECT_EQ(r.shock_location.count, 6u);
  EXPECT_NEAR(r.shock_location.absolute_rms, 1.0, 1e-12);
  double reference = 0.0;  // rms of b's locations 10 .. 15
  for (int k = 0; k < 6; ++k) reference += (10.0 + k) * (10.0 + k) / 6.0;
  EXPECT_NEAR(r.shock_location.fractional_rms, 1.0 / std::sqrt(reference), 1e-12);
  EXPECT_GT(r.center_of_mass.absolute_rms, 0.0);

  RunRecord fewer = b;
  fewer.profiles.pop_back();
  EXPECT_THROW(compare_runs(a, fewer), std::invalid_argument);
  RunRecord shifted = b;
  shifted.profiles[3].phase += 0.01;
  EXPECT_THROW(compare_runs(a, shifted), std::invalid_argument);
}

// ---- undefined bins and the plate ----------------------------------------------------------

constexpr double undefined = std::numeric_limits<double>::quiet_NaN();

/// p with the bins `gone` emptied as the MD leaves a bin no particle visits: n = nu = 0, T and
/// u_z undefined, and their standard errors undefined.
Profile emptied(Profile p, const std::vector<std::size_t>& gone) {
  for (std::size_t i : gone) {
    p.n[i] = p.nu[i] = 0.0;
    p.T[i] = p.uz[i] = undefined;
    if (!p.n_se.empty()) p.n_se[i] = 0.0;
    if (!p.T_se.empty()) p.T_se[i] = p.uz_se[i] = undefined;
  }
  return p;
}

/// p without the bins `gone` at all.
Profile removed(const Profile& p, const std::vector<std::size_t>& gone) {
  std::vector<char> keep(p.size(), 1);
  for (std::size_t i : gone) keep[i] = 0;
  Profile q = p;
  for (auto field : {&Profile::z, &Profile::n, &Profile::nu, &Profile::uz, &Profile::T,
                     &Profile::n_se, &Profile::uz_se, &Profile::T_se}) {
    if ((p.*field).empty()) continue;
    (q.*field).clear();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (keep[i]) (q.*field).push_back((p.*field)[i]);
  }
  return q;
}

/// Equal, or both NaN.
bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

TEST(UndefinedBins, EmptyBinsInAndAboveTheLayerChangeNoResult) {
  // A shock at zs = 16 + k moving up through a layer (bottom at the plate, top near zs + 15),
  // with standard errors; empty bins inside the layer (z = 8.5, 29.5, and zs - 1.5, just
  // above the temperature maximum, where the walk to the steepest drop passes) and in the gas
  // above it (40.5, 45.5, both in the span of temperature_slope_above) must give the numbers
  // of the same profiles without those bins: nothing undefined reaches a defined result.
  std::vector<Profile> with_empty, without;
  for (std::size_t k = 0; k < 6; ++k) {
    const std::vector<std::size_t> gone{8, 14 + k, 29, 40, 45};
    Profile p = at(0.5 * static_cast<double>(k), 0.0, shock_profile(16.0 + static_cast<double>(k), 0.8));
    p.n_se.assign(p.size(), 0.01);
    p.uz_se.assign(p.size(), 0.02);
    p.T_se.assign(p.size(), 0.03);
    with_empty.push_back(emptied(p, gone));
    without.push_back(removed(emptied(p, gone), gone));
  }
  AnalysisOptions o;
  o.periodic = false;
  o.frequency = kTestFrequency;
  const RunQuantities a = analyze_profiles(with_empty, 0.9, o), b = analyze_profiles(without, 0.9, o);
  ASSERT_TRUE(a.shock.has_value());
  EXPECT_EQ(a.shock->phases.size(), 6u);
  const auto columns_a = phase_columns(a), columns_b = phase_columns(b);
  for (std::size_t q = 0; q < columns_a.size(); ++q) {
    // Kn takes one-sided gradients beside an empty bin, and central ones across a removed
    // one: the bins differ by design (KnudsenNumbers); it must be defined all the same.
    const bool knudsen = columns_a[q].name == "knudsen_mass_fraction";
    for (std::size_t k = 0; k < columns_a[q].values.size(); ++k) {
      if (knudsen) {
        EXPECT_TRUE(std::isfinite(columns_a[q].values[k])) << "phase " << k;
      } else {
        EXPECT_TRUE(same(columns_a[q].values[k], columns_b[q].values[k]))
            << columns_a[q].name << " at phase " << k << ": " << columns_a[q].values[k]
            << " against " << columns_b[q].values[k];
      }
    }
  }
  const auto runs_a = run_values(a), runs_b = run_values(b);
  for (std::size_t q = 0; q < runs_a.size(); ++q)
    EXPECT_TRUE(same(runs_a[q].values[0], runs_b[q].values[0])) << runs_a[q].name;
  for (const auto& q : a.phases) {
    EXPECT_TRUE(std::isfinite(q.layer_temperature));
    EXPECT_TRUE(std::isfinite(q.temperature_slope_above));
    EXPECT_TRUE(std::isfinite(q.max_mach));
    EXPECT_TRUE(q.front.has_value());
  }
  std::printf("[measured] with empty bins: layer T %.6f, slope above %.6f, shock speed %.6f, "
              "front width %.6f at the first phase\n", a.phases[0].layer_temperature,
              a.phases[0].temperature_slope_above, a.shock->speed, a.phases[0].front->width);
  // An empty bin where T falls steepest (z = 16.5, the shock at 16): the drop is taken across
  // it, and the mean free path from the density of the bins around it, not the 0 at its centre.
  const Profile cut = emptied(shock_profile(16.0, 0.8), {16});
  std::optional<Shock> across;
  ASSERT_NO_THROW(across = find_shock(cut));
  ASSERT_TRUE(across.has_value());
  const auto expected = find_shock(removed(cut, {16}));
  ASSERT_TRUE(expected.has_value());
  EXPECT_EQ(across->location, expected->location);
  EXPECT_EQ(across->mean_free_path, expected->mean_free_path);
  EXPECT_TRUE(std::isfinite(across->mean_free_path));

  // The agreement metrics leave out the heights where a run is undefined.
  const std::vector<std::size_t> gone{8, 29, 40, 45};
  const Profile reference = shock_profile(18.0, 0.8);
  const Profile md = emptied(shock_profile(18.0, 0.8), gone);
  const auto T = profile_difference(md, reference, "T");
  EXPECT_EQ(T.count, reference.size() - gone.size());
  EXPECT_EQ(T.l1, 0.0);
  // The other way round an undefined bin also leaves out the bin below it, whose height
  // interpolates between the two.
  EXPECT_EQ(profile_difference(reference, md, "T").count, reference.size() - 2 * gone.size());
  EXPECT_EQ(profile_difference(md, reference, "nu").count, reference.size());
}

TEST(UndefinedBins, TheLayerBottomIsNeverBelowThePlate) {
  // MD bins fixed in the lab frame from z = 0, the plate at 2.3: bins [0, 1] and [1, 2] lie
  // below it and are empty, the bin [2, 3] straddles it with its material above 2.3 (nu 0.3
  // over the whole bin), a layer of nu 0.5 above it up to z = 16, nothing higher.
  Profile p = make_profile([](double z) { return z < 2.0 ? 0.0 : z < 3.0 ? 0.3 : z < 16.0 ? 0.5 : 0.0; },
                           [](double) { return 1.0; }, [](double) { return 0.0; }, 30);
  p.plate_z = 2.3;
  p = emptied(p, {0, 1});
  for (std::size_t i = 16; i < p.size(); ++i) p = emptied(p, {i});
  // Unclipped, both bottoms would lie below the plate: the threshold crossing between the
  // centres 1.5 and 2.5, and 1 % of the material spread over the whole bin [2, 3].
  const double crossing = 1.5 + layer_volume_fraction / 0.3;
  double total = 0.0;
  for (double n : p.n) total += n;
  const double spread = 2.0 + 0.01 * total / p.n[2];
  ASSERT_LT(crossing, p.plate_z);
  ASSERT_LT(spread, p.plate_z);
  const auto layer = find_layer(p);
  ASSERT_TRUE(layer.has_value());
  EXPECT_EQ(layer->bottom, 2.3);
  EXPECT_NEAR(layer->top, 15.5 + (0.5 - layer_volume_fraction) / 0.5, 1e-12);
  AnalysisOptions o;
  const RunQuantities r = analyze_profiles({p}, 0.9, o);
  EXPECT_EQ(r.phases[0].mass_bottom, 2.3);
  for (const auto& column : phase_columns(r)) {
    if (column.name == "layer_bottom" || column.name == "mass_bottom") {
      EXPECT_GE(column.values[0], p.plate_z) << column.name;
    }
    if (column.name == "layer_gap" || column.name == "mass_gap") {
      EXPECT_EQ(column.values[0], 0.0) << column.name;
    }
  }
  std::printf("[measured] plate 2.3: unclipped layer bottom %.4f and 1 %% bottom %.4f, reported %.4f and %.4f\n",
              crossing, spread, layer->bottom, r.phases[0].mass_bottom);
  // A bottom found above the plate is left alone.
  p.plate_z = 1.0;
  EXPECT_NEAR(find_layer(p)->bottom, crossing, 1e-12);
}

}  // namespace
