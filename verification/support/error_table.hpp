#pragma once
// Error tables and study summaries as small CSV files, the input of
// reports/make_convergence_report.py (its docstring documents the same schema).
//
//   <name>.errors.csv  study,field,norm,level,h,error
//   <name>.orders.csv  study,field,norm,fit_points,fitted_order,order_std_error,
//                      pair_order_finest,pair_order_next,design_order,tolerance,pass
//   <name>.gci.csv     study,quantity,h1,h2,h3,phi1,phi2,phi3,order,phi_extrapolated,
//                      relative_difference21,extrapolated_error21,gci21,gci32,convergence,
//                      design_order,order_tolerance,uncertainty1,pass
//                      (order: GciRow::observed_order; uncertainty1: fine_grid_uncertainty,
//                      in phi's units; two-grid rows: h3, phi3, gci32, pass are nan and
//                      convergence is "two-grids")
//
// Numbers are written with 17 significant digits (exact round trip); names may not contain
// commas, quotes or line breaks. Files are written atomically (temp file + rename).
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
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

/// A quantity of interest on three grids with its GCI analysis (or on two grids: h3 and phi3
/// are NaN, the order is assumed, Fs = 3 and there is nothing to check).
struct GciRow {
  std::string study, quantity;
  double h1 = 0.0, h2 = 0.0, h3 = 0.0, phi1 = 0.0, phi2 = 0.0, phi3 = 0.0;
  GciResult result;
  /// The order the scheme is designed for, and the band around it in which an observed order
  /// places the triple in the asymptotic range (pass()).
  double design_order = 2.0;
  double order_tolerance = 0.1;
  /// False where the study reads the asymptotic ratio as a diagnostic and claims something
  /// else (a time-step study: its time error against the grid error, a BoundCheck).
  bool asymptotic_range_claimed = true;
  bool checked() const {
    return asymptotic_range_claimed && result.kind != ConvergenceKind::two_grids;
  }
  /// The observed order, negative where the changes grow under refinement (Celik's apparent
  /// order is a magnitude, so that a diverging triple would show a positive one).
  double observed_order() const;
  /// In the asymptotic range: the grids converge monotonically at an observed order within
  /// order_tolerance of design_order. (Celik's ratio GCI32 / (r21^p GCI21) is phi1 / phi2
  /// for a constant refinement ratio whatever p, so it would pass an order of 10 or 0.3; an
  /// oscillation's order says nothing, whatever its value.)
  bool pass() const;
};
GciRow make_gci_row(const std::string& study, const std::string& quantity, double h1, double h2,
                    double h3, double phi1, double phi2, double phi3, double design_order = 2.0,
                    double order_tolerance = 0.1);
GciRow make_two_grid_gci_row(const std::string& study, const std::string& quantity, double h1,
                             double h2, double phi1, double phi2, double assumed_order);
/// The discretisation uncertainty of a three-grid study's finest value phi1, or of its middle
/// value phi2: the GCI Fs |phi1 - phi2| / (r21^q - 1), or Fs |phi2 - phi3| / (r32^q - 1),
/// by the factor-of-safety rule of Oberkampf and Roy (Verification and Validation in
/// Scientific Computing, 2010, section 8.6): in the asymptotic range (pass()) Fs = 1.25;
/// outside it Fs = 3; q is the observed order held within [0.5, design_order] (an order
/// above the design one is a cancellation of error terms, one near 0 would make the GCI
/// unbounded). A two-grid row gives its GCI (Fs = 3, the assumed order). An oscillating or
/// stagnant triple has no order: its uncertainty is at least half the range of its three
/// values (Stern, Wilson, Coleman and Paterson, J. Fluids Eng. 123, 793, 2001), since the
/// finest pair of an oscillation may agree by accident. The coverage of both rules on
/// synthetic triples of known truth is measured in support.GridUncertainty.
double fine_grid_uncertainty(const GciRow& row);
double middle_grid_uncertainty(const GciRow& row);

/// A bound on the error of a three-level study's coarsest value phi3, where the study refines
/// from the setting in production (the time-step studies: phi3 at the production step):
/// |phi3 - phi1| + fine_grid_uncertainty(row), the change to the finest level plus that
/// level's own uncertainty (the triangle inequality). In the asymptotic range it exceeds the
/// Richardson estimate |phi3 - phi_ext| by at least a quarter of the finest level's
/// extrapolated error (Fs 1.25); outside it, the extrapolation is not trusted and the margin grows (Fs 3, or half
/// the range of a triple that does not converge monotonically). Its coverage of the true error
/// on synthetic series of known truth: support.CoarseLevelError.
struct CoarseLevelError {
  enum class Method { asymptotic, outside_asymptotic_range, no_order };
  double error = 0.0;
  Method method = Method::no_order;
};
CoarseLevelError coarse_level_error(const GciRow& row);
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
/// The rows of a three-grid GCI table judged anew from their grids and values (h1..h3,
/// phi1..phi3) at `design_order`, whatever judge wrote it; a row its study did not claim
/// (pass nan) stays unclaimed. Throws std::runtime_error on a malformed table or a two-grid
/// row.
std::vector<GciRow> gci_from_csv(const std::string& text, double design_order);

/// The order a quantity of interest can reach by theory, and the short name of the reason
/// (the grid studies' table, verification/grid-studies/theoretical_orders.csv; its reasons are
/// explained in verification/README.md).
struct TheoreticalOrder {
  double order = 0.0;
  std::string reason;
};
using TheoreticalOrders = std::map<std::string, TheoreticalOrder>;
/// A table `quantity,order,reason` (first line that header; lines starting with '#' are
/// comments). Throws std::runtime_error on a malformed table, a repeated quantity, an order
/// outside [0.5, 10] or an empty reason.
TheoreticalOrders theoretical_orders_from_csv(const std::string& text);
TheoreticalOrders read_theoretical_orders(const std::filesystem::path& path);
/// The declared order of `quantity`; throws std::runtime_error naming it if it has none.
const TheoreticalOrder& theoretical_order(const TheoreticalOrders& orders,
                                          const std::string& quantity);
/// gci_from_csv with each row judged at its quantity's theoretical order (throws
/// std::runtime_error for a quantity the table does not declare).
std::vector<GciRow> gci_from_csv(const std::string& text, const TheoreticalOrders& orders);
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
