#pragma once
// Standing-wave patterns of a vibrated layer seen from above (docs/analysis.md, "Patterns"):
// a horizontal field on the periodic box (column mass or centre-of-mass height), its power
// spectrum, the dominant wavenumber, the symmetry of the pattern from the angular moments of
// the power around it (stripes, squares, hexagons as in Bougie et al., Phys. Rev. E 71,
// 021301 (2005)), the subharmonic response from cycle to cycle, the growth and saturation of
// the pattern's amplitude, and mean values with standard errors over independent samples.
// Lengths are in grain diameters sigma, wavenumbers in 1/sigma, the particle mass is 1.
// Bad input (an empty grid, a box that is not positive, sizes that disagree) throws
// InputError naming what is wrong and the allowed range.
#include <cstddef>
#include <string>
#include <vector>

namespace shaker::analysis {

/// The horizontal plane of the periodic box: nx x ny cells over Lx x Ly (sigma); cell (i, j)
/// is centred at x = (i + 1/2) Lx / nx, y = (j + 1/2) Ly / ny.
struct HorizontalGrid {
  std::size_t nx = 0, ny = 0;
  double lx = 0.0, ly = 0.0;
  std::size_t cells() const { return nx * ny; }
  double cell_area() const { return lx * ly / static_cast<double>(cells()); }
};

/// Throws InputError unless nx, ny >= 1 and Lx, Ly are finite and positive.
void check_grid(const HorizontalGrid& grid);
/// The same cells over the same box.
bool same_grid(const HorizontalGrid& a, const HorizontalGrid& b);

/// One value per cell, row-major: values[j * nx + i] (x varies fastest).
struct HorizontalField {
  HorizontalGrid grid;
  std::vector<double> values;
  double at(std::size_t i, std::size_t j) const { return values[j * grid.nx + i]; }
};

/// Particle centres (sigma), one entry per particle in each of x, y, z. x and y are wrapped
/// into the periodic box; z is the lab-frame height.
struct ParticlePositions {
  std::vector<double> x, y, z;
};

/// Mass per unit area over each cell (particles per sigma^2): the column mass.
HorizontalField column_mass_field(const ParticlePositions& particles, const HorizontalGrid& grid);

/// Mean height of the particles over each cell (sigma). A cell without a particle takes the
/// mean height of all particles, so that it adds nothing to the spectrum of the mean-removed
/// field. InputError if there is no particle.
HorizontalField center_of_mass_height_field(const ParticlePositions& particles,
                                            const HorizontalGrid& grid);

/// A number density n(x, y, z) (1/sigma^3) on nx x ny x nz cells of the box, index
/// (k * ny + j) * nx + i (as the 3D continuum stores it); cell k spans
/// [z_bottom + k dz, z_bottom + (k + 1) dz].
struct DensityColumns {
  HorizontalGrid grid;
  std::size_t nz = 0;
  double z_bottom = 0.0, dz = 0.0;
  std::vector<double> n;
};

/// Column mass sum_k n dz over each horizontal cell (1/sigma^2).
HorizontalField column_mass_field(const DensityColumns& density);
/// Centre-of-mass height sum_k n z_k / sum_k n over each column (sigma), z_k the cell centre;
/// a column without material takes the mean height of all material.
HorizontalField center_of_mass_height_field(const DensityColumns& density);

/// Power of the mean-removed field per Fourier mode: P(k) = |F(k)|^2 / N^2 with
/// F(k) = sum_x (f(x) - mean f) exp(-i k.x) over the N = nx ny cells, so that sum_k P(k) is
/// the mean square of f - mean f (Parseval). Mode (i, j) has k = 2 pi (m_i / Lx, m_j / Ly)
/// with m_i = i for i <= nx / 2 and i - nx above (negative frequencies; the Nyquist mode of an
/// even n counted as positive).
struct PowerSpectrum {
  HorizontalGrid grid;
  std::vector<double> power;  ///< [j * nx + i], units of the field squared
  double kx(std::size_t i) const;
  double ky(std::size_t j) const;
  double total() const;  ///< sum of P: the variance of the field over the cells
};
/// The spectrum by GSL's mixed-radix FFT (any nx, ny). InputError if a value is not finite.
PowerSpectrum power_spectrum(const HorizontalField& field);

/// The width of the shells in |k|: 2 pi / max(Lx, Ly), the finest spacing of the modes.
double shell_width(const HorizontalGrid& grid);

/// The power in shells of |k|: shell s holds the modes with |k| in [(s - 1/2) dk, (s + 1/2) dk),
/// dk = shell_width. The mode k = 0 (zero power) is left out.
struct RadialSpectrum {
  double dk = 0.0;
  std::vector<double> k;       ///< shell centres s dk
  std::vector<double> power;   ///< summed P over the shell's modes
  std::vector<std::size_t> modes;  ///< modes in the shell
  double average(std::size_t s) const;  ///< power / modes: the radially averaged spectrum
};
RadialSpectrum radial_spectrum(const PowerSpectrum& spectrum);

/// The dominant wavenumber k* (1/sigma) and wavelength 2 pi / k* (sigma). The peak is the shell
/// carrying the most power (summed, not averaged: a shell's power is the variance at that
/// |k| whatever number of lattice modes it happens to hold), refined below a shell width by
/// the power-weighted mean |k| of the modes in it and its two neighbouring shells.
struct DominantWavenumber {
  double k = 0.0, wavelength = 0.0;
  double peak_power = 0.0;  ///< power of the peak shell
};
/// InputError if the field is uniform (no power at any k).
DominantWavenumber dominant_wavenumber(const PowerSpectrum& spectrum);

enum class PatternSymmetry { stripes, squares, hexagons, disordered };
std::string to_string(PatternSymmetry symmetry);

struct SymmetryOptions {
  /// Half-width of the annulus around k*, in shell widths (> 0): wide enough for the power a
  /// pattern that does not fit the box leaks into neighbouring modes.
  double annulus_shells = 1.5;
  /// A moment at or above this (in (0, 1]) makes the pattern of its order: the first of A2,
  /// A4, A6 to reach it names the symmetry (stripes, squares, hexagons); none: disordered.
  /// Stripes have A2 = A4 = A6 = 1, squares A2 = 0, A4 = 1, hexagons A2 = A4 = 0, A6 = 1;
  /// isotropic noise over M modes has A_n of order 1 / sqrt(M).
  double threshold = 0.5;
};

/// A_n = |sum P(k) exp(i n theta_k)| / sum P(k) over the modes with ||k| - k*| <= annulus,
/// theta_k the angle of k from the x axis, and the symmetry they give.
struct PatternSymmetryMeasure {
  double a2 = 0.0, a4 = 0.0, a6 = 0.0;
  std::size_t modes = 0;  ///< modes in the annulus
  PatternSymmetry symmetry = PatternSymmetry::disordered;
};
PatternSymmetryMeasure pattern_symmetry(const PowerSpectrum& spectrum, double k_star,
                                        const SymmetryOptions& options = {});
/// The symmetry that moments A2, A4, A6 give under `threshold` (SymmetryOptions::threshold):
/// also for moments averaged over samples.
PatternSymmetry classify_symmetry(double a2, double a4, double a6, double threshold);

/// Pearson correlation of two fields on the same grid over the cells (NaN if either is
/// uniform).
double field_correlation(const HorizontalField& a, const HorizontalField& b);

/// Pearson correlation of `now` with `before` translated by half a wavelength along the
/// wavevector k0 of `now`'s strongest Fourier mode (of k0 and -k0 the one with kx > 0, or kx = 0
/// and ky > 0; by d = pi k0 / |k0|^2, in Fourier space:
/// F_before(k) exp(-i k.d)). A subharmonic standing wave repeats one drive cycle later shifted
/// by half its wavelength, whatever its waveform: +1 for it, where field_correlation gives -1
/// only for a sinusoid (the even harmonics of a steep wave do not invert). NaN if either field
/// is uniform; InputError for differing grids or a value that is not finite.
double half_wavelength_correlation(const HorizontalField& before, const HorizontalField& now);

/// The correlation of the fields at one phase of consecutive cycles, averaged over the pairs
/// (0-1, 1-2, ...): -1 for a pattern that inverts every cycle (subharmonic, period two drive
/// cycles), +1 for one that repeats (harmonic). The error is the standard error of the mean
/// over the pairs (pairs sharing a field are uncorrelated for independent fields). Pairs
/// with a uniform field are left out. InputError with fewer than two fields or differing grids.
struct CycleCorrelation {
  double mean = 0.0, standard_error = 0.0;
  std::size_t pairs = 0;
};
CycleCorrelation cycle_to_cycle_correlation(const std::vector<HorizontalField>& same_phase);

/// The pattern's amplitude at one instant: the rms of the mean-removed field (sqrt of the
/// total power), in the field's unit. A single cosine of amplitude a gives a / sqrt(2).
double order_parameter(const HorizontalField& field);

/// The saturation of an order parameter sampled at increasing times.
struct Saturation {
  double value = 0.0, standard_error = 0.0;  ///< mean over the last third of the samples
  /// First time the order parameter reaches fraction x value, interpolated linearly between
  /// the samples either side (NaN if it never does).
  double time = 0.0;
};
/// fraction in (0, 1]; at least three samples; times strictly increasing.
Saturation saturation(const std::vector<double>& times, const std::vector<double>& order,
                      double fraction = 0.9);

/// Mean over independent samples (cycles) and its standard error, the jackknife error of
/// run_analysis.hpp over the leave-one-out means (NaN entries dropped; error NaN below two).
struct MeanAndError {
  double mean = 0.0, standard_error = 0.0;
  std::size_t samples = 0;
};
MeanAndError mean_and_error(const std::vector<double>& samples);

/// The pattern quantities of one field.
struct PatternMeasure {
  DominantWavenumber dominant;
  PatternSymmetryMeasure symmetry;
  double order_parameter = 0.0;
};
PatternMeasure measure_pattern(const HorizontalField& field, const SymmetryOptions& options = {});

/// Means and standard errors over fields taken at independent instants (one per cycle).
struct PatternSummary {
  MeanAndError k, wavelength, a2, a4, a6, order_parameter;
};
PatternSummary summarize_patterns(const std::vector<PatternMeasure>& samples);

}  // namespace shaker::analysis
