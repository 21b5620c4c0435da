// The time behaviour of pattern.hpp: cycle-to-cycle correlation, the order parameter and its
// saturation, and means with standard errors over independent samples.
#include "analysis/pattern.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "analysis/run_analysis.hpp"
#include "common/errors.hpp"

namespace shaker::analysis {
namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

void check_field(const HorizontalField& f) {
  check_grid(f.grid);
  if (f.values.size() != f.grid.cells())
    throw InputError(fmt::format("pattern field: {} values for {} x {} cells; allowed: exactly "
                                 "nx ny", f.values.size(), f.grid.nx, f.grid.ny));
}

double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

}  // namespace

bool same_grid(const HorizontalGrid& a, const HorizontalGrid& b) {
  return a.nx == b.nx && a.ny == b.ny && a.lx == b.lx && a.ly == b.ly;
}

double field_correlation(const HorizontalField& a, const HorizontalField& b) {
  check_field(a);
  check_field(b);
  if (!same_grid(a.grid, b.grid))
    throw InputError(fmt::format("field correlation: grids {} x {} over {} x {} and {} x {} over "
                                 "{} x {}; allowed: the same grid", a.grid.nx, a.grid.ny, a.grid.lx,
                                 a.grid.ly, b.grid.nx, b.grid.ny, b.grid.lx, b.grid.ly));
  const double mean_a = mean_of(a.values), mean_b = mean_of(b.values);
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (std::size_t c = 0; c < a.values.size(); ++c) {
    const double da = a.values[c] - mean_a, db = b.values[c] - mean_b;
    ab += da * db, aa += da * da, bb += db * db;
  }
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : nan;
}

CycleCorrelation cycle_to_cycle_correlation(const std::vector<HorizontalField>& same_phase) {
  if (same_phase.size() < 2)
    throw InputError(fmt::format("cycle-to-cycle correlation: {} field(s); allowed: at least two "
                                 "consecutive cycles", same_phase.size()));
  std::vector<double> pairs;
  for (std::size_t c = 0; c + 1 < same_phase.size(); ++c)
    pairs.push_back(field_correlation(same_phase[c], same_phase[c + 1]));
  const MeanAndError m = mean_and_error(pairs);
  return {m.mean, m.standard_error, m.samples};
}

double order_parameter(const HorizontalField& field) { return std::sqrt(power_spectrum(field).total()); }

Saturation saturation(const std::vector<double>& times, const std::vector<double>& order, double fraction) {
  if (times.size() != order.size() || times.size() < 3)
    throw InputError(fmt::format("saturation: {} times and {} values; allowed: equal numbers, at "
                                 "least three", times.size(), order.size()));
  if (!(fraction > 0.0 && fraction <= 1.0))
    throw InputError(fmt::format("saturation: fraction {}; allowed: (0, 1]", fraction));
  for (std::size_t s = 0; s < times.size(); ++s)
    if (!std::isfinite(times[s]) || !std::isfinite(order[s]) || (s > 0 && !(times[s] > times[s - 1])))
      throw InputError(fmt::format("saturation: sample {} (t = {}, value {}); allowed: finite, "
                                   "times strictly increasing", s, times[s], order[s]));
  const std::size_t first_of_last_third = times.size() - times.size() / 3;
  const MeanAndError last_third = mean_and_error(
      std::vector<double>(order.begin() + static_cast<std::ptrdiff_t>(first_of_last_third), order.end()));
  Saturation result{last_third.mean, last_third.standard_error, nan};
  const double level = fraction * last_third.mean;
  for (std::size_t s = 0; s < order.size(); ++s) {
    if (order[s] < level) continue;
    if (s == 0) {
      result.time = times[0];
    } else {
      const double w = (level - order[s - 1]) / (order[s] - order[s - 1]);
      result.time = times[s - 1] + w * (times[s] - times[s - 1]);
    }
    break;
  }
  return result;
}

MeanAndError mean_and_error(const std::vector<double>& samples) {
  std::vector<double> finite;
  for (double x : samples)
    if (std::isfinite(x)) finite.push_back(x);
  if (finite.empty()) return {nan, nan, 0};
  const double n = static_cast<double>(finite.size()), mean = mean_of(finite);
  std::vector<double> leave_one_out;
  for (double x : finite) leave_one_out.push_back(n > 1.0 ? (n * mean - x) / (n - 1.0) : nan);
  return {mean, jackknife_error(leave_one_out), finite.size()};
}

PatternMeasure measure_pattern(const HorizontalField& field, const SymmetryOptions& options) {
  const PowerSpectrum spectrum = power_spectrum(field);
  PatternMeasure m;
  m.dominant = dominant_wavenumber(spectrum);
  m.symmetry = pattern_symmetry(spectrum, m.dominant.k, options);
  m.order_parameter = std::sqrt(spectrum.total());
  return m;
}

PatternSummary summarize_patterns(const std::vector<PatternMeasure>& samples) {
  const auto over = [&](auto get) {
    std::vector<double> values;
    for (const auto& s : samples) values.push_back(get(s));
    return mean_and_error(values);
  };
  return {over([](const PatternMeasure& m) { return m.dominant.k; }),
          over([](const PatternMeasure& m) { return m.dominant.wavelength; }),
          over([](const PatternMeasure& m) { return m.symmetry.a2; }),
          over([](const PatternMeasure& m) { return m.symmetry.a4; }),
          over([](const PatternMeasure& m) { return m.symmetry.a6; }),
          over([](const PatternMeasure& m) { return m.order_parameter; })};
}

}  // namespace shaker::analysis
