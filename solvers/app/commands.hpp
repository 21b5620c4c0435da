#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace shaker {

struct RunOptions {
  std::string config_file;
  std::vector<std::string> overrides;
};

/// A subcommand taking CONFIG and any number of --set key=value.
CLI::App* add_run_subcommand(CLI::App& app, const std::string& name, const std::string& help,
                             RunOptions& options);

int command_md(const RunOptions& options);
int command_continuum(const RunOptions& options);
int command_config(const RunOptions& options);
int command_describe(bool markdown);  ///< shaker config --describe [--markdown]
int command_analyze(const std::string& run_file, const std::string& csv_file,
                    const std::string& profiles_csv = "");
int command_compare(const std::string& first, const std::string& second,
                    const std::string& csv_file);

}  // namespace shaker
