#pragma once
#include <CLI/CLI.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "analysis/analysis.hpp"
#include "common/progress.hpp"

namespace shaker {

struct RunOptions {
  std::string config_file;
  std::vector<std::string> overrides;
  ProgressSettings progress;  ///< solvers only
};

/// A command-line number that must be finite and within [low, high]: refuses an empty value, a
/// word, nan and inf (CLI::Range lets nan through, and an empty value keeps the default).
CLI::Validator finite_between(double low, double high);

/// A subcommand taking CONFIG and any number of --set key=value.
CLI::App* add_run_subcommand(CLI::App& app, const std::string& name, const std::string& help,
                             RunOptions& options);
/// The same with a solver's --quiet and --progress-interval.
CLI::App* add_solver_subcommand(CLI::App& app, const std::string& name, const std::string& help,
                                RunOptions& options);

/// `config`: CONFIG optional, with --describe [--markdown].
struct ConfigOptions {
  RunOptions run;
  bool describe = false, markdown = false;
};
CLI::App* add_config_subcommand(CLI::App& app, ConfigOptions& options);

int command_md(const RunOptions& options);
int command_continuum(const RunOptions& options);
int command_config(const RunOptions& options);
struct AnalyzeOptions {
  std::vector<std::string> run_files;  ///< one run, or runs of one configuration to pool
  std::string csv_file, json_file, profiles_csv, pooled_file;
  /// --patterns: the pattern quantities of the run's particle or fields file, per frame, as CSV
  std::string patterns_csv;
  double pattern_cell = 2.0;  ///< --pattern-cell: width of the MD pattern grid's cells (sigma)
  analysis::ShockCriteria criteria;
  bool quiet = false;
};
CLI::App* add_analyze_subcommand(CLI::App& app, AnalyzeOptions& options);
int command_analyze(const AnalyzeOptions& options);
/// The pattern quantities (docs/analysis.md, "Patterns") of every frame of `snapshots`: an MD
/// particle file, binned on cells about `cell` wide, or a 3D continuum fields file, on its own
/// cells: a CSV row per frame, and summary lines (means over the frames of each stored phase)
/// for the printed table.
struct PatternTables {
  std::string csv, summary;
};
PatternTables pattern_tables(const std::filesystem::path& snapshots, double cell);
/// The snapshots --patterns reads for a run file: RUN.particles.h5, or RUN.fields.h5 where
/// only that exists.
std::filesystem::path pattern_snapshots_path(const std::filesystem::path& run_file);
int command_describe(bool markdown);  ///< shaker config --describe [--markdown]
struct CompareOptions {
  std::string first, second, csv_file;
};
CLI::App* add_compare_subcommand(CLI::App& app, CompareOptions& options);
int command_compare(const CompareOptions& options);

}  // namespace shaker
