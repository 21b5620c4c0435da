#pragma once
// Analysis quantities of physics.md as pure functions on a Profile. The same code serves MD
// and continuum output (and `shaker analyze` / `shaker compare`).
#include <optional>
#include <string>
#include <vector>

#include "common/profile.hpp"

namespace shaker::analysis {

/// The layer threshold: nu > 0.04 nu_max.
inline constexpr double layer_volume_fraction = 0.04 * 0.65;

struct Layer {
  /// lowest height where nu crosses the threshold (interpolated), never below the plate
  double bottom = 0.0;
  double top = 0.0;     ///< highest such height
};
/// The layer, or nothing if no bin exceeds the threshold.
std::optional<Layer> find_layer(const Profile& p);

/// f at height `at`, linearly interpolated between the centres z (held constant beyond them).
double interpolate(const std::vector<double>& z, const std::vector<double>& f, double at);

/// Centre-of-mass height of all the material, sum(n z) / sum(n).
double center_of_mass(const Profile& p);

/// Ma = |u_z - V_p| / c in every bin (NaN where there is no material or u_z or T is
/// undefined, 0 where T = 0).
std::vector<double> mach_number(const Profile& p, double e);
/// Largest Ma inside the layer (0 if there is no layer).
double max_mach_in_layer(const Profile& p, double e);

/// What makes a temperature extremum real rather than noise. A drop or rise counts only if it
/// exceeds both a fraction of the peak temperature and a multiple of the combined standard
/// error of the two bins (when the profile carries standard errors).
struct ShockCriteria {
  double relative_drop = 0.25;  ///< minimum (T_max - T_min) / T_max
  double standard_errors = 3.0; ///< minimum drop in combined standard errors
  double relative_rise = 0.05;  ///< the rise above the minimum that confirms it, / T_max
  /// minimum fraction of the incoming velocity (relative to the plate, at the temperature
  /// minimum) that the flow has lost at the temperature maximum
  double deceleration = 0.5;
};

struct Shock {
  double location = 0.0;         ///< height of steepest temperature decrease, sub-bin
  double compressed_top = 0.0;   ///< height of the temperature maximum
  double undisturbed_bottom = 0.0;  ///< height of the temperature minimum above it
  double width = 0.0;            ///< d = undisturbed_bottom - compressed_top
  double mean_free_path = 0.0;   ///< xi at the shock location (n interpolated there)
  double width_over_mfp() const { return width / mean_free_path; }
};
/// The shock of physics.md ("Analysis quantities"), or nothing if the profile has none. It is
/// a shock in the layer: nu at its location is above the layer threshold and the location is
/// below the layer's top (see find_shock in analysis.cpp for why).
std::optional<Shock> find_shock(const Profile& p, const ShockCriteria& criteria = {});

/// The bins of p with material and a defined T (NaN marks an MD bin with fewer than two
/// particles; an older file's empty bin holds T = 0 with n = 0), every field of p kept for
/// those bins. What walks T from bin to bin (the shock, the fitted front, their mean free
/// paths) skips the other bins as if they were not there.
Profile with_defined_temperature(const Profile& p);

/// Local Knudsen numbers per bin (docs/analysis.md): the mean free path xi over the gradient
/// length of density, Kn_n = xi |dn/dz| / n, and of temperature, Kn_T = xi |dT/dz| / T.
/// Gradients are central differences over the neighbouring bins with material (one-sided at
/// the ends and beside an empty bin); NaN where the bin has no material or no defined
/// neighbour, and Kn_T NaN where T is not positive or undefined.
struct KnudsenNumbers {
  std::vector<double> density, temperature;
};
KnudsenNumbers knudsen_numbers(const Profile& p);

/// Navier-Stokes order is expected to hold where Kn is well below this.
inline constexpr double knudsen_limit = 0.1;
/// The fraction of the material in bins where the larger of Kn_n and Kn_T exceeds `limit`.
double knudsen_mass_fraction(const Profile& p, const KnudsenNumbers& kn, double limit = knudsen_limit);

/// Everything `shaker analyze` prints for one phase.
struct PhaseSummary {
  double phase = 0.0, plate_z = 0.0, center_of_mass = 0.0, max_mach = 0.0;
  std::optional<Layer> layer;
  std::optional<Shock> shock;
};
PhaseSummary summarize(const Profile& p, double e);


// ---- Agreement metrics ------------------------------------------------------------------

struct SeriesDifference {
  std::size_t count = 0;      ///< pairs where both series exist
  double absolute_rms = 0.0;  ///< sqrt(mean((a - b)^2))
  double fractional_rms = 0.0;  ///< absolute_rms / sqrt(mean(b^2))
};
/// Compares a(t) with b(t) over the entries where both are present (NaN marks absence).
/// Throws std::invalid_argument if the lengths differ.
SeriesDifference series_difference(const std::vector<double>& a, const std::vector<double>& b);

struct ProfileNorms {
  double l1 = 0.0, l2 = 0.0, linf = 0.0;  ///< mean |d|, sqrt(mean d^2), max |d|
  std::size_t count = 0;                  ///< heights compared
};
/// Norms of a.field - b.field at a's heights inside the range both cover (b interpolated
/// linearly), leaving out heights where either is undefined (NaN: an MD bin without
/// particles). field is "nu" or "T".
ProfileNorms profile_difference(const Profile& a, const Profile& b, const std::string& field);

/// The metrics of physics.md between two runs sampled at the same phases.
struct RunComparison {
  SeriesDifference shock_location;   ///< over phases where both have a shock
  SeriesDifference center_of_mass;   ///< over all phases
  std::vector<double> phases;
  std::vector<ProfileNorms> nu_norms, T_norms;  ///< per phase
};
/// Pairs each phase of a with the nearest phase of b; throws std::invalid_argument if the
/// phase grids differ.
RunComparison compare_runs(const RunRecord& a, const RunRecord& b);

}  // namespace shaker::analysis
