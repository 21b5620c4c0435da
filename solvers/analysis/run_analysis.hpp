#pragma once
// The analysis of a whole run (docs/analysis.md): every per-phase quantity, the shock's life
// over the cycle, and, for MD runs that keep their per-cycle sums, the jackknife standard
// error of every number over the independent samples (cycles, or repeated runs pooled).
#include <optional>
#include <string>
#include <vector>

#include "analysis/analysis.hpp"
#include "analysis/front_fit.hpp"
#include "common/profile.hpp"

namespace shaker::analysis {

/// Everything the analysis derives at one stored phase.
struct PhaseQuantities {
  double phase = 0.0, time = 0.0, plate_z = 0.0, center_of_mass = 0.0, max_mach = 0.0;
  std::optional<Layer> layer;
  /// Height below which 1 % of the material lies: a layer bottom that does not depend on a
  /// volume-fraction threshold in the dilute gas. Never below the plate.
  double mass_bottom = 0.0;
  /// number-weighted mean T over the bins inside the layer where T is defined (NaN without)
  double layer_temperature = 0.0;
  /// The fraction of the material where the local Knudsen number exceeds knudsen_limit.
  double knudsen_mass_fraction = 0.0;
  /// dT/dz of a least-squares line through the bins with material and a defined T in the span
  /// above the layer's top (the dilute gas above the layer); NaN with fewer than 3 such bins.
  double temperature_slope_above = 0.0;
  std::optional<Shock> shock;
  /// A tanh front fitted to T across the shock (front_fit.hpp), where the fit resolves it
  /// (width error below the width): a width that does not depend on the bin.
  std::optional<FrontFit> front;
  double front_mean_free_path = 0.0;  ///< xi at the fitted front's centre
};

/// Half-width of the window fitted around a shock: the larger of 1.5 paper widths and this.
inline constexpr double front_window_minimum = 4.0;

/// The shock's life over the stored phases.
struct ShockLife {
  std::vector<std::size_t> phases;  ///< indices, in time order (may wrap the cycle)
  double formation_phase = 0.0;     ///< first phase of the life (negative if it wraps)
  double exit_phase = 0.0;          ///< where the shock meets the layer top (interpolated)
  double lifetime = 0.0;            ///< exit - formation, in cycles
  double speed = 0.0;               ///< slope of location - plate_z against t, plate frame
  double speed_fit_error = 0.0;     ///< standard error of that slope from the fit residuals
  /// The speed's rounding step (NaN if fewer than 3 phases): the fit's window starts and ends
  /// at stored phases, and on a curved path the slope of a line is the speed at the window's
  /// centre (exactly, for a parabola), so the phase grid rounds the speed as it rounds the
  /// window: |2 c| s / sqrt(2), c the t^2 coefficient of the fitted heights, s the spacing in
  /// time (the centre, the mean of two ends each rounded by one spacing, has the variance of a
  /// value rounded to s / sqrt(2)).
  double speed_resolution = 0.0;
  double curvature = 0.0;           ///< 2 x the t^2 coefficient of location(t); NaN if < 4 points
  /// Means over the phases of the life with the front clear of the plate (NaN without one).
  double width_mean = 0.0, width_over_mfp_mean = 0.0;
};

struct RunQuantities {
  std::vector<PhaseQuantities> phases;
  std::optional<ShockLife> shock;
  double center_of_mass_mean = 0.0, center_of_mass_apex = 0.0;
  double width_over_mfp_peak_phase = 0.0;  ///< phase of the largest d/xi in the life (NaN)
  double layer_temperature_peak = 0.0;     ///< largest layer_temperature over the phases
  double max_mach_peak = 0.0;              ///< largest max_mach over the phases
  double bin_height = 0.0;                 ///< of the profiles (MD bin or continuum cell)
};

/// Height above the layer's top over which temperature_slope_above is fitted.
inline constexpr double gas_span_above_layer = 10.0;

struct AnalysisOptions {
  ShockCriteria criteria;
  /// The longest time, in cycles, for which the shock rule may miss a shock without ending its
  /// life: each stored phase without a shock between two with one stands for one phase
  /// spacing. A time, not a count of phases, so that the life does not depend on how finely
  /// the run is stored (docs/analysis.md).
  double max_gap = 0.02;
  /// A front closer to the plate than this (sigma), or than two bins, sits in the lowest bins
  /// whatever its true height: such phases are left out of the speed and of d and d/xi.
  double plate_clearance = 2.0;
  /// The exit is extrapolated from the gap (layer top - shock) over the life's last
  /// exit_window cycles, at most exit_reach cycles beyond the last phase with a shock.
  double exit_window = 0.06, exit_reach = 0.05;
  bool periodic = true;  ///< the stored phases are one periodic cycle (a life may wrap)
  double frequency = 1.0;  ///< f, to place phases of a wrapped life on one time axis
};

/// The analysis of a set of profiles (one per stored phase, in phase order).
RunQuantities analyze_profiles(const std::vector<Profile>& profiles, double e,
                               const AnalysisOptions& options);

/// A named quantity with its unit (docs/units.md) and one value per stored phase, or a single
/// value for a per-run quantity; NaN where it does not exist (no layer, no shock).
struct NamedValues {
  std::string name, unit;
  std::vector<double> values;
  /// The grid the value is quantised to (the stored phases' spacing for a phase that is a
  /// stored phase, the bin height for a distance between bin centres), per entry; empty if
  /// the value is not quantised. Its uniform rounding error, resolution / sqrt(12), is part
  /// of the value's uncertainty (docs/analysis.md).
  std::vector<double> resolution = {};
};
/// The per-phase quantities as columns, in a fixed order (the columns of `shaker analyze`).
std::vector<NamedValues> phase_columns(const RunQuantities& r);
/// The per-run quantities, one value each, in a fixed order.
std::vector<NamedValues> run_values(const RunQuantities& r);

/// Upward crossings of a height per cycle over the sampled cycles of a run (time-series
/// column crossings_z<h>): one count per cycle.
std::vector<double> crossings_per_cycle(const RunRecord& run, const std::string& column);

/// The profiles of `run` rebuilt from every sample but `left_out`.
std::vector<Profile> profiles_without(const RunRecord& run, std::size_t left_out);

/// Jackknife standard error of an estimate from its leave-one-out values (NaN entries are
/// dropped; NaN if fewer than two remain).
double jackknife_error(const std::vector<double>& leave_one_out);

/// The standard error of a value: the jackknife error over its leave-one-out values combined
/// in quadrature with the rounding error of a value quantised to `resolution` (resolution /
/// sqrt(12), the standard deviation of a uniform rounding error; NaN resolution: none). A
/// quantised value without replicates has the rounding error alone.
double standard_error(double value, const std::vector<double>& leave_one_out, double resolution);

}  // namespace shaker::analysis
