#include "app/commands.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <optional>
#include <string>

#include "analysis/analysis.hpp"
#include "analysis/run_analysis.hpp"
#include "common/atomic_output.hpp"
#include "common/config.hpp"
#include "common/describe.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/output_paths.hpp"
#include "common/ranks.hpp"
#include "common/run_file.hpp"
#include "continuum/run_continuum.hpp"
#include "md/run_md.hpp"

namespace shaker {
namespace {

config::Config load(const RunOptions& options) {
  return config::Config::load(options.config_file, options.overrides);
}

/// The configuration of a solver's run; under a launcher every rank must have the same (a
/// rank that fails to load it takes part with its error, so none is left waiting).
config::Config load_on_every_rank(const RunOptions& options) {
  std::optional<config::Config> config;
  std::string failure;
  try {
    config = load(options);
  } catch (const InputError& error) {
    failure = error.what();
  }
  if (launched_by_mpi()) Ranks::world().require_same_configuration(config ? config->to_toml() : "error: " + failure);
  if (!config) throw InputError(failure);
  return *config;
}

}  // namespace

CLI::Validator finite_between(double low, double high) {
  const std::string allowed = fmt::format("allowed: a number with {} <= value <= {}", low, high);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0.0;
        std::size_t used = 0;
        try {
          value = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != text.size() || !std::isfinite(value) || value < low || value > high)
          return fmt::format("value '{}' is not a finite number in range; {}", text, allowed);
        return {};
      },
      fmt::format("NUMBER in [{}, {}]", low, high));
}

CLI::App* add_run_subcommand(CLI::App& app, const std::string& name, const std::string& help,
                             RunOptions& options) {
  auto* sub = app.add_subcommand(name, help);
  sub->add_option("CONFIG", options.config_file, "case file (TOML)")->required();
  sub->add_option("--set", options.overrides,
                  "override a configuration key, e.g. --set material.e=0.8 (repeatable)")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  return sub;
}

CLI::App* add_solver_subcommand(CLI::App& app, const std::string& name, const std::string& help,
                                RunOptions& options) {
  auto* sub = add_run_subcommand(app, name, help, options);
  sub->add_flag("--quiet", options.progress.quiet, "no progress on stderr");
  sub->add_option("--progress-interval", options.progress.interval_seconds,
                  fmt::format("seconds between progress lines when stderr is not a terminal "
                              "(a terminal gets one live line); allowed: {}",
                              progress_interval_range.describe()))
      ->check(finite_between(progress_interval_range.lo, progress_interval_range.hi))
      ->capture_default_str();
  return sub;
}

CLI::App* add_config_subcommand(CLI::App& app, ConfigOptions& options) {
  auto* config = add_run_subcommand(
      app, "config", "Print the effective configuration (defaults, file, --set overrides)",
      options.run);
  config->get_option("CONFIG")->required(false);
  auto* describe = config->add_flag(
      "--describe", options.describe,
      "instead: every key with its type, default, allowed values, units and meaning");
  config->add_flag("--markdown", options.markdown,
                   "with --describe: as Markdown (docs/configuration.md)")
      ->needs(describe);
  return config;
}

CLI::App* add_analyze_subcommand(CLI::App& app, AnalyzeOptions& options) {
  auto* analyze = app.add_subcommand(
      "analyze", "The analysis of docs/analysis.md: per stored phase (layer, centre of mass, "
                 "shock location and width, d/xi, maximum Ma, layer temperature) and per run "
                 "(shock formation, exit, lifetime, speed; crossings per cycle), with jackknife "
                 "errors over the samples of MD runs; several runs of one configuration are pooled");
  analyze->add_option("RUN", options.run_files, "HDF5 run file(s)")->required();
  analyze->add_option("--csv", options.csv_file, "also write the per-phase table as CSV");
  analyze->add_option("--json", options.json_file,
                      "also write every quantity with its unit, error and jackknife replicates");
  analyze->add_option("--profiles-csv", options.profiles_csv,
                      "also write every profile with its Mach and Knudsen numbers (phase,z,n,nu,uz,T,mach,kn_n,kn_T)");
  analyze->add_option("--pooled", options.pooled_file,
                      "also write the pooled run (profiles and samples of all RUNs) to this file");
  auto* patterns = analyze->add_option("--patterns", options.patterns_csv,
                      "also write the pattern quantities of the run's particle file (RUN.particles.h5) "
                      "or, for a 3D continuum run, its fields file (RUN.fields.h5), one row per frame, "
                      "as CSV (one RUN only)");
  analyze->add_option("--pattern-cell", options.pattern_cell,
                      "with --patterns: width of the cells the particles are binned on (sigma; the "
                      "continuum's fields keep their own cells)")
      ->check(finite_between(0.01, 1e6))->capture_default_str()->needs(patterns);
  analyze->add_flag("--quiet", options.quiet, "print nothing (with --csv, --json, --profiles-csv, --pooled or --patterns)");
  analyze->add_option("--relative-drop", options.criteria.relative_drop,
                      "shock rule: minimum (T_max - T_min) / T_max")
      ->check(finite_between(0.0, 1.0))->capture_default_str();
  analyze->add_option("--standard-errors", options.criteria.standard_errors,
                      "shock rule: minimum drop in combined standard errors")
      ->check(finite_between(0.0, 100.0))->capture_default_str();
  analyze->add_option("--deceleration", options.criteria.deceleration,
                      "shock rule: minimum fraction of the incoming velocity lost")
      ->check(finite_between(0.0, 1.0))->capture_default_str();
  return analyze;
}

CLI::App* add_compare_subcommand(CLI::App& app, CompareOptions& options) {
  auto* compare = app.add_subcommand(
      "compare", "Agreement metrics between two runs (docs/analysis.md): fractional RMS of shock "
                 "location and centre of mass, profile norms of nu and T");
  compare->add_option("A", options.first, "HDF5 run file")->required();
  compare->add_option("B", options.second, "HDF5 run file (the reference)")->required();
  compare->add_option("--csv", options.csv_file,
                      "also write the metrics as CSV (metric,value,error,units,replicates)");
  return compare;
}

int command_md(const RunOptions& options) {
  options.progress.validate();
  return md::run(load_on_every_rank(options), {{"configuration file", options.config_file}}, options.progress);
}
int command_continuum(const RunOptions& options) {
  options.progress.validate();
  // Under mpirun a 3D box is decomposed over the ranks; a 1D column, or a box too narrow for
  // the ranks, is refused there with exit 2 before any work (continuum/run_continuum.cpp).
  return continuum::run(load_on_every_rank(options), {{"configuration file", options.config_file}}, options.progress);
}

int command_config(const RunOptions& options) {
  fmt::print("{}", config::annotate_units(load(options).to_toml()));
  return 0;
}

int command_describe(bool markdown) {
  fmt::print("{}", config::describe_schema(markdown));
  return 0;
}

namespace {

/// The scalar metrics of a comparison, in the order of the CSV.
std::vector<std::pair<std::string, double>> comparison_metrics(const analysis::RunComparison& r) {
  double nu_l1 = 0.0, T_l1 = 0.0, nu_max = 0.0, T_max = 0.0;
  const auto phases = static_cast<double>(r.phases.size());
  for (std::size_t k = 0; k < r.phases.size(); ++k) {
    nu_l1 += r.nu_norms[k].l1 / phases;
    T_l1 += r.T_norms[k].l1 / phases;
    nu_max = std::max(nu_max, r.nu_norms[k].linf);
    T_max = std::max(T_max, r.T_norms[k].linf);
  }
  return {{"shock_location_fractional_rms", r.shock_location.fractional_rms},
          {"shock_location_absolute_rms", r.shock_location.absolute_rms},
          {"shock_location_phases", static_cast<double>(r.shock_location.count)},
          {"center_of_mass_fractional_rms", r.center_of_mass.fractional_rms},
          {"center_of_mass_absolute_rms", r.center_of_mass.absolute_rms},
          {"center_of_mass_phases", static_cast<double>(r.center_of_mass.count)},
          {"nu_l1_mean_over_phases", nu_l1},
          {"nu_linf_max_over_phases", nu_max},
          {"T_l1_mean_over_phases", T_l1},
          {"T_linf_max_over_phases", T_max}};
}

/// The units of each metric of comparison_metrics (docs/analysis.md).
std::string metric_units(const std::string& metric) {
  if (metric.find("absolute_rms") != std::string::npos || metric.rfind("T_", 0) == 0)
    return metric.rfind("T_", 0) == 0 ? "g sigma" : "sigma";
  return "1";  // fractional RMS, counts of phases, volume fractions
}

/// Replicate s leaves sample s out of each run that has more than s samples (a paired
/// jackknife: for independent runs its variance is the sum of the two runs' variances).
std::vector<std::vector<std::pair<std::string, double>>> comparison_replicates(const RunRecord& a,
                                                                              const RunRecord& b) {
  const auto samples = [](const RunRecord& r) { return r.samples.empty() ? 0 : r.samples.samples(); };
  const std::size_t m = std::max(samples(a), samples(b));
  std::vector<std::vector<std::pair<std::string, double>>> out;
  if (m < 2) return out;
  for (std::size_t s = 0; s < m; ++s) {
    RunRecord ra = a, rb = b;
    if (s < samples(a) && samples(a) >= 2) ra.profiles = analysis::profiles_without(a, s);
    if (s < samples(b) && samples(b) >= 2) rb.profiles = analysis::profiles_without(b, s);
    out.push_back(comparison_metrics(analysis::compare_runs(ra, rb)));
  }
  return out;
}

/// The CSV outputs given (empty: not asked for), checked against the run files read.
void check_csv_outputs(std::vector<NamedPath> outputs, const std::vector<NamedPath>& inputs) {
  std::erase_if(outputs, [](const NamedPath& p) { return p.path.empty(); });
  check_output_paths(outputs, inputs);
}

/// Profile norms interpolate in the reference's bins: a run with fewer than two bins in a
/// stored phase has nothing to compare, and would report a perfect 0.
void require_comparable_profiles(const RunRecord& run, const std::string& path) {
  for (const auto& p : run.profiles)
    if (p.size() < 2)
      throw InputError(fmt::format("run file '{}': the profile at phase {} has {} bin(s); compare "
                                   "needs at least 2 bins in every phase", path, p.phase, p.size()));
  if (run.profiles.empty())
    throw InputError(fmt::format("run file '{}' stores no profile; compare needs at least one phase "
                                 "with at least 2 bins", path));
}

/// compare matches the runs phase by phase: both must store the same phases.
void require_same_phases(const RunRecord& a, const RunRecord& b, const std::string& first,
                         const std::string& second) {
  if (a.profiles.size() != b.profiles.size())
    throw InputError(fmt::format("run file '{}' stores {} phases, the reference '{}' {}; allowed: "
                                 "runs of the same run.phases_per_cycle", first, a.profiles.size(),
                                 second, b.profiles.size()));
  for (std::size_t k = 0; k < a.profiles.size(); ++k)
    if (std::abs(a.profiles[k].phase - b.profiles[k].phase) > 1e-9)
      throw InputError(fmt::format("run file '{}' stores phase {} where the reference '{}' stores {}; "
                                   "allowed: the same phases in both", first, a.profiles[k].phase,
                                   second, b.profiles[k].phase));
}
}  // namespace

int command_compare(const CompareOptions& options) {
  const auto& [first, second, csv_file] = options;
  check_csv_outputs({{"--csv", csv_file}}, {{"run file A", first}, {"run file B", second}});
  const RunRecord a = read_run_file(first), b = read_run_file(second);
  require_comparable_profiles(a, first);
  require_comparable_profiles(b, second);
  require_same_phases(a, b, first, second);
  const auto r = analysis::compare_runs(a, b);
  const auto metrics = comparison_metrics(r);
  const auto replicates = comparison_replicates(a, b);
  std::vector<double> errors;
  for (std::size_t i = 0; i < metrics.size(); ++i) {
    std::vector<double> values;
    for (const auto& rep : replicates) values.push_back(rep[i].second);
    errors.push_back(analysis::jackknife_error(values));
  }
  fmt::print("# A = {} ({}), B = {} ({}, reference); errors: {}\n", first, a.solver, second,
             b.solver, replicates.empty() ? std::string("none")
                                          : fmt::format("jackknife over {} samples", replicates.size()));
  for (std::size_t i = 0; i < metrics.size(); ++i)
    fmt::print("{:>32} {:.6g} +- {:.2g}\n", metrics[i].first, metrics[i].second, errors[i]);
  fmt::print("{:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "phase", "nu_L1", "nu_L2", "nu_max",
             "T_L1", "T_L2", "T_max");
  for (std::size_t k = 0; k < r.phases.size(); ++k)
    fmt::print("{:7.4f} {:9.4f} {:9.4f} {:9.4f} {:9.4f} {:9.4f} {:9.4f}\n", r.phases[k],
               r.nu_norms[k].l1, r.nu_norms[k].l2, r.nu_norms[k].linf, r.T_norms[k].l1,
               r.T_norms[k].l2, r.T_norms[k].linf);
  if (!csv_file.empty()) {
    std::string csv = "metric,value,error,units,replicates\n";
    for (std::size_t i = 0; i < metrics.size(); ++i) {
      std::vector<std::string> reps;
      for (const auto& rep : replicates) reps.push_back(fmt::format("{}", rep[i].second));
      csv += fmt::format("{},{},{},{},{}\n", metrics[i].first, metrics[i].second, errors[i],
                         metric_units(metrics[i].first), fmt::join(reps, ";"));
    }
    write_text_atomically(csv_file, csv);
  }
  return 0;
}

}  // namespace shaker
