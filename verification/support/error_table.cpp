#include "support/error_table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "common/atomic_output.hpp"
#include "common/hdf5_file.hpp"

namespace shaker::convergence {

namespace {
constexpr const char* errors_header = "study,field,norm,level,h,error";

std::string checked_name(const std::string& name) {
  if (name.empty() || name.find_first_of(",\"\n\r") != std::string::npos)
    throw std::invalid_argument("CSV name must be non-empty without commas, quotes or line breaks: '" +
                                name + "'");
  return name;
}

std::string number(double x) { return fmt::format("{:.17g}", x); }

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

double parse_number(const std::string& text, std::size_t line_number) {
  try {
    std::size_t used = 0;
    const double x = std::stod(text, &used);
    if (used != text.size()) throw std::invalid_argument(text);
    return x;
  } catch (const std::exception&) {
    // Also reached for trailing characters; "nan" and "inf" (as fmt writes them) are accepted.
    throw std::runtime_error(fmt::format("error table line {}: '{}' is not a number",
                                         line_number, text));
  }
}

bool within(double measured, double expected, double tolerance) {
  return std::isfinite(measured) && std::abs(measured - expected) <= tolerance;
}
}  // namespace

void ErrorTable::add(ErrorRow row) {
  checked_name(row.study);
  checked_name(row.field);
  checked_name(row.norm);
  rows_.push_back(std::move(row));
}

void ErrorTable::add_norms(const std::string& study, const std::string& field, int level,
                           double h, const ErrorNorms& norms) {
  add({study, field, "L1", level, h, norms.l1});
  add({study, field, "L2", level, h, norms.l2});
  add({study, field, "Linf", level, h, norms.linf});
}

std::vector<ErrorTable::Key> ErrorTable::series_keys() const {
  std::vector<Key> keys;
  for (const auto& row : rows_) {
    const bool seen = std::any_of(keys.begin(), keys.end(), [&](const Key& k) {
      return k.study == row.study && k.field == row.field && k.norm == row.norm;
    });
    if (!seen) keys.push_back({row.study, row.field, row.norm});
  }
  return keys;
}

std::vector<ErrorRow> ErrorTable::series(const Key& key) const {
  std::vector<ErrorRow> out;
  for (const auto& row : rows_)
    if (row.study == key.study && row.field == key.field && row.norm == key.norm) out.push_back(row);
  std::sort(out.begin(), out.end(), [](const ErrorRow& a, const ErrorRow& b) { return a.h > b.h; });
  return out;
}

std::string ErrorTable::to_csv() const {
  std::string text = std::string(errors_header) + "\n";
  for (const auto& row : rows_)
    text += fmt::format("{},{},{},{},{},{}\n", row.study, row.field, row.norm, row.level,
                        number(row.h), number(row.error));
  return text;
}

ErrorTable ErrorTable::from_csv(const std::string& text) {
  std::stringstream stream(text);
  std::string line;
  if (!std::getline(stream, line) || line != errors_header)
    throw std::runtime_error(std::string("error table: first line must be '") + errors_header +
                             "'");
  ErrorTable table;
  std::size_t line_number = 1;
  while (std::getline(stream, line)) {
    ++line_number;
    if (line.empty()) continue;
    const auto cells = split(line);
    if (cells.size() != 6)
      throw std::runtime_error(
          fmt::format("error table line {}: expected 6 columns, found {}", line_number, cells.size()));
    ErrorRow row{cells[0], cells[1], cells[2], 0, parse_number(cells[4], line_number),
                 parse_number(cells[5], line_number)};
    row.level = static_cast<int>(parse_number(cells[3], line_number));
    table.add(std::move(row));
  }
  return table;
}

void ErrorTable::write_csv(const std::filesystem::path& path) const {
  write_text_atomically(path, to_csv());
}

ErrorTable ErrorTable::read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open error table " + path.string());
  std::stringstream buffer;
  buffer << in.rdbuf();
  return from_csv(buffer.str());
}

bool OrderCheck::pass() const {
  // The next pair is missing (NaN) only in a two-level study; otherwise NaN fails.
  const bool next_ok = std::isnan(pair_order_next) && fit_points < 3
                           ? true
                           : within(pair_order_next, design_order, tolerance);
  return within(fitted_order, design_order, tolerance) &&
         within(pair_order_finest, design_order, tolerance) && next_ok;
}

std::vector<OrderCheck> check_orders(const ErrorTable& table, double design_order,
                                     double tolerance, std::size_t fit_points) {
  std::vector<OrderCheck> checks;
  for (const auto& key : table.series_keys()) {
    const auto rows = table.series(key);  // coarse to fine
    if (rows.size() < 2)
      throw std::invalid_argument("check_orders: series " + key.study + "/" + key.field + "/" +
                                  key.norm + " has fewer than two levels");
    std::vector<double> h, e;
    for (const auto& row : rows) {
      h.push_back(row.h);
      e.push_back(row.error);
    }
    OrderCheck check{key.study, key.field, key.norm};
    check.design_order = design_order;
    check.tolerance = tolerance;
    const std::size_t m = rows.size();
    // A zero or negative error makes the order undefined: recorded as NaN, which fails.
    const auto pair = [&](std::size_t coarse, std::size_t fine) {
      if (!(e[coarse] > 0.0 && e[fine] > 0.0)) return std::numeric_limits<double>::quiet_NaN();
      return observed_order(e[coarse], e[fine], h[coarse] / h[fine]);
    };
    check.pair_order_finest = pair(m - 2, m - 1);
    check.pair_order_next = m >= 3 ? pair(m - 3, m - 2) : std::numeric_limits<double>::quiet_NaN();
    try {
      const OrderFit fit = fit_order(h, e, fit_points);
      check.fit_points = fit.points;
      check.fitted_order = fit.order;
      check.order_std_error = fit.order_std_error;
    } catch (const std::invalid_argument&) {
      check.fit_points = std::min(fit_points, m);
      check.fitted_order = check.order_std_error = std::numeric_limits<double>::quiet_NaN();
    }
    checks.push_back(check);
  }
  return checks;
}

std::string orders_to_csv(std::span<const OrderCheck> checks) {
  std::string text =
      "study,field,norm,fit_points,fitted_order,order_std_error,pair_order_finest,"
      "pair_order_next,design_order,tolerance,pass\n";
  for (const auto& c : checks)
    text += fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", checked_name(c.study),
                        checked_name(c.field), checked_name(c.norm), c.fit_points,
                        number(c.fitted_order), number(c.order_std_error),
                        number(c.pair_order_finest), number(c.pair_order_next),
                        number(c.design_order), number(c.tolerance), c.pass() ? 1 : 0);
  return text;
}

void write_orders_csv(const std::filesystem::path& path, std::span<const OrderCheck> checks) {
  write_text_atomically(path, orders_to_csv(checks));
}

double GciRow::observed_order() const {
  const bool diverging = result.kind == ConvergenceKind::monotonic &&
                         std::abs(phi3 - phi2) < std::abs(phi2 - phi1);
  return diverging ? -result.order : result.order;
}

bool GciRow::pass() const {
  return result.kind == ConvergenceKind::monotonic &&
         within(observed_order(), design_order, order_tolerance);
}

namespace {
/// The uncertainty of one grid's value given the change to its neighbour over refinement
/// ratio r (fine_grid_uncertainty's rule).
double grid_uncertainty(const GciRow& row, double change, double r) {
  if (row.result.kind == ConvergenceKind::two_grids) return std::abs(row.phi1) * row.result.gci21;
  if (row.result.kind != ConvergenceKind::monotonic) {
    const auto [low, high] = std::minmax({row.phi1, row.phi2, row.phi3});
    return std::max(std::abs(change), 0.5 * (high - low));
  }
  // Equal changes (an order of 0) leave the order equation without a root: the least order.
  const double observed = row.observed_order();
  const double order =
      std::isfinite(observed)
          ? std::clamp(observed, least_order_outside_asymptotic_range, row.design_order)
          : least_order_outside_asymptotic_range;
  const double safety =
      row.pass() ? safety_factor_three_grids : safety_factor_outside_asymptotic_range;
  return safety * std::abs(change) / (std::pow(r, order) - 1.0);
}
}  // namespace

double fine_grid_uncertainty(const GciRow& row) {
  return grid_uncertainty(row, row.phi1 - row.phi2, row.h2 / row.h1);
}

double middle_grid_uncertainty(const GciRow& row) {
  // Without an order, phi2 is judged against phi1, the nearer the truth.
  return row.result.kind == ConvergenceKind::monotonic
             ? grid_uncertainty(row, row.phi2 - row.phi3, row.h3 / row.h2)
             : grid_uncertainty(row, row.phi2 - row.phi1, row.h2 / row.h1);
}

CoarseLevelError coarse_level_error(const GciRow& row) {
  const CoarseLevelError::Method method =
      row.result.kind != ConvergenceKind::monotonic ? CoarseLevelError::Method::no_order
      : row.pass() ? CoarseLevelError::Method::asymptotic
                   : CoarseLevelError::Method::outside_asymptotic_range;
  return {std::abs(row.phi3 - row.phi1) + fine_grid_uncertainty(row), method};
}

std::string to_string(CoarseLevelError::Method method) {
  switch (method) {
    case CoarseLevelError::Method::asymptotic:
      return "change to the finest level + its GCI with Fs 1.25";
    case CoarseLevelError::Method::outside_asymptotic_range:
      return "change to the finest level + its GCI with Fs 3 (not asymptotic)";
    case CoarseLevelError::Method::no_order:
      return "change to the finest level + at least half the range (not monotonic)";
  }
  return "unknown";
}

GciRow make_gci_row(const std::string& study, const std::string& quantity, double h1, double h2,
                    double h3, double phi1, double phi2, double phi3, double design_order,
                    double order_tolerance) {
  return GciRow{study,
                quantity,
                h1,
                h2,
                h3,
                phi1,
                phi2,
                phi3,
                three_grid_gci(h1, h2, h3, phi1, phi2, phi3),
                design_order,
                order_tolerance};
}

GciRow make_two_grid_gci_row(const std::string& study, const std::string& quantity, double h1,
                             double h2, double phi1, double phi2, double assumed_order) {
  const TwoGridGci two = two_grid_gci(h1, h2, phi1, phi2, assumed_order);
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  GciResult result;
  result.r21 = two.r21;
  result.r32 = nan;
  result.order = two.order;
  result.phi_extrapolated = two.phi_extrapolated;
  result.relative_difference21 = two.relative_difference21;
  result.relative_difference32 = nan;
  result.extrapolated_error21 = std::abs((two.phi_extrapolated - phi1) / two.phi_extrapolated);
  result.gci21 = two.gci21;
  result.gci32 = result.asymptotic_ratio = nan;
  result.kind = ConvergenceKind::two_grids;
  return GciRow{study, quantity, h1, h2, nan, phi1, phi2, nan, result, assumed_order, nan};
}

std::string gci_to_csv(std::span<const GciRow> rows) {
  std::string text =
      "study,quantity,h1,h2,h3,phi1,phi2,phi3,order,phi_extrapolated,relative_difference21,"
      "extrapolated_error21,gci21,gci32,convergence,design_order,order_tolerance,uncertainty1,"
      "pass\n";
  for (const auto& row : rows) {
    const GciResult& r = row.result;
    text += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                        checked_name(row.study), checked_name(row.quantity), number(row.h1),
                        number(row.h2), number(row.h3), number(row.phi1), number(row.phi2),
                        number(row.phi3), number(row.observed_order()),
                        number(r.phi_extrapolated),
                        number(r.relative_difference21), number(r.extrapolated_error21),
                        number(r.gci21), number(r.gci32), to_string(r.kind),
                        number(row.design_order), number(row.order_tolerance),
                        number(fine_grid_uncertainty(row)),
                        row.checked() ? (row.pass() ? "1" : "0") : "nan");
  }
  return text;
}

namespace {
std::vector<GciRow> judged_gci_rows(const std::string& text,
                                    const std::function<double(const std::string&)>& order_of) {
  std::stringstream stream(text);
  std::string line;
  if (!std::getline(stream, line)) throw std::runtime_error("GCI table: empty");
  const auto header = split(line);
  const auto column = [&](const std::string& name) {
    const auto at = std::find(header.begin(), header.end(), name);
    if (at == header.end()) throw std::runtime_error("GCI table: no column '" + name + "'");
    return static_cast<std::size_t>(at - header.begin());
  };
  const std::size_t study = column("study"), quantity = column("quantity"),
                    convergence = column("convergence"), pass = column("pass");
  std::array<std::size_t, 6> grid{column("h1"),   column("h2"),   column("h3"),
                                  column("phi1"), column("phi2"), column("phi3")};
  std::vector<GciRow> rows;
  for (std::size_t line_number = 2; std::getline(stream, line); ++line_number) {
    if (line.empty()) continue;
    const auto cells = split(line);
    if (cells.size() != header.size())
      throw std::runtime_error(fmt::format("GCI table line {}: expected {} columns, found {}",
                                           line_number, header.size(), cells.size()));
    if (cells[convergence] == "two-grids")
      throw std::runtime_error(fmt::format(
          "GCI table line {}: a two-grid row has no observed order to judge", line_number));
    std::array<double, 6> x{};
    for (std::size_t k = 0; k < grid.size(); ++k) x[k] = parse_number(cells[grid[k]], line_number);
    rows.push_back(make_gci_row(cells[study], cells[quantity], x[0], x[1], x[2], x[3], x[4],
                                x[5], order_of(cells[quantity])));
    rows.back().asymptotic_range_claimed = cells[pass] != "nan";
  }
  return rows;
}
}  // namespace

std::vector<GciRow> gci_from_csv(const std::string& text, double design_order) {
  return judged_gci_rows(text, [&](const std::string&) { return design_order; });
}

std::vector<GciRow> gci_from_csv(const std::string& text, const TheoreticalOrders& orders) {
  return judged_gci_rows(
      text, [&](const std::string& quantity) { return theoretical_order(orders, quantity).order; });
}

TheoreticalOrders theoretical_orders_from_csv(const std::string& text) {
  std::stringstream stream(text);
  std::string line;
  std::size_t line_number = 0;
  const auto next_line = [&] {
    while (std::getline(stream, line)) {
      ++line_number;
      if (!line.empty() && line.front() != '#') return true;
    }
    return false;
  };
  if (!next_line() || line != "quantity,order,reason")
    throw std::runtime_error("theoretical orders: the first line must be 'quantity,order,reason'");
  TheoreticalOrders orders;
  while (next_line()) {
    const auto cells = split(line);
    if (cells.size() != 3 || cells[0].empty() || cells[2].empty())
      throw std::runtime_error(fmt::format(
          "theoretical orders line {}: expected a quantity, an order and a reason", line_number));
    const double order = parse_number(cells[1], line_number);
    if (!(order >= 0.5 && order <= 10.0))
      throw std::runtime_error(fmt::format(
          "theoretical orders line {}: order {} outside [0.5, 10]", line_number, cells[1]));
    if (!orders.emplace(cells[0], TheoreticalOrder{order, cells[2]}).second)
      throw std::runtime_error(fmt::format("theoretical orders line {}: '{}' declared twice",
                                           line_number, cells[0]));
  }
  return orders;
}

TheoreticalOrders read_theoretical_orders(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("theoretical orders: cannot read " + path.string());
  std::stringstream text;
  text << in.rdbuf();
  try {
    return theoretical_orders_from_csv(text.str());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

const TheoreticalOrder& theoretical_order(const TheoreticalOrders& orders,
                                          const std::string& quantity) {
  const auto found = orders.find(quantity);
  if (found == orders.end())
    throw std::runtime_error("no theoretical order declared for '" + quantity +
                             "' (verification/grid-studies/theoretical_orders.csv)");
  return found->second;
}

std::string bounds_to_csv(std::span<const BoundCheck> rows) {
  std::string text = "study,quantity,value,value_basis,bound,bound_basis,pass\n";
  for (const auto& row : rows)
    text += fmt::format("{},{},{},{},{},{},{}\n", checked_name(row.study),
                        checked_name(row.quantity), number(row.value),
                        checked_name(row.value_basis), number(row.bound),
                        checked_name(row.bound_basis),
                        row.checked() ? (row.pass() ? "1" : "0") : "nan");
  return text;
}

void write_gci_csv(const std::filesystem::path& path, std::span<const GciRow> rows) {
  write_text_atomically(path, gci_to_csv(rows));
}

std::vector<std::filesystem::path> write_study_files(
    const std::filesystem::path& directory, const std::string& name,
    const std::vector<std::pair<std::string, std::string>>& files) {
  if (checked_name(name).find('/') != std::string::npos)
    throw std::invalid_argument("study file name may not contain '/': " + name);
  std::vector<std::filesystem::path> targets{directory};
  if (const char* collected = std::getenv(study_directory_variable);
      collected != nullptr && *collected != '\0')
    targets.emplace_back(collected);
  std::vector<std::filesystem::path> written;
  for (const auto& target : targets) {
    std::filesystem::create_directories(target);
    for (const auto& [suffix, text] : files) {
      write_text_atomically(target / (name + suffix), text);
      written.push_back(target / (name + suffix));
    }
  }
  return written;
}

std::vector<std::filesystem::path> write_bounds(const std::filesystem::path& directory,
                                                const std::string& name,
                                                std::span<const BoundCheck> rows) {
  return write_study_files(directory, name, {{".bounds.csv", bounds_to_csv(rows)}});
}

std::vector<std::filesystem::path> write_study(const std::filesystem::path& directory,
                                               const std::string& name, const ErrorTable& table,
                                               std::span<const OrderCheck> checks,
                                               std::span<const GciRow> gci) {
  std::vector<std::pair<std::string, std::string>> files{{".errors.csv", table.to_csv()},
                                                         {".orders.csv", orders_to_csv(checks)}};
  if (!gci.empty()) files.emplace_back(".gci.csv", gci_to_csv(gci));
  return write_study_files(directory, name, files);
}

}  // namespace shaker::convergence
