// Unit tests of the pattern analysis (solvers/analysis/pattern.hpp) on synthetic fields of
// known answer: stripes, squares and hexagons with seeded white noise, fields built from
// particles and from a 3D density, a pattern alternating from cycle to cycle, a saturating
// growth. The statistics over seeds (bias, coverage of the error bars) are printed and
// recorded as test properties, so a reader of the test log sees the measured numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "analysis/pattern.hpp"
#include "test_support.hpp"

namespace {

namespace an = shaker::analysis;
using an::HorizontalField;
using an::HorizontalGrid;
using an::PatternSymmetry;

constexpr double two_pi = 2.0 * M_PI;

double centre(std::size_t i, std::size_t n, double length) {
  return (static_cast<double>(i) + 0.5) * length / static_cast<double>(n);
}
double cell_x(const HorizontalGrid& g, std::size_t i) { return centre(i, g.nx, g.lx); }
double cell_y(const HorizontalGrid& g, std::size_t j) { return centre(j, g.ny, g.ly); }

/// f(x, y) at the cell centres, plus white noise of standard deviation `noise` per cell.
HorizontalField sampled(const HorizontalGrid& g, const std::function<double(double, double)>& f,
                        double noise = 0.0, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  HorizontalField field{g, {}};
  for (std::size_t j = 0; j < g.ny; ++j)
    for (std::size_t i = 0; i < g.nx; ++i)
      field.values.push_back(f(cell_x(g, i), cell_y(g, j)) + noise * gauss(rng));
  return field;
}

HorizontalField white_noise(const HorizontalGrid& g, std::uint64_t seed) {
  return sampled(g, [](double, double) { return 0.0; }, 1.0, seed);
}

/// Stripes of wavevector (kx, ky) and amplitude 1, phase phi.
std::function<double(double, double)> stripes(double kx, double ky, double phi = 0.0) {
  return [=](double x, double y) { return std::cos(kx * x + ky * y + phi); };
}

const HorizontalGrid square_box{64, 64, 64.0, 64.0};
/// Hexagons fit a box of aspect ratio sqrt(3) / 2: k1 = 2 pi (8, 0) / Lx and
/// k2,3 = 2 pi (-4 / Lx, +-6 / Ly) all have |k| = 2 pi 8 / Lx.
const HorizontalGrid hexagon_box{64, 56, 64.0, 64.0 * std::sqrt(3.0) / 2.0};

double hexagons(double x, double y) {
  const double k = two_pi * 8.0 / hexagon_box.lx;
  double sum = 0.0;
  for (int n = 0; n < 3; ++n) {
    const double angle = two_pi * n / 3.0;
    sum += std::cos(k * (std::cos(angle) * x + std::sin(angle) * y));
  }
  return sum;
}

// ---- Spectrum -----------------------------------------------------------------------------

TEST(PatternSpectrum, ParsevalHoldsOnRandomFieldsOfAnySize) {
  for (const HorizontalGrid g : {HorizontalGrid{48, 36, 30.0, 20.0}, HorizontalGrid{35, 27, 35.0, 27.0},
                                 HorizontalGrid{17, 1, 17.0, 1.0}}) {
    const HorizontalField f = sampled(g, [](double x, double) { return 3.0 + 0.1 * x; }, 1.0, 7);
    double mean = 0.0, square = 0.0;
    for (double v : f.values) mean += v / static_cast<double>(g.cells());
    for (double v : f.values) square += (v - mean) * (v - mean) / static_cast<double>(g.cells());
    EXPECT_LT(shaker::testing::relative_error(an::power_spectrum(f).total(), square), 1e-12)
        << g.nx << " x " << g.ny;
  }
}

TEST(PatternSpectrum, SingleCosineHasPowerAtPlusAndMinusItsWavevector) {
  const HorizontalGrid g{30, 25, 30.0, 50.0};  // kx index 4, ky index -3: 2 pi (4/30, -3/50)
  const an::PowerSpectrum s = an::power_spectrum(sampled(g, stripes(two_pi * 4 / 30.0, -two_pi * 3 / 50.0)));
  const std::size_t plus = 22 * g.nx + 4, minus = 3 * g.nx + 26;  // j = 25 - 3, i = 30 - 4
  EXPECT_NEAR(s.power[plus], 0.25, 1e-13);
  EXPECT_NEAR(s.power[minus], 0.25, 1e-13);
  EXPECT_NEAR(s.kx(4), two_pi * 4 / 30.0, 1e-15);
  EXPECT_NEAR(s.kx(26), -two_pi * 4 / 30.0, 1e-15);
  EXPECT_NEAR(s.ky(22), -two_pi * 3 / 50.0, 1e-15);
  EXPECT_NEAR(s.kx(15), two_pi * 15 / 30.0, 1e-15);  // the Nyquist mode counted as positive
  EXPECT_NEAR(s.ky(12), two_pi * 12 / 50.0, 1e-15);  // odd n: 12 positive, 13 negative
  EXPECT_NEAR(s.ky(13), -two_pi * 12 / 50.0, 1e-15);
  EXPECT_NEAR(s.total(), 0.5, 1e-13);
}

TEST(PatternSpectrum, RadialShellsHoldEveryModeButZero) {
  const HorizontalGrid g{40, 30, 40.0, 60.0};
  const an::RadialSpectrum r = an::radial_spectrum(an::power_spectrum(white_noise(g, 3)));
  std::size_t modes = 0;
  double power = 0.0;
  for (std::size_t s = 0; s < r.power.size(); ++s) modes += r.modes[s], power += r.power[s];
  EXPECT_EQ(modes, g.cells() - 1);
  EXPECT_NEAR(r.dk, two_pi / 60.0, 1e-15);
  EXPECT_EQ(r.modes[0], 0u);
  EXPECT_NEAR(power, an::power_spectrum(white_noise(g, 3)).total(), 1e-12 * power);
}

// ---- Dominant wavenumber -------------------------------------------------------------------

TEST(PatternWavenumber, StripesFoundWithinHalfAShellAtAnyWavelength) {
  const double dk = two_pi / square_box.lx;
  // Wavelengths that fit the box a whole number of times (m) and that do not.
  for (double m : {5.0, 8.0, 13.0, 5.25, 6.5, 7.75, 10.4, 12.9}) {
    const double k0 = m * dk;
    const bool fits = m == std::floor(m);
    const auto f = sampled(square_box, stripes(k0, 0.0, 0.3), 0.2, 11);
    const an::DominantWavenumber d = an::dominant_wavenumber(an::power_spectrum(f));
    // Commensurate: exact but for the noise. Otherwise the power leaks to neighbouring modes
    // and the centroid is within half a shell.
    const double tolerance = fits ? 0.02 * dk : 0.5 * dk;
    EXPECT_NEAR(d.k, k0, tolerance) << "m = " << m;
    const double lambda0 = two_pi / k0;
    EXPECT_NEAR(d.wavelength, lambda0, tolerance * lambda0 * lambda0 / two_pi * 1.05) << "m = " << m;
    std::cout << "stripes m = " << m << ": k* error " << (d.k - k0) / dk << " shells\n";
  }
}

TEST(PatternWavenumber, RotatedStripesFoundExactly) {
  const double dk = two_pi / square_box.lx;
  const auto f = sampled(square_box, stripes(3 * dk, 4 * dk, 1.0), 0.2, 12);
  const an::PatternMeasure m = an::measure_pattern(f);
  EXPECT_NEAR(m.dominant.k, 5 * dk, 0.02 * dk);
  EXPECT_NEAR(m.dominant.wavelength, square_box.lx / 5, 0.02 * square_box.lx / 5);
  EXPECT_GT(m.symmetry.a2, 0.95);
  EXPECT_EQ(m.symmetry.symmetry, PatternSymmetry::stripes);
}

// ---- Symmetry -----------------------------------------------------------------------------

TEST(PatternSymmetry, SquaresAndHexagonsClassifiedByTheirMoments) {
  const double k = two_pi * 8 / square_box.lx;
  const auto squares = an::measure_pattern(
      sampled(square_box, [&](double x, double y) { return std::cos(k * x) + std::cos(k * y); }, 0.2, 21));
  EXPECT_EQ(squares.symmetry.symmetry, PatternSymmetry::squares);
  EXPECT_LT(squares.symmetry.a2, 0.05);
  EXPECT_GT(squares.symmetry.a4, 0.95);
  EXPECT_LT(squares.symmetry.a6, 0.05);
  EXPECT_NEAR(squares.dominant.k, k, 0.02 * two_pi / square_box.lx);

  const auto hex = an::measure_pattern(sampled(hexagon_box, hexagons, 0.2, 22));
  EXPECT_EQ(hex.symmetry.symmetry, PatternSymmetry::hexagons);
  EXPECT_LT(hex.symmetry.a2, 0.05);
  EXPECT_LT(hex.symmetry.a4, 0.05);
  EXPECT_GT(hex.symmetry.a6, 0.95);
  EXPECT_NEAR(hex.dominant.k, two_pi * 8 / hexagon_box.lx, 0.02 * two_pi / hexagon_box.lx);
  std::cout << "squares A2 A4 A6 = " << squares.symmetry.a2 << " " << squares.symmetry.a4 << " "
            << squares.symmetry.a6 << "; hexagons " << hex.symmetry.a2 << " " << hex.symmetry.a4
            << " " << hex.symmetry.a6 << "\n";
}

TEST(PatternSymmetry, NoiseIsDisordered) {
  double largest = 0.0;
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    const auto m = an::measure_pattern(white_noise(square_box, 100 + seed));
    EXPECT_EQ(m.symmetry.symmetry, PatternSymmetry::disordered) << "seed " << seed;
    largest = std::max({largest, m.symmetry.a2, m.symmetry.a4, m.symmetry.a6});
  }
  std::cout << "white noise, 50 seeds: largest A_n " << largest << "\n";
  RecordProperty("noise_largest_moment", std::to_string(largest));
  EXPECT_LT(largest, 0.35);
}

TEST(PatternSymmetry, ThresholdDecidesBetweenStripesAndSquares) {
  // cos kx + c cos ky has A2 = (1 - c^2) / (1 + c^2): 0.6 at c = 0.5.
  const double k = two_pi * 8 / square_box.lx;
  const auto f = sampled(square_box, [&](double x, double y) { return std::cos(k * x) + 0.5 * std::cos(k * y); });
  const an::PowerSpectrum s = an::power_spectrum(f);
  EXPECT_NEAR(an::pattern_symmetry(s, k).a2, 0.6, 1e-12);
  EXPECT_EQ(an::pattern_symmetry(s, k, {1.5, 0.5}).symmetry, PatternSymmetry::stripes);
  EXPECT_EQ(an::pattern_symmetry(s, k, {1.5, 0.7}).symmetry, PatternSymmetry::squares);
}

// ---- Fields from particles and from a density ----------------------------------------------

TEST(PatternFields, ColumnMassAndHeightFromParticles) {
  // Particles spread in x with density 1 + b cos(k x), at height h0 + a cos(k x).
  const HorizontalGrid g{32, 32, 64.0, 64.0};
  const double k = two_pi * 4 / g.lx, b = 0.5, h0 = 5.0, a = 1.5;
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  an::ParticlePositions p;
  while (p.x.size() < 200000) {
    const double x = g.lx * unit(rng), y = g.ly * unit(rng);
    if ((1.0 + b) * unit(rng) > 1.0 + b * std::cos(k * x)) continue;
    p.x.push_back(x + 3.0 * g.lx);  // unwrapped positions are wrapped into the box
    p.y.push_back(y - g.ly);
    p.z.push_back(h0 + a * std::cos(k * x));
  }
  // Averaging over a cell of width h scales a cosine by sin(k h / 2) / (k h / 2).
  const double h = g.lx / static_cast<double>(g.nx), cell_average = std::sin(k * h / 2) / (k * h / 2);
  const double mean_mass = 200000 / (g.lx * g.ly);

  const auto mass = an::measure_pattern(an::column_mass_field(p, g));
  // The counts' Poisson noise (variance ~195 per cell, 1/1024 of it per mode) in the ~80
  // modes of the shells either side of the peak, against a peak of ~4500 (counts squared),
  // moves the centroid by ~80 x 0.19 / 4500 ~ 0.003 shells: 0.013 in wavelength at 16 sigma.
  EXPECT_NEAR(mass.dominant.wavelength, 16.0, 0.013);
  const double mass_amplitude = std::sqrt(2.0 * mass.dominant.peak_power);
  EXPECT_NEAR(mass_amplitude / (b * mean_mass * cell_average), 1.0, 0.01);

  const auto height = an::measure_pattern(an::center_of_mass_height_field(p, g));
  EXPECT_NEAR(height.dominant.wavelength, 16.0, 1e-3);
  EXPECT_NEAR(std::sqrt(2.0 * height.dominant.peak_power) / (a * cell_average), 1.0, 0.01);
  std::cout << "particles: column-mass amplitude / truth " << mass_amplitude / (b * mean_mass * cell_average)
            << ", height amplitude / truth " << std::sqrt(2.0 * height.dominant.peak_power) / (a * cell_average)
            << "\n";
}

TEST(PatternFields, ColumnMassAndHeightFromADensity) {
  // n = (1 + b cos k x) g(z - h(x)), g a Gaussian of width w, h = h0 + a cos(k x): the column
  // mass is (1 + b cos k x) sqrt(2 pi) w, the centre of mass h(x) (midpoint sums of a Gaussian
  // well inside the range are exact to rounding).
  an::DensityColumns d{{24, 8, 48.0, 16.0}, 200, -1.0, 0.2, {}};
  const double k = two_pi * 3 / d.grid.lx, b = 0.4, w = 2.0, h0 = 18.0, a = 2.0;
  for (std::size_t kz = 0; kz < d.nz; ++kz)
    for (std::size_t j = 0; j < d.grid.ny; ++j)
      for (std::size_t i = 0; i < d.grid.nx; ++i) {
        const double x = cell_x(d.grid, i), z = d.z_bottom + centre(kz, 1, d.dz);
        const double u = (z - h0 - a * std::cos(k * x)) / w;
        d.n.push_back((1.0 + b * std::cos(k * x)) * std::exp(-0.5 * u * u));
      }
  const HorizontalField mass = an::column_mass_field(d), height = an::center_of_mass_height_field(d);
  for (std::size_t i = 0; i < d.grid.nx; ++i) {
    const double x = cell_x(d.grid, i);
    EXPECT_NEAR(mass.at(i, 5), (1.0 + b * std::cos(k * x)) * std::sqrt(two_pi) * w, 1e-10);
    EXPECT_NEAR(height.at(i, 5), h0 + a * std::cos(k * x), 1e-10);
  }
  const auto m = an::measure_pattern(height);
  EXPECT_NEAR(m.dominant.wavelength, 16.0, 1e-10);
  EXPECT_NEAR(std::sqrt(2.0 * m.dominant.peak_power), a, 1e-10);
  EXPECT_NEAR(m.order_parameter, a / std::sqrt(2.0), 1e-10);
}

// ---- Subharmonic response ------------------------------------------------------------------

TEST(PatternSubharmonic, CorrelationFromCycleToCycle) {
  const HorizontalGrid g{32, 32, 32.0, 32.0};
  const HorizontalField f = sampled(g, stripes(two_pi * 3 / 32.0, 0.0), 0.3, 41);
  HorizontalField minus_f = f;
  for (double& v : minus_f.values) v = 5.0 - v;  // inverted about another mean
  const auto alternating = an::cycle_to_cycle_correlation({f, minus_f, f, minus_f, f});
  EXPECT_NEAR(alternating.mean, -1.0, 1e-12);
  EXPECT_NEAR(alternating.standard_error, 0.0, 1e-12);
  EXPECT_EQ(alternating.pairs, 4u);
  EXPECT_NEAR(an::cycle_to_cycle_correlation({f, f, f}).mean, 1.0, 1e-12);

  // Stripes (variance 1/2) inverting every cycle under fresh noise (variance 1/4): the
  // correlation is -(1/2) / (1/2 + 1/4) = -2/3. Over 1024 cells one pair scatters by about
  // (1 - 4/9) / sqrt(1024) = 0.017, so the mean of 19 pairs is within 0.02.
  std::vector<HorizontalField> inverting;
  for (int c = 0; c < 20; ++c)
    inverting.push_back(sampled(g, stripes(two_pi * 3 / 32.0, 0.0, c % 2 == 0 ? 0.0 : M_PI), 0.5, 300 + c));
  const auto noisy = an::cycle_to_cycle_correlation(inverting);
  EXPECT_NEAR(noisy.mean, -2.0 / 3.0, 0.02);
  std::cout << "inverting stripes under noise: correlation " << noisy.mean << " +- " << noisy.standard_error << "\n";

  // Independent noise: the mean within 2 standard errors in about 95 % of repeats, and the
  // error near 1 / sqrt(cells pairs).
  int covered = 0, repeats = 400;
  double error_sum = 0.0;
  for (int r = 0; r < repeats; ++r) {
    std::vector<HorizontalField> cycles;
    for (int c = 0; c < 20; ++c) cycles.push_back(white_noise(g, 1000 * r + c + 1));
    const auto noise = an::cycle_to_cycle_correlation(cycles);
    if (r == 0) {
      EXPECT_LT(std::abs(noise.mean), 3.0 * noise.standard_error);
    }
    covered += std::abs(noise.mean) < 2.0 * noise.standard_error;
    error_sum += noise.standard_error;
  }
  const double coverage = static_cast<double>(covered) / repeats;
  const double mean_error = error_sum / repeats, expected = 1.0 / std::sqrt(1024.0 * 19.0);
  std::cout << "noise correlation: coverage of +-2 se " << coverage << ", mean se " << mean_error
            << " (1/sqrt(N pairs) = " << expected << ")\n";
  RecordProperty("correlation_coverage", std::to_string(coverage));
  EXPECT_GE(coverage, 0.90);
  EXPECT_LE(coverage, 0.99);
  EXPECT_NEAR(mean_error / expected, 1.0, 0.1);
}

// A subharmonic standing wave repeats one cycle later shifted by half its wavelength, whatever
// its waveform. A steep one carries even harmonics, which that shift leaves in place: the plain
// correlation then misses -1, the half-wavelength correlation still gives +1.
TEST(PatternSubharmonic, HalfWavelengthCorrelationSeesSteepStripesInvert) {
  const HorizontalGrid g{64, 4, 128.0, 8.0};
  const double k = two_pi * 5 / 128.0;
  const auto steep = [k](double sign) {
    return [k, sign](double x, double) { return sign * std::cos(k * x) + 0.6 * std::cos(2.0 * k * x); };
  };
  const HorizontalField up = sampled(g, steep(1.0)), down = sampled(g, steep(-1.0));
  // Power 1/2 inverts, 0.18 stays: (0.18 - 0.5) / 0.68.
  EXPECT_NEAR(an::field_correlation(up, down), (0.18 - 0.5) / 0.68, 1e-9);
  EXPECT_NEAR(an::half_wavelength_correlation(up, down), 1.0, 1e-9);
  EXPECT_NEAR(an::half_wavelength_correlation(down, up), 1.0, 1e-9);
  // A sinusoid: the shift is the inversion, so the two correlations are opposite; a pattern
  // that repeats unshifted (harmonic) gives -1.
  const HorizontalField wave = sampled(g, stripes(k, 0.0, 0.3)), inverted = sampled(g, stripes(k, 0.0, 0.3 + M_PI));
  EXPECT_NEAR(an::half_wavelength_correlation(wave, inverted), 1.0, 1e-9);
  EXPECT_NEAR(an::half_wavelength_correlation(wave, wave), -1.0, 1e-9);
  // Oblique stripes on a square box: the shift runs along their wavevector.
  const HorizontalGrid square{32, 32, 32.0, 32.0};
  const double kx = two_pi * 3 / 32.0, ky = two_pi * 2 / 32.0;
  const auto oblique = [kx, ky](double sign) {
    return [=](double x, double y) {
      const double phase = kx * x + ky * y;
      return sign * std::cos(phase) + 0.5 * std::cos(2.0 * phase);
    };
  };
  EXPECT_NEAR(an::half_wavelength_correlation(sampled(square, oblique(1.0)), sampled(square, oblique(-1.0))),
              1.0, 1e-9);
  // Independent noise: near 0 (one pair of 1024 cells scatters by about 1 / sqrt(1024)).
  EXPECT_LT(std::abs(an::half_wavelength_correlation(white_noise(square, 7), white_noise(square, 8))), 0.1);
  EXPECT_TRUE(std::isnan(an::half_wavelength_correlation(sampled(g, [](double, double) { return 2.0; }), up)));
  shaker::testing::expect_input_error([&] { an::half_wavelength_correlation(up, white_noise(square, 1)); },
                     {"half-wavelength correlation", "the same grid"});
}

// ---- Order parameter and saturation --------------------------------------------------------

struct Growth {
  std::vector<double> t, order;
};
/// A_s tanh(t / tau) + noise at 201 times over [0, 10 tau].
Growth tanh_growth(double a_s, double tau, double noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, noise);
  Growth g;
  for (int s = 0; s <= 200; ++s) {
    g.t.push_back(0.05 * tau * s);
    g.order.push_back(a_s * std::tanh(g.t.back() / tau) + gauss(rng));
  }
  return g;
}

TEST(PatternOrderParameter, SaturationOfATanhGrowth) {
  const double a_s = 2.0, tau = 3.0, noise = 0.02, t90 = tau * std::atanh(0.9);
  const double t50 = tau * std::atanh(0.5);
  const Growth one = tanh_growth(a_s, tau, noise, 51);
  const auto s = an::saturation(one.t, one.order);
  EXPECT_NEAR(s.value, a_s, 3.0 * s.standard_error);
  EXPECT_NEAR(s.standard_error / (noise / std::sqrt(67.0)), 1.0, 0.3);
  EXPECT_NEAR(s.time, t90, 0.1 * tau);
  EXPECT_NEAR(an::saturation(one.t, one.order, 0.5).time, t50, 0.05 * tau);

  int covered = 0, repeats = 400;
  double time_bias = 0.0, worst_time = 0.0;
  for (int r = 0; r < repeats; ++r) {
    const Growth g = tanh_growth(a_s, tau, noise, 5000 + r);
    const auto sat = an::saturation(g.t, g.order);
    covered += std::abs(sat.value - a_s) < 2.0 * sat.standard_error;
    time_bias += (sat.time - t90) / repeats;
    worst_time = std::max(worst_time, std::abs(sat.time - t90));
  }
  const double coverage = static_cast<double>(covered) / repeats;
  std::cout << "saturation: coverage of +-2 se " << coverage << ", time to 90 % bias "
            << time_bias / tau << " tau, worst " << worst_time / tau << " tau\n";
  RecordProperty("saturation_coverage", std::to_string(coverage));
  EXPECT_GE(coverage, 0.90);
  EXPECT_LE(coverage, 0.99);
  // Noise lets the first crossing come early: a bias of a few noise / slope (slope at t90 is
  // 0.19 A_s / tau, noise / slope = 0.05 tau).
  EXPECT_LT(std::abs(time_bias), 0.1 * tau);
  EXPECT_LT(worst_time, 0.25 * tau);
}

TEST(PatternOrderParameter, RmsOfTheMeanRemovedField) {
  const auto f = sampled(square_box, [](double x, double) { return 7.0 + 3.0 * std::cos(two_pi * 5 * x / 64.0); });
  EXPECT_NEAR(an::order_parameter(f), 3.0 / std::sqrt(2.0), 1e-12);
}

// ---- Errors over independent samples -------------------------------------------------------

/// Fraction of `repeats` means of `cycles` samples that lie within 2 standard errors of `truth`.
template <class Sample>
double coverage_of(int repeats, int cycles, double truth, Sample sample, double* bias) {
  int covered = 0;
  *bias = 0.0;
  for (int r = 0; r < repeats; ++r) {
    std::vector<double> values;
    for (int c = 0; c < cycles; ++c) values.push_back(sample(static_cast<std::uint64_t>(r * cycles + c)));
    const an::MeanAndError m = an::mean_and_error(values);
    covered += std::abs(m.mean - truth) < 2.0 * m.standard_error;
    *bias += (m.mean - truth) / repeats;
  }
  return static_cast<double>(covered) / repeats;
}

TEST(PatternErrors, CoverageOfTheWavenumberOverCycles) {
  // Each cycle's stripes have a wavenumber m dk, m uniform in 6..10, a random phase and noise:
  // the mean k* over 20 cycles against the true mean 8 dk.
  const HorizontalGrid g{48, 48, 64.0, 64.0};
  const double dk = two_pi / g.lx;
  const auto sample = [&](std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    const double m = std::uniform_int_distribution<int>(6, 10)(rng);
    const double phase = std::uniform_real_distribution<double>(0.0, two_pi)(rng);
    return an::measure_pattern(sampled(g, stripes(m * dk, 0.0, phase), 0.2, seed + 77)).dominant.k;
  };
  double bias = 0.0;
  const double coverage = coverage_of(400, 20, 8.0 * dk, sample, &bias);
  std::cout << "k* over cycles: coverage of +-2 se " << coverage << ", bias " << bias / dk << " shells\n";
  RecordProperty("wavenumber_coverage", std::to_string(coverage));
  EXPECT_GE(coverage, 0.90);
  EXPECT_LE(coverage, 0.99);
  EXPECT_LT(std::abs(bias), 0.05 * dk);
}

TEST(PatternErrors, CoverageOfTheStripeMomentOverCycles) {
  // cos kx + c cos ky with c uniform in [0.2, 0.8] per cycle: A2 = (1 - c^2) / (1 + c^2),
  // whose mean over c is (2 (atan 0.8 - atan 0.2) - 0.6) / 0.6.
  const double k = two_pi * 8 / square_box.lx;
  const double truth = (2.0 * (std::atan(0.8) - std::atan(0.2)) - 0.6) / 0.6;
  const auto sample = [&](std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    const double c = std::uniform_real_distribution<double>(0.2, 0.8)(rng);
    const auto f = sampled(square_box, [&](double x, double y) { return std::cos(k * x) + c * std::cos(k * y); },
                           0.05, seed + 99);
    return an::measure_pattern(f).symmetry.a2;
  };
  double bias = 0.0;
  const double coverage = coverage_of(400, 20, truth, sample, &bias);
  std::cout << "A2 over cycles: coverage of +-2 se " << coverage << ", bias " << bias << "\n";
  RecordProperty("a2_coverage", std::to_string(coverage));
  EXPECT_GE(coverage, 0.90);
  EXPECT_LE(coverage, 0.99);
  EXPECT_LT(std::abs(bias), 0.005);
}

TEST(PatternErrors, SummaryOfMeasuresIsTheirMeanAndError) {
  std::vector<an::PatternMeasure> samples(4);
  const double k[] = {1.0, 2.0, 3.0, 6.0};
  for (int s = 0; s < 4; ++s) samples[s].dominant.k = k[s], samples[s].order_parameter = 2.0;
  const an::PatternSummary summary = an::summarize_patterns(samples);
  EXPECT_DOUBLE_EQ(summary.k.mean, 3.0);
  // sample standard deviation sqrt(14 / 3) over sqrt(4)
  EXPECT_NEAR(summary.k.standard_error, std::sqrt(14.0 / 3.0) / 2.0, 1e-14);
  EXPECT_EQ(summary.k.samples, 4u);
  EXPECT_DOUBLE_EQ(summary.order_parameter.mean, 2.0);
  EXPECT_DOUBLE_EQ(summary.order_parameter.standard_error, 0.0);
  EXPECT_TRUE(std::isnan(an::mean_and_error({5.0}).standard_error));
}

// ---- Bad input ----------------------------------------------------------------------------

TEST(PatternBadInput, RejectedWithMessagesNamingTheAllowedRange) {
  using shaker::testing::expect_input_error;
  const HorizontalGrid g{8, 8, 8.0, 8.0};
  expect_input_error([] { an::check_grid({0, 8, 8.0, 8.0}); }, {"0 x 8 cells", "nx >= 1"});
  expect_input_error([] { an::check_grid({8, 8, -1.0, 8.0}); }, {"box -1 x 8", "> 0"});
  expect_input_error([] { an::check_grid({8, 8, 8.0, NAN}); }, {"finite"});
  expect_input_error([&] { an::power_spectrum({g, std::vector<double>(63, 0.0)}); },
                     {"63 values for 8 x 8", "exactly nx ny"});
  expect_input_error([&] { an::power_spectrum({g, std::vector<double>(64, NAN)}); }, {"not finite"});
  expect_input_error([&] { an::dominant_wavenumber(an::power_spectrum({g, std::vector<double>(64, 1.0)})); },
                     {"uniform"});
  expect_input_error([&] { an::column_mass_field({{1.0, 2.0}, {1.0}, {1.0, 2.0}}, g); },
                     {"2 x, 1 y and 2 z", "one of each"});
  expect_input_error([&] { an::center_of_mass_height_field(an::ParticlePositions{}, g); }, {"no material"});
  expect_input_error([&] { an::column_mass_field(an::DensityColumns{g, 2, 0.0, 1.0, std::vector<double>(100)}); },
                     {"100 values for 8 x 8 x 2"});
  expect_input_error([&] { an::column_mass_field(an::DensityColumns{g, 1, 0.0, 0.0, std::vector<double>(64)}); },
                     {"dz = 0", "> 0"});
  const auto s = an::power_spectrum(white_noise(g, 1));
  expect_input_error([&] { an::pattern_symmetry(s, 1.0, {1.5, 1.2}); }, {"threshold 1.2", "(0, 1]"});
  expect_input_error([&] { an::pattern_symmetry(s, 1.0, {0.0, 0.5}); }, {"half-width 0", "> 0"});
  expect_input_error([&] { an::pattern_symmetry(s, -1.0); }, {"k* = -1"});
  expect_input_error([&] { an::cycle_to_cycle_correlation({white_noise(g, 1)}); }, {"1 field(s)", "at least two"});
  expect_input_error([&] { an::field_correlation(white_noise(g, 1), white_noise({8, 4, 8.0, 8.0}, 1)); },
                     {"the same grid"});
  expect_input_error([] { an::saturation({0.0, 1.0, 2.0}, {1.0, 1.0, 1.0}, 1.5); }, {"fraction 1.5", "(0, 1]"});
  expect_input_error([] { an::saturation({0.0, 1.0}, {1.0, 1.0}); }, {"at least three"});
  expect_input_error([] { an::saturation({0.0, 2.0, 1.0}, {1.0, 1.0, 1.0}); }, {"strictly increasing"});
  expect_input_error([] { an::classify_symmetry(0.1, 0.1, 0.1, 0.0); }, {"threshold 0", "(0, 1]"});
}

}  // namespace
