// `shaker`: one program, git-style subcommands. Subcommands only parse and dispatch.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>

#include "app/commands.hpp"
#include "common/errors.hpp"
#include "common/ranks.hpp"
#include "common/signals.hpp"
#include "common/terminal_log.hpp"
#include "common/version.hpp"

using namespace shaker;

namespace {

/// Every subcommand's options, filled by the parser.
struct Subcommands {
  RunOptions md, continuum;
  ConfigOptions config;
  AnalyzeOptions analyze;
  CompareOptions compare;
};

void add_subcommands(CLI::App& app, Subcommands& options) {
  add_solver_subcommand(app, "md", "Run the event-driven MD solver on a case file", options.md);
  add_solver_subcommand(app, "continuum", "Run the continuum solver on a case file",
                        options.continuum);
  add_config_subcommand(app, options.config);
  add_analyze_subcommand(app, options.analyze);
  add_compare_subcommand(app, options.compare);
}

int dispatch(const CLI::App& app, const Subcommands& options) {
  if (app.got_subcommand("md")) return command_md(options.md);
  if (app.got_subcommand("continuum")) return command_continuum(options.continuum);
  if (app.got_subcommand("config"))
    return options.config.describe ? command_describe(options.config.markdown)
                                   : command_config(options.config.run);
  if (app.got_subcommand("analyze")) return command_analyze(options.analyze);
  if (app.got_subcommand("compare")) return command_compare(options.compare);
  return 2;
}

/// Runs the chosen subcommand and turns what ends it into the exit code of the README.
int exit_code_of(const CLI::App& app, const Subcommands& options) {
  try {
    const int code = dispatch(app, options);
    // What a command printed (a table, a summary) is part of its result: lost output (a full
    // disk, a closed pipe) is a failure, not a success.
    if (code == 0 && (std::fflush(stdout) != 0 || std::ferror(stdout)))
      throw std::runtime_error(fmt::format("cannot write to standard output ({})", std::strerror(errno)));
    return code;
  } catch (const StopRequested& stop) {
    if (*stop.what() != '\0') terminal_log::say(stderr, "{}\n", stop.what());
    return stop.exit_code();
  } catch (const CollapseError& error) {
    terminal_log::say(stderr, "shaker: stopped: {}\n", error.what());
    Ranks::abort_others(collapse_exit_code);
    return collapse_exit_code;
  } catch (const InputError& error) {
    // Every rank reads the same input and fails alike, so none is left waiting.
    terminal_log::say(stderr, "shaker: error: {}\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    terminal_log::say(stderr, "shaker: failed: {}\n", error.what());
    Ranks::abort_others(1);
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // SIGTERM/SIGINT/SIGHUP: remove partial files, exit 128 + signal, with a message; inside a
  // solver's run loop SIGTERM and SIGINT first write a checkpoint (StopRequested). First of
  // all, so that a launcher's signal never meets the default action (a silent end).
  install_signal_cleanup();
  CLI::App app{"granular-shaker: event-driven MD and continuum solvers for vertically "
               "oscillated granular layers (Bougie et al., PRE 66, 051301, 2002)"};
  app.set_version_flag("--version",
                       fmt::format("shaker {} ({})", program_version(), git_commit()));
  app.require_subcommand(1);
  Subcommands options;
  add_subcommands(app, options);
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
  return exit_code_of(app, options);
}
