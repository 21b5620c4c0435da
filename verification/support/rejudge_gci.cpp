// Rewrites stored GCI tables (*.gci.csv) with the current judge and schema: each row is judged
// anew from its grids and values (conv::gci_from_csv), so that a report never shows verdicts
// of two judges side by side. The nightly regenerates its tables; this is for tables kept in
// the repository (reports/convergence-tables) when the judge changes.
//
// usage: rejudge_gci [--design-order P | --orders TABLE] FILE...
//   P: one order for every row (2 unless given); TABLE: each row at its quantity's theoretical
//   order (verification/grid-studies/theoretical_orders.csv; a quantity it does not declare is
//   an error). The time-step studies' own tables (real-time-*.gci.csv without "-grid") are
//   judged at their integrator's temporal order: give them --design-order.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/error_table.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Judge stored GCI tables anew and rewrite them in the current schema"};
  double design_order = 2.0;
  std::string orders_file;
  std::vector<std::string> files;
  auto* single = app.add_option("--design-order", design_order, "the scheme's order for these tables")
                     ->check(CLI::Range(0.5, 10.0));
  app.add_option("--orders", orders_file,
                 "table quantity,order,reason: each row judged at its quantity's order")
      ->check(CLI::ExistingFile)
      ->excludes(single);
  app.add_option("files", files, "GCI tables (*.gci.csv), rewritten in place")
      ->required()
      ->check(CLI::ExistingFile);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  namespace conv = shaker::convergence;
  conv::TheoreticalOrders orders;
  try {
    if (!orders_file.empty()) orders = conv::read_theoretical_orders(orders_file);
  } catch (const std::exception& e) {
    fmt::print(stderr, "rejudge_gci: {}\n", e.what());
    return 2;
  }
  for (const auto& file : files) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    try {
      const auto rows = orders_file.empty() ? conv::gci_from_csv(text.str(), design_order)
                                            : conv::gci_from_csv(text.str(), orders);
      conv::write_gci_csv(file, rows);
      int checked = 0, passed = 0;
      for (const auto& row : rows) {
        checked += row.checked();
        passed += row.checked() && row.pass();
      }
      fmt::print("{}: {} rows, {} checked, {} in the asymptotic range\n", file, rows.size(),
                 checked, passed);
    } catch (const std::exception& e) {
      fmt::print(stderr, "rejudge_gci: {}: {}\n", file, e.what());
      return 2;
    }
  }
  return 0;
}
