// The spectra of pattern.hpp: the 2D power spectrum (GSL's mixed-radix FFT), its shells in
// |k|, the dominant wavenumber and the angular moments of the power around it.
#include <fmt/format.h>
#include <gsl/gsl_fft_complex.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <stdexcept>

#include "analysis/pattern.hpp"
#include "common/errors.hpp"

namespace shaker::analysis {
namespace {

constexpr double two_pi = 2.0 * M_PI;

/// The signed index of Fourier mode i of n: i up to n / 2, i - n above.
double signed_mode(std::size_t i, std::size_t n) {
  return i <= n / 2 ? static_cast<double>(i) : static_cast<double>(i) - static_cast<double>(n);
}

/// The wavenumber (1/sigma) of Fourier mode i of n cells over `length`.
double wavenumber(std::size_t i, std::size_t n, double length) { return two_pi * signed_mode(i, n) / length; }

/// Forward FFT in place of `lines` complex sequences of length n, the l-th starting at complex
/// element l * line_step with elements `stride` apart (GSL's packed layout: re, im).
void fft_lines(std::vector<double>& data, std::size_t n, std::size_t stride, std::size_t lines,
               std::size_t line_step) {
  const std::unique_ptr<gsl_fft_complex_wavetable, decltype(&gsl_fft_complex_wavetable_free)>
      table(gsl_fft_complex_wavetable_alloc(n), &gsl_fft_complex_wavetable_free);
  const std::unique_ptr<gsl_fft_complex_workspace, decltype(&gsl_fft_complex_workspace_free)>
      work(gsl_fft_complex_workspace_alloc(n), &gsl_fft_complex_workspace_free);
  if (!table || !work) throw std::runtime_error(fmt::format("FFT of length {}: no memory", n));
  for (std::size_t l = 0; l < lines; ++l)
    if (gsl_fft_complex_forward(data.data() + 2 * l * line_step, stride, n, table.get(), work.get()) != 0)
      throw std::runtime_error(fmt::format("FFT of length {} failed", n));
}

/// The shell of |k| a mode belongs to (pattern.hpp, RadialSpectrum).
std::size_t shell_of(double k, double dk) { return static_cast<std::size_t>(std::floor(k / dk + 0.5)); }

void check_options(const SymmetryOptions& o) {
  if (!(o.annulus_shells > 0.0) || !std::isfinite(o.annulus_shells))
    throw InputError(fmt::format("pattern symmetry: annulus half-width {} shells; allowed: "
                                 "finite and > 0", o.annulus_shells));
  if (!(o.threshold > 0.0 && o.threshold <= 1.0))
    throw InputError(fmt::format("pattern symmetry: threshold {}; allowed: (0, 1]", o.threshold));
}

}  // namespace

double PowerSpectrum::kx(std::size_t i) const { return wavenumber(i, grid.nx, grid.lx); }
double PowerSpectrum::ky(std::size_t j) const { return wavenumber(j, grid.ny, grid.ly); }
double PowerSpectrum::total() const {
  double sum = 0.0;
  for (double p : power) sum += p;
  return sum;
}

namespace {

/// F(k) of the mean-removed field (pattern.hpp, PowerSpectrum), packed re, im per mode
/// [j * nx + i].
std::vector<double> fourier_coefficients(const HorizontalField& field) {
  check_grid(field.grid);
  const std::size_t nx = field.grid.nx, ny = field.grid.ny, cells = field.grid.cells();
  if (field.values.size() != cells)
    throw InputError(fmt::format("pattern field: {} values for {} x {} cells; allowed: exactly "
                                 "nx ny", field.values.size(), nx, ny));
  double mean = 0.0;
  for (double v : field.values) {
    if (!std::isfinite(v)) throw InputError(fmt::format("pattern field: value {} is not finite", v));
    mean += v / static_cast<double>(cells);
  }
  std::vector<double> data(2 * cells, 0.0);
  for (std::size_t c = 0; c < cells; ++c) data[2 * c] = field.values[c] - mean;
  fft_lines(data, nx, 1, ny, nx);  // rows: along x
  fft_lines(data, ny, nx, nx, 1);  // columns: along y
  return data;
}

}  // namespace

PowerSpectrum power_spectrum(const HorizontalField& field) {
  const std::vector<double> data = fourier_coefficients(field);
  const std::size_t cells = field.grid.cells();
  PowerSpectrum spectrum{field.grid, std::vector<double>(cells)};
  const double norm = 1.0 / (static_cast<double>(cells) * static_cast<double>(cells));
  for (std::size_t c = 0; c < cells; ++c)
    spectrum.power[c] = (data[2 * c] * data[2 * c] + data[2 * c + 1] * data[2 * c + 1]) * norm;
  return spectrum;
}

double half_wavelength_correlation(const HorizontalField& before, const HorizontalField& now) {
  if (!same_grid(before.grid, now.grid))
    throw InputError(fmt::format("half-wavelength correlation: grids {} x {} over {} x {} and {} x {} "
                                 "over {} x {}; allowed: the same grid", before.grid.nx, before.grid.ny,
                                 before.grid.lx, before.grid.ly, now.grid.nx, now.grid.ny, now.grid.lx,
                                 now.grid.ly));
  const std::vector<double> a = fourier_coefficients(before), b = fourier_coefficients(now);
  const HorizontalGrid& g = now.grid;
  const std::size_t nx = g.nx, cells = g.cells();
  std::size_t strongest = 0;
  double aa = 0.0, bb = 0.0, top = 0.0;
  for (std::size_t c = 0; c < cells; ++c) {
    const double power = b[2 * c] * b[2 * c] + b[2 * c + 1] * b[2 * c + 1];
    if (power > top) top = power, strongest = c;
    aa += a[2 * c] * a[2 * c] + a[2 * c + 1] * a[2 * c + 1], bb += power;
  }
  if (!(aa > 0.0) || !(bb > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  double k0x = wavenumber(strongest % nx, nx, g.lx), k0y = wavenumber(strongest / nx, g.ny, g.ly);
  // k0 and -k0 carry the same power: take the one with kx > 0 (or kx = 0, ky > 0), so that the
  // shift does not hang on the last bits of the two.
  if (k0x < 0.0 || (k0x == 0.0 && k0y < 0.0)) k0x = -k0x, k0y = -k0y;
  const double scale = M_PI / (k0x * k0x + k0y * k0y);
  const double dx = scale * k0x, dy = scale * k0y;
  double ab = 0.0;  // Re sum F_shifted(k) conj F_now(k)
  for (std::size_t c = 0; c < cells; ++c) {
    const std::complex<double> shifted =
        std::complex<double>(a[2 * c], a[2 * c + 1]) *
        std::polar(1.0, -(wavenumber(c % nx, nx, g.lx) * dx + wavenumber(c / nx, g.ny, g.ly) * dy));
    ab += std::real(shifted * std::complex<double>(b[2 * c], -b[2 * c + 1]));
  }
  return ab / std::sqrt(aa * bb);
}

double shell_width(const HorizontalGrid& grid) { return two_pi / std::max(grid.lx, grid.ly); }

double RadialSpectrum::average(std::size_t s) const {
  return modes[s] > 0 ? power[s] / static_cast<double>(modes[s]) : 0.0;
}

RadialSpectrum radial_spectrum(const PowerSpectrum& spectrum) {
  RadialSpectrum radial;
  radial.dk = shell_width(spectrum.grid);
  for (std::size_t j = 0; j < spectrum.grid.ny; ++j)
    for (std::size_t i = 0; i < spectrum.grid.nx; ++i) {
      if (i == 0 && j == 0) continue;
      const std::size_t s = shell_of(std::hypot(spectrum.kx(i), spectrum.ky(j)), radial.dk);
      if (s >= radial.power.size()) radial.power.resize(s + 1, 0.0), radial.modes.resize(s + 1, 0);
      radial.power[s] += spectrum.power[j * spectrum.grid.nx + i];
      ++radial.modes[s];
    }
  for (std::size_t s = 0; s < radial.power.size(); ++s) radial.k.push_back(radial.dk * static_cast<double>(s));
  return radial;
}

DominantWavenumber dominant_wavenumber(const PowerSpectrum& spectrum) {
  const RadialSpectrum radial = radial_spectrum(spectrum);
  if (radial.power.empty() || !(spectrum.total() > 0.0))
    throw InputError("dominant wavenumber: the field is uniform (no power at any k); allowed: a "
                     "field that varies over the box");
  const auto peak = static_cast<std::size_t>(
      std::max_element(radial.power.begin(), radial.power.end()) - radial.power.begin());
  double weighted = 0.0, sum = 0.0;
  for (std::size_t j = 0; j < spectrum.grid.ny; ++j)
    for (std::size_t i = 0; i < spectrum.grid.nx; ++i) {
      const double k = std::hypot(spectrum.kx(i), spectrum.ky(j));
      const std::size_t s = shell_of(k, radial.dk);
      if (k == 0.0 || s + 1 < peak || s > peak + 1) continue;
      weighted += spectrum.power[j * spectrum.grid.nx + i] * k;
      sum += spectrum.power[j * spectrum.grid.nx + i];
    }
  const double k_star = weighted / sum;
  return {k_star, two_pi / k_star, radial.power[peak]};
}

std::string to_string(PatternSymmetry symmetry) {
  switch (symmetry) {
    case PatternSymmetry::stripes: return "stripes";
    case PatternSymmetry::squares: return "squares";
    case PatternSymmetry::hexagons: return "hexagons";
    case PatternSymmetry::disordered: return "disordered";
  }
  return "disordered";
}

PatternSymmetryMeasure pattern_symmetry(const PowerSpectrum& spectrum, double k_star,
                                        const SymmetryOptions& options) {
  check_options(options);
  if (!(k_star > 0.0) || !std::isfinite(k_star))
    throw InputError(fmt::format("pattern symmetry: k* = {}; allowed: finite and > 0", k_star));
  const double half_width = options.annulus_shells * shell_width(spectrum.grid);
  std::complex<double> m2, m4, m6;
  double sum = 0.0;
  PatternSymmetryMeasure measure;
  for (std::size_t j = 0; j < spectrum.grid.ny; ++j)
    for (std::size_t i = 0; i < spectrum.grid.nx; ++i) {
      const double kx = spectrum.kx(i), ky = spectrum.ky(j), k = std::hypot(kx, ky);
      if (k == 0.0 || std::abs(k - k_star) > half_width) continue;
      const double p = spectrum.power[j * spectrum.grid.nx + i], theta = std::atan2(ky, kx);
      m2 += std::polar(p, 2.0 * theta);
      m4 += std::polar(p, 4.0 * theta);
      m6 += std::polar(p, 6.0 * theta);
      sum += p;
      ++measure.modes;
    }
  if (!(sum > 0.0)) return measure;  // no power near k*: nothing to order
  measure.a2 = std::abs(m2) / sum, measure.a4 = std::abs(m4) / sum, measure.a6 = std::abs(m6) / sum;
  measure.symmetry = classify_symmetry(measure.a2, measure.a4, measure.a6, options.threshold);
  return measure;
}

PatternSymmetry classify_symmetry(double a2, double a4, double a6, double threshold) {
  check_options({1.0, threshold});
  if (a2 >= threshold) return PatternSymmetry::stripes;
  if (a4 >= threshold) return PatternSymmetry::squares;
  if (a6 >= threshold) return PatternSymmetry::hexagons;
  return PatternSymmetry::disordered;
}

}  // namespace shaker::analysis
