#pragma once
// Convergence arithmetic: observed orders, least-squares order fits,
// Richardson extrapolation, Roache's grid convergence index (GCI) in the form of
// Celik et al., J. Fluids Eng. 130 (2008) 078001, and discrete error norms.
//
// Conventions: level 1 is the finest grid, h its representative spacing (or time step);
// r21 = h2 / h1 > 1. Everything here is a pure function of its arguments.
#include <cmath>
#include <cstddef>
#include <span>
#include <string>

namespace shaker::convergence {

/// Observed order between two levels: p = ln(E_coarse / E_fine) / ln r.
double observed_order(double error_coarse, double error_fine, double refinement_ratio);

/// Least-squares fit of ln E = ln C + p ln h (gsl_fit_linear, unweighted).
struct OrderFit {
  double order = 0.0;           ///< slope p
  double order_std_error = 0.0; ///< from the residual scatter; NaN for a two-point fit
  double log_constant = 0.0;    ///< ln C
  std::size_t points = 0;
};

/// Fits the `finest` levels with the smallest h (all levels when finest == 0).
/// Throws std::invalid_argument for mismatched sizes, fewer than 2 points, or h, E <= 0.
OrderFit fit_order(std::span<const double> h, std::span<const double> error,
                   std::size_t finest = 0);

/// Richardson extrapolation phi_ext = (r^p phi_fine - phi_coarse) / (r^p - 1).
double richardson_extrapolate(double phi_fine, double phi_coarse, double refinement_ratio,
                              double order);

/// Sign pattern of eps32 / eps21 (eps21 = phi2 - phi1, eps32 = phi3 - phi2); two_grids: only
/// two levels, so the order is assumed and nothing about the pattern is known. A change within
/// round-off of the values (`round_off_change`) is no change: stagnant.
enum class ConvergenceKind { monotonic, oscillatory, stagnant, two_grids };
std::string to_string(ConvergenceKind kind);

inline constexpr double safety_factor_three_grids = 1.25;
/// A change between two levels at most this fraction of the largest |phi| is round-off: a
/// quantity assembled from cell centres (the shock width 3.7 = 3.7000000000000028 on one grid
/// and 3.6999999999999993 on the next) would otherwise converge "monotonically" at order 45.
inline constexpr double round_off_change = 1e-12;
inline constexpr double safety_factor_two_grids = 3.0;
/// Three grids outside the asymptotic range (Oberkampf and Roy 2010), and the least order
/// their GCI takes.
inline constexpr double safety_factor_outside_asymptotic_range = 3.0;
inline constexpr double least_order_outside_asymptotic_range = 0.5;

/// The three-grid procedure of Celik et al. (2008): apparent order by fixed-point iteration
/// (needed when r21 != r32), extrapolated value, relative errors, fine-grid GCI21, GCI32 and
/// the asymptotic-range ratio GCI32 / (r21^p GCI21) (close to 1 in the asymptotic range).
/// Relative quantities are fractions (not percent).
struct GciResult {
  double r21 = 0.0, r32 = 0.0;
  double order = 0.0;               ///< apparent order p
  bool order_converged = false;     ///< fixed-point iteration met its tolerance
  int iterations = 0;
  double phi_extrapolated = 0.0;    ///< phi_ext^21
  double relative_difference21 = 0.0;   ///< e_a^21 = |(phi1 - phi2) / phi1|
  double relative_difference32 = 0.0;   ///< e_a^32 = |(phi2 - phi3) / phi2|
  double extrapolated_error21 = 0.0;    ///< e_ext^21 = |(phi_ext - phi1) / phi_ext|
  double gci21 = 0.0;               ///< fine-grid GCI = Fs e_a^21 / (r21^p - 1)
  double gci32 = 0.0;               ///< Fs e_a^32 / (r32^p - 1)
  double asymptotic_ratio = 0.0;    ///< GCI32 / (r21^p GCI21)
  ConvergenceKind kind = ConvergenceKind::monotonic;
};

/// h1 < h2 < h3 (fine to coarse) and the quantity on each grid.
GciResult three_grid_gci(double h1, double h2, double h3, double phi1, double phi2, double phi3,
                         double safety_factor = safety_factor_three_grids);

/// Two grids: the order cannot be observed, so the formal order is assumed; Fs = 3.
struct TwoGridGci {
  double r21 = 0.0, order = 0.0, phi_extrapolated = 0.0, relative_difference21 = 0.0, gci21 = 0.0;
};
TwoGridGci two_grid_gci(double h1, double h2, double phi1, double phi2, double assumed_order,
                        double safety_factor = safety_factor_two_grids);

/// Discrete norms of (numeric - exact) on a uniform grid, normalised by the number of cells
/// so that they approximate the continuous norms over unit volume:
/// L1 = sum|e| / N, L2 = sqrt(sum e^2 / N), Linf = max |e|.
struct ErrorNorms {
  double l1 = 0.0, l2 = 0.0, linf = 0.0;
};
ErrorNorms error_norms(std::span<const double> numeric, std::span<const double> exact);

/// |actual - expected| / |expected| (the absolute difference when expected is zero).
inline double relative_error(double actual, double expected) {
  const double difference = std::abs(actual - expected);
  return expected == 0.0 ? difference : difference / std::abs(expected);
}

}  // namespace shaker::convergence
