// `shaker`: one program, git-style subcommands. Subcommands only parse and dispatch.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>

#include "app/commands.hpp"
#include "common/checkpoints.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/ranks.hpp"
#include "common/terminal_log.hpp"
#include "common/version.hpp"

int main(int argc, char** argv) {
  using namespace shaker;
  // SIGTERM/SIGINT/SIGHUP: remove partial files, exit 128 + signal, with a message; inside a
  // solver's run loop SIGTERM and SIGINT first write a checkpoint (StopRequested). First of
  // all, so that a launcher's signal never meets the default action (a silent end).
  install_signal_cleanup();
  CLI::App app{"granular-shaker: event-driven MD and continuum solvers for vertically "
               "oscillated granular layers (Bougie et al., PRE 66, 051301, 2002)"};
  app.set_version_flag("--version",
                       fmt::format("shaker {} ({})", program_version(), git_commit()));
  app.require_subcommand(1);

  RunOptions run_md, run_continuum, show_config;
  add_solver_subcommand(app, "md", "Run the event-driven MD solver on a case file", run_md);
  add_solver_subcommand(app, "continuum", "Run the continuum solver on a case file", run_continuum);
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

  AnalyzeOptions analysis;
  auto* analyze = app.add_subcommand(
      "analyze", "The analysis of docs/analysis.md: per stored phase (layer, centre of mass, "
                 "shock location and width, d/xi, maximum Ma, layer temperature) and per run "
                 "(shock formation, exit, lifetime, speed; crossings per cycle), with jackknife "
                 "errors over the samples of MD runs; several runs of one configuration are pooled");
  analyze->add_option("RUN", analysis.run_files, "HDF5 run file(s)")->required();
  analyze->add_option("--csv", analysis.csv_file, "also write the per-phase table as CSV");
  analyze->add_option("--json", analysis.json_file,
                      "also write every quantity with its unit, error and jackknife replicates");
  analyze->add_option("--profiles-csv", analysis.profiles_csv,
                      "also write every profile with its Mach and Knudsen numbers (phase,z,n,nu,uz,T,mach,kn_n,kn_T)");
  analyze->add_option("--pooled", analysis.pooled_file,
                      "also write the pooled run (profiles and samples of all RUNs) to this file");
  auto* patterns = analyze->add_option("--patterns", analysis.patterns_csv,
                      "also write the pattern quantities of the run's particle file (RUN.particles.h5), "
                      "one row per frame, as CSV (one RUN only)");
  analyze->add_option("--pattern-cell", analysis.pattern_cell,
                      "with --patterns: width of the cells the particles are binned on (sigma)")
      ->check(finite_between(0.01, 1e6))->capture_default_str()->needs(patterns);
  analyze->add_flag("--quiet", analysis.quiet, "print nothing (with --json or --csv)");
  analyze->add_option("--relative-drop", analysis.criteria.relative_drop,
                      "shock rule: minimum (T_max - T_min) / T_max")
      ->check(finite_between(0.0, 1.0))->capture_default_str();
  analyze->add_option("--standard-errors", analysis.criteria.standard_errors,
                      "shock rule: minimum drop in combined standard errors")
      ->check(finite_between(0.0, 100.0))->capture_default_str();
  analyze->add_option("--deceleration", analysis.criteria.deceleration,
                      "shock rule: minimum fraction of the incoming velocity lost")
      ->check(finite_between(0.0, 1.0))->capture_default_str();

  std::string first, second, compare_csv;
  auto* compare = app.add_subcommand(
      "compare", "Agreement metrics between two runs (docs/analysis.md): fractional RMS of shock "
                 "location and centre of mass, profile norms of nu and T");
  compare->add_option("A", first, "HDF5 run file")->required();
  compare->add_option("B", second, "HDF5 run file (the reference)")->required();
  compare->add_option("--csv", compare_csv, "also write the metrics as CSV (metric,value,error,units,replicates)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  struct FinalizeRanks {
    ~FinalizeRanks() { Ranks::finalize(); }
  } finalize_ranks;
  const auto run_command = [&] {
    if (app.got_subcommand("md")) return command_md(run_md);
    if (app.got_subcommand("continuum")) return command_continuum(run_continuum);
    if (app.got_subcommand("config"))
      return describe ? command_describe(markdown) : command_config(show_config);
    if (app.got_subcommand("analyze")) return command_analyze(analysis);
    if (app.got_subcommand("compare")) return command_compare(first, second, compare_csv);
    return 2;
  };
  try {
    const int code = run_command();
    // What a command printed (a table, a summary) is part of its result: lost output (a full
    // disk, a closed pipe) is a failure, not a success.
    if (code == 0 && (std::fflush(stdout) != 0 || std::ferror(stdout)))
      throw std::runtime_error(fmt::format("cannot write to standard output ({})", std::strerror(errno)));
    return code;
  } catch (const StopRequested& stop) {
    if (*stop.what() != '\0') terminal_log::say(stderr, "{}\n", stop.what());
    return stop.exit_code();
  } catch (const InputError& error) {
    // Every rank reads the same input and fails alike, so none is left waiting.
    terminal_log::say(stderr, "shaker: error: {}\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    terminal_log::say(stderr, "shaker: failed: {}\n", error.what());
    Ranks::abort_others(1);
    return 1;
  }
  return 2;
}
