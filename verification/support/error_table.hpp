#pragma once
// Error tables and study summaries as small CSV files, the input of
// reports/make_convergence_report.py (its docstring documents the same schema).
//
//   <name>.errors.csv  study,field,norm,level,h,error
//   <name>.orders.csv  study,field,norm,fit_points,fitted_order,order_std_error,
//                      pair_order_finest,pair_order_next,design_order,tolerance,pass
//   <name>.gci.csv     study,quantity,h1,h2,h3,phi1,phi2,phi3,order,phi_extrapolated,
//                      relative_difference21,extrapolated_error21,gci21,gci32,
//                      asymptotic_ratio,convergence,asymptotic_tolerance,pass
//                      (two-grid rows: h3, phi3, gci32, asymptotic_ratio, pass are nan and
//                      convergence is "two-grids")
//
// Numbers are written with 17 significant digits (exact round trip); names may not contain
// commas, quotes or line breaks. Files are written atomically (temp file + rename).
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "support/convergence.hpp"

namespace shaker::convergence {

struct ErrorRow {
  std::string study;  ///< e.g. "mms-1d-full-space"
  std::string field;  ///< n, ux, uy, uz, T, ...
  std::string norm;   ///< L1, L2, Linf
  int level = 0;      ///< 0 = coarsest
  double h = 0.0;     ///< grid spacing or time step
  double error = 0.0;
};

class ErrorTable {
 public:
  void add(ErrorRow row);
  /// The three norms of one field on one level.
  void add_norms(const std::string& study, const std::string& field, int level, double h,
                 const ErrorNorms& norms);
  const std::vector<ErrorRow>& rows() const { return rows_; }

  /// Distinct (study, field, norm) triples in first-appearance order.
  struct Key {
    std::string study, field, norm;
  };
  std::vector<Key> series_keys() const;
  /// Rows of one series sorted from coarse to fine (decreasing h).
  std::vector<ErrorRow> series(const Key& key) const;

  std::string to_csv() const;
  static ErrorTable from_csv(const std::string& text);  ///< throws std::runtime_error
  void write_csv(const std::filesystem::path& path) const;
  static ErrorTable read_csv(const std::filesystem::path& path);

 private:
  std::vector<ErrorRow> rows_;
};

/// Observed order of one series against its design order.
struct OrderCheck {
  std::string study, field, norm;
  std::size_t fit_points = 0;
  double fitted_order = 0.0;       ///< least-squares slope over the fit_points finest levels
  double order_std_error = 0.0;
  double pair_order_finest = 0.0;  ///< two-level order of the finest pair
  double pair_order_next = 0.0;    ///< of the next pair (NaN with only two levels)
  double design_order = 0.0;
  double tolerance = 0.0;
  /// Fitted and both pair orders within tolerance of the design order (NaN fails).
  bool pass() const;
};

/// One OrderCheck per series of the table; each series needs at least two levels.
std::vector<OrderCheck> check_orders(const ErrorTable& table, double design_order,
                                     double tolerance, std::size_t fit_points = 3);
std::string orders_to_csv(std::span<const OrderCheck> checks);
void write_orders_csv(const std::filesystem::path& path, std::span<const OrderCheck> checks);

/// A quantity of interest on three grids with its GCI analysis (or on two grids: h3, phi3 and
/// the asymptotic ratio are NaN, the order is assumed, Fs = 3 and there is nothing to check).
struct GciRow {
  std::string study, quantity;
  double h1 = 0.0, h2 = 0.0, h3 = 0.0, phi1 = 0.0, phi2 = 0.0, phi3 = 0.0;
  GciResult result;
  /// pass: the three grids converge monotonically and |asymptotic_ratio - 1| <= tolerance (an
  /// oscillation's ratio, from the magnitudes of its changes, can fall near 1 by accident)
  double asymptotic_tolerance = 0.1;
  /// False where the study reads the asymptotic ratio as a diagnostic and claims something
  /// else (a time-step study: its time error against the grid error, a BoundCheck).
  bool asymptotic_range_claimed = true;
  bool checked() const {
    return asymptotic_range_claimed && result.kind != ConvergenceKind::two_grids;
  }
  bool pass() const;
};
GciRow make_gci_row(const std::string& study, const std::string& quantity, double h1, double h2,
                    double h3, double phi1, double phi2, double phi3,
                    double asymptotic_tolerance = 0.1);
GciRow make_two_grid_gci_row(const std::string& study, const std::string& quantity, double h1,
                             double h2, double phi1, double phi2, double assumed_order);
/// The discretisation uncertainty of a three-grid study's finest value phi1, or of its middle
/// value phi2. In the asymptotic range (pass()): Roache's GCI, Fs |phi1 - phi2| / (r21^p - 1)
/// or Fs |phi2 - phi3| / (r32^p - 1), with the observed order p held at or below the formal
/// one (with a constant refinement ratio the asymptotic ratio is phi1 / phi2 for any p, so it
/// cannot tell an order of 10 from one of 2; an order above the formal one is a cancellation,
/// as in coarse_level_error). Otherwise nothing can be extrapolated: a monotonic triple gives
/// the change between the finest pair |phi1 - phi2|; an oscillating or stagnant one at least
/// half the range of its three values (Stern, Wilson, Coleman and Paterson, J. Fluids Eng.
/// 123, 793, 2001), since the finest pair of an oscillation may agree by accident (on
/// synthetic triples with a random first-order scatter, |phi1 - phi2| alone covers the true
/// error of phi1 in about two thirds of the oscillating draws, this rule in over nine tenths:
/// support.GridUncertainty).
double fine_grid_uncertainty(const GciRow& row, double formal_order);
double middle_grid_uncertainty(const GciRow& row, double formal_order);

/// The error of a three-level study's coarsest value phi3, where the study refines from the
/// setting in production (the time-step studies: phi3 at the production step). Richardson
/// extrapolation from the two finest levels only where the levels converge monotonically
/// (|phi3 - phi2| > |phi2 - phi1|, exact for a constant ratio) in the asymptotic range
/// (row.pass()), with the observed order held at or below the formal order: an order above
/// it reads a cancellation of error terms as fast convergence and would put phi_ext too close
/// to phi1 (Roache, Verification and Validation in Computational Science and Engineering,
/// 1998, uses min(p, p_formal) likewise). Otherwise (oscillating, diverging or stagnant
/// levels) nothing can be extrapolated, and the error is the largest change from phi3.
struct CoarseLevelError {
  enum class Method { extrapolated, extrapolated_at_formal_order, largest_change };
  double error = 0.0;
  Method method = Method::largest_change;
};
CoarseLevelError coarse_level_error(const GciRow& row, double formal_order);
std::string to_string(CoarseLevelError::Method method);

/// A study's claim that an error lies within an uncertainty: `value` (e.g. the time error of
/// the production step, or |3D - 1D|) at most `bound` (e.g. the grid uncertainty); each basis
/// says how its number was obtained. A NaN bound (no estimate exists) is not checked.
struct BoundCheck {
  std::string study, quantity;
  double value = 0.0;
  std::string value_basis;
  double bound = 0.0;
  std::string bound_basis;
  bool checked() const { return !std::isnan(bound); }
  bool pass() const { return value <= bound; }  // <=: nothing changes and nothing may (0, 0)
};
std::string bounds_to_csv(std::span<const BoundCheck> rows);

std::string gci_to_csv(std::span<const GciRow> rows);
void write_gci_csv(const std::filesystem::path& path, std::span<const GciRow> rows);

/// Environment variable naming the directory that collects study tables for the nightly
/// convergence report (ci/nightly sets it; unset in ordinary ctest runs).
inline constexpr const char* study_directory_variable = "SHAKER_CONVERGENCE_DIR";

/// Writes each (suffix, text) of `files` to <directory>/<name><suffix>, atomically, and the
/// same files to SHAKER_CONVERGENCE_DIR when it is set. Returns every file written.
std::vector<std::filesystem::path> write_study_files(
    const std::filesystem::path& directory, const std::string& name,
    const std::vector<std::pair<std::string, std::string>>& files);

/// Writes <directory>/<name>.bounds.csv like write_study_files (and to SHAKER_CONVERGENCE_DIR).
std::vector<std::filesystem::path> write_bounds(const std::filesystem::path& directory,
                                                const std::string& name,
                                                std::span<const BoundCheck> rows);

/// Writes <directory>/<name>.errors.csv and <name>.orders.csv (and <name>.gci.csv when GCI
/// rows are given), atomically; when SHAKER_CONVERGENCE_DIR is set, writes the same files there
/// too. `name` must be unique per test (the test name) and may not contain '/'.
/// Returns every file written.
std::vector<std::filesystem::path> write_study(const std::filesystem::path& directory,
                                               const std::string& name, const ErrorTable& table,
                                               std::span<const OrderCheck> checks,
                                               std::span<const GciRow> gci = {});

}  // namespace shaker::convergence
