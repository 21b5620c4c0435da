// `shaker`: one program, git-style subcommands. Subcommands only parse and dispatch.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cstdio>
#include <exception>

#include "app/commands.hpp"
#include "common/errors.hpp"
#include "common/version.hpp"

int main(int argc, char** argv) {
  using namespace shaker;
  CLI::App app{"granular-shaker: event-driven MD and continuum solvers for vertically "
               "oscillated granular layers (Bougie et al., PRE 66, 051301, 2002)"};
  app.set_version_flag("--version",
                       fmt::format("shaker {} ({})", program_version(), git_commit()));
  app.require_subcommand(1);

  RunOptions run_md, run_continuum, show_config;
  add_run_subcommand(app, "md", "Run the event-driven MD solver on a case file", run_md);
  add_run_subcommand(app, "continuum", "Run the continuum solver on a case file", run_continuum);
  auto* config = add_run_subcommand(
      app, "config", "Print the effective configuration (defaults, file, --set overrides)",
      show_config);
  config->get_option("CONFIG")->required(false);
  bool describe = false, markdown = false;
  auto* describe_flag = config->add_flag(
      "--describe", describe,
      "instead: every key with its type, default, allowed values, units and meaning");
  config->add_flag("--markdown", markdown, "with --describe: as Markdown (docs/configuration.md)")
      ->needs(describe_flag);

  std::string run_file, analysis_csv, profiles_csv;
  auto* analyze = app.add_subcommand(
      "analyze", "Print the analysis of a run per stored phase: layer, centre of mass, "
                 "shock location and width, d/xi, maximum Ma");
  analyze->add_option("RUN", run_file, "HDF5 run file")->required();
  analyze->add_option("--csv", analysis_csv, "also write the table as CSV to this file");
  analyze->add_option("--profiles-csv", profiles_csv,
                      "also write every profile with its Mach number (phase,z,n,nu,uz,T,mach)");

  std::string first, second, compare_csv;
  auto* compare = app.add_subcommand(
      "compare", "Agreement metrics between two runs (docs/analysis.md): fractional RMS of shock "
                 "location and centre of mass, profile norms of nu and T");
  compare->add_option("A", first, "HDF5 run file")->required();
  compare->add_option("B", second, "HDF5 run file (the reference)")->required();
  compare->add_option("--csv", compare_csv, "also write the metrics as metric,value CSV");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  try {
    if (app.got_subcommand("md")) return command_md(run_md);
    if (app.got_subcommand("continuum")) return command_continuum(run_continuum);
    if (app.got_subcommand("config"))
      return describe ? command_describe(markdown) : command_config(show_config);
    if (app.got_subcommand("analyze")) return command_analyze(run_file, analysis_csv, profiles_csv);
    if (app.got_subcommand("compare")) return command_compare(first, second, compare_csv);
  } catch (const InputError& error) {
    fmt::print(stderr, "shaker: error: {}\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    fmt::print(stderr, "shaker: failed: {}\n", error.what());
    return 1;
  }
  return 2;
}
