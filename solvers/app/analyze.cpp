// `shaker analyze`: the one analysis of docs/analysis.md, printed as a table and written as
// JSON or CSV. Several run files of one configuration are pooled; an MD run (or pool) that
// keeps its per-cycle sums gets the jackknife standard error of every number over its samples.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <numeric>

#include "analysis/run_analysis.hpp"
#include "app/commands.hpp"
#include "common/atomic_output.hpp"
#include "common/config.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/output_paths.hpp"
#include "common/run_file.hpp"
#include "common/version.hpp"

namespace shaker {
namespace {

/// Central values, leave-one-out replicates and standard errors of every named quantity.
struct Estimates {
  std::vector<analysis::NamedValues> central;
  std::vector<std::vector<analysis::NamedValues>> replicates;  // [sample][quantity]
  std::vector<std::vector<double>> errors;                     // [quantity][entry]
};

void add_errors(Estimates& e) {
  for (std::size_t q = 0; q < e.central.size(); ++q) {
    std::vector<double> errors;
    const auto& c = e.central[q];
    for (std::size_t i = 0; i < c.values.size(); ++i) {
      std::vector<double> values;
      for (const auto& r : e.replicates) values.push_back(r[q].values[i]);
      const double resolution = i < c.resolution.size() ? c.resolution[i] : NAN;
      errors.push_back(analysis::standard_error(c.values[i], values, resolution));
    }
    e.errors.push_back(std::move(errors));
  }
}

/// The per-phase and per-run estimates of a run: one analysis of the full sample and one of
/// each leave-one-out sample.
std::pair<Estimates, Estimates> estimate(const RunRecord& run, const analysis::AnalysisOptions& options) {
  Estimates phases, per_run;
  const auto add = [&](const std::vector<Profile>& profiles, bool central) {
    const auto r = analysis::analyze_profiles(profiles, run.e, options);
    if (central) {
      phases.central = analysis::phase_columns(r);
      per_run.central = analysis::run_values(r);
    } else {
      phases.replicates.push_back(analysis::phase_columns(r));
      per_run.replicates.push_back(analysis::run_values(r));
    }
  };
  add(run.profiles, true);
  const std::size_t samples = run.samples.empty() ? 0 : run.samples.samples();
  if (samples >= 2)
    for (std::size_t s = 0; s < samples; ++s) add(analysis::profiles_without(run, s), false);
  add_errors(phases);
  add_errors(per_run);
  return {std::move(phases), std::move(per_run)};
}

std::string json_number(double x) { return std::isfinite(x) ? fmt::format("{:.17g}", x) : "null"; }

std::string json_list(const std::vector<double>& values) {
  std::vector<std::string> items;
  for (double x : values) items.push_back(json_number(x));
  return fmt::format("[{}]", fmt::join(items, ", "));
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", static_cast<int>(c));
    else out += c;
  }
  return out + "\"";
}

/// "name": {"unit": ..., "value": ..., "error": ..., "replicates": [...]}
std::string json_quantities(const Estimates& e, bool scalar) {
  std::vector<std::string> entries;
  for (std::size_t q = 0; q < e.central.size(); ++q) {
    const auto& c = e.central[q];
    std::vector<std::string> replicates;
    for (const auto& r : e.replicates)
      replicates.push_back(scalar ? json_number(r[q].values[0]) : json_list(r[q].values));
    const std::string resolution = c.resolution.empty() ? "null"
                                   : scalar             ? json_number(c.resolution[0])
                                                        : json_list(c.resolution);
    entries.push_back(fmt::format(
        "    {}: {{\"unit\": {}, \"value\": {}, \"error\": {}, \"resolution\": {}, "
        "\"replicates\": [{}]}}",
        json_string(c.name), json_string(c.unit),
        scalar ? json_number(c.values[0]) : json_list(c.values),
        scalar ? json_number(e.errors[q][0]) : json_list(e.errors[q]), resolution,
        fmt::join(replicates, ", ")));
  }
  return fmt::format("{{\n{}\n  }}", fmt::join(entries, ",\n"));
}

struct Crossings {
  std::string column;
  std::vector<double> per_cycle;
  double mean = NAN, error = NAN;  // between-cycle standard error of the mean
  /// Leave-one-cycle-out means, when the cycles are the run's samples (then replicate i
  /// leaves out the same cycle as the other quantities' replicate i); else empty.
  std::vector<double> replicates;
};

/// Crossings per cycle of every crossing column: mean over the cycles of all runs, and its
/// between-cycle standard error (the jackknife error of the leave-one-cycle-out means, which
/// for a mean is the standard error exactly).
std::vector<Crossings> crossings(const std::vector<RunRecord>& runs, std::size_t samples) {
  std::vector<Crossings> out;
  for (const auto& name : runs.front().series.names) {
    if (name.rfind("crossings_z", 0) != 0 && name.rfind("particles_z", 0) != 0) continue;
    Crossings c{name, {}, NAN, NAN, {}};
    for (const auto& run : runs) {
      const auto counts = analysis::crossings_per_cycle(run, name);
      c.per_cycle.insert(c.per_cycle.end(), counts.begin(), counts.end());
    }
    const double m = static_cast<double>(c.per_cycle.size());
    const double sum = std::accumulate(c.per_cycle.begin(), c.per_cycle.end(), 0.0);
    if (m >= 1) c.mean = sum / m;
    std::vector<double> left_out;
    if (m >= 2)
      for (double x : c.per_cycle) left_out.push_back((sum - x) / (m - 1));
    c.error = analysis::jackknife_error(left_out);
    if (c.per_cycle.size() == samples) c.replicates = std::move(left_out);
    out.push_back(std::move(c));
  }
  return out;
}

std::string analysis_json(const std::vector<std::string>& inputs, const RunRecord& run,
                          const Estimates& phases, const Estimates& per_run,
                          const std::vector<Crossings>& crossing) {
  const std::size_t samples = run.samples.empty() ? 0 : run.samples.samples();
  std::vector<std::string> quoted, counts;
  for (const auto& i : inputs) quoted.push_back(json_string(i));
  for (const auto& c : crossing)
    counts.push_back(fmt::format("    {}: {{\"unit\": \"particles per cycle\", \"value\": {}, "
                                 "\"error\": {}, \"per_cycle\": {}, \"replicates\": {}}}",
                                 json_string(c.column), json_number(c.mean), json_number(c.error),
                                 json_list(c.per_cycle), json_list(c.replicates)));
  return fmt::format(
      "{{\n  \"schema\": \"shaker-analysis\",\n  \"schema_version\": 1,\n"
      "  \"program_version\": {},\n  \"git_commit\": {},\n  \"inputs\": [{}],\n"
      "  \"solver\": {},\n  \"model_variant\": {},\n  \"restitution_for_analysis\": {},\n"
      "  \"samples\": {},\n  \"error_method\": {},\n  \"configuration\": {},\n"
      "  \"per_phase\": {},\n  \"per_run\": {},\n  \"crossings\": {{\n{}\n  }}\n}}\n",
      json_string(program_version()), json_string(git_commit()), fmt::join(quoted, ", "),
      json_string(run.solver), json_string(run.model_variant), json_number(run.e), samples,
      json_string(samples >= 2 ? fmt::format("jackknife over {} samples", samples) : "none"),
      json_string(run.configuration), json_quantities(phases, false),
      json_quantities(per_run, true), fmt::join(counts, ",\n"));
}

std::string analysis_csv(const Estimates& phases) {
  std::vector<std::string> header;
  // Each column's units in brackets after its name, as in the profiles CSV.
  for (const auto& c : phases.central) header.push_back(fmt::format("{} [{}]", c.name, c.unit));
  for (const auto& c : phases.central) header.push_back(fmt::format("{}_error [{}]", c.name, c.unit));
  std::string csv = fmt::format("{}\n", fmt::join(header, ","));
  const std::size_t rows = phases.central.front().values.size();
  for (std::size_t k = 0; k < rows; ++k) {
    std::vector<std::string> row;
    for (const auto& c : phases.central) row.push_back(fmt::format("{}", c.values[k]));
    for (const auto& e : phases.errors) row.push_back(fmt::format("{}", e[k]));
    csv += fmt::format("{}\n", fmt::join(row, ","));
  }
  return csv;
}

std::string with_error(double value, double error, int precision) {
  if (!std::isfinite(value)) return "-";
  if (!std::isfinite(error)) return fmt::format("{:.{}f}", value, precision);
  return fmt::format("{:.{}f}({:.{}f})", value, precision, error, precision);
}

void print_table(const std::string& title, const Estimates& phases, const Estimates& per_run,
                 const std::vector<Crossings>& crossing) {
  fmt::print("{}\n", title);
  const char* shown[] = {"phase", "plate_z", "layer_bottom", "layer_top", "center_of_mass",
                         "shock_location", "shock_width", "width_over_mfp", "max_mach"};
  std::vector<std::size_t> index;
  for (const char* name : shown)
    for (std::size_t q = 0; q < phases.central.size(); ++q)
      if (phases.central[q].name == name) index.push_back(q);
  for (std::size_t q : index) fmt::print("{:>17}", phases.central[q].name);
  fmt::print("\n");
  for (std::size_t k = 0; k < phases.central.front().values.size(); ++k) {
    for (std::size_t q : index)
      fmt::print("{:>17}", with_error(phases.central[q].values[k], phases.errors[q][k], 3));
    fmt::print("\n");
  }
  for (std::size_t q = 0; q < per_run.central.size(); ++q)
    fmt::print("# {}: {} [{}]\n", per_run.central[q].name,
               with_error(per_run.central[q].values[0], per_run.errors[q][0], 4), per_run.central[q].unit);
  for (const auto& c : crossing)
    fmt::print("# {} per cycle: {} over {} cycles\n", c.column, with_error(c.mean, c.error, 3),
               c.per_cycle.size());
}

// One row per stored phase and bin: the profile, its Mach number (for plots of Ma(z)) and its
// local Knudsen numbers (NaN where undefined).
void write_profiles_csv(const RunRecord& run, const std::string& path) {
  std::string csv = "phase [1],z [sigma],n [1/sigma^3],nu [1],uz [sqrt(g sigma)],T [g sigma],mach [1],kn_n [1],kn_T [1]\n";
  for (const auto& p : run.profiles) {
    const auto mach = analysis::mach_number(p, run.e);
    const auto kn = analysis::knudsen_numbers(p);
    for (std::size_t i = 0; i < p.size(); ++i)
      csv += fmt::format("{},{},{},{},{},{},{},{},{}\n", p.phase, p.z[i], p.n[i], p.nu[i], p.uz[i],
                         p.T[i], mach[i], kn.density[i], kn.temperature[i]);
  }
  write_text_atomically(path, csv);
}

}  // namespace

int command_analyze(const AnalyzeOptions& o) {
  std::vector<NamedPath> outputs, inputs;
  for (const auto& [flag, path] : {std::pair{"--csv", o.csv_file}, {"--json", o.json_file},
                                   {"--profiles-csv", o.profiles_csv}, {"--pooled", o.pooled_file},
                                   {"--patterns", o.patterns_csv}})
    if (!path.empty()) outputs.push_back({flag, path});
  for (const auto& file : o.run_files) inputs.push_back({"run file", file});
  if (!o.patterns_csv.empty()) {
    if (o.run_files.size() != 1)
      throw InputError(fmt::format("--patterns with {} run files; allowed: one RUN, whose particle "
                                   "or fields file it reads", o.run_files.size()));
    inputs.push_back({"snapshot file (RUN.particles.h5 of shaker md with md.snapshot_phases, or "
                      "RUN.fields.h5 of a 3D shaker continuum with continuum.field_phases)",
                      pattern_snapshots_path(o.run_files.front())});
    check_input_file(inputs.back());
  }
  check_output_paths(outputs, inputs);
  std::vector<RunRecord> runs;
  for (const auto& file : o.run_files) runs.push_back(read_run_file(file));
  // Read before anything is printed or written: a bad snapshot file is bad input.
  const PatternTables patterns =
      o.patterns_csv.empty() ? PatternTables{} : pattern_tables(inputs.back().path, o.pattern_cell);
  const RunRecord run = pool_runs(runs);
  const auto config = config::Config::from_toml(run.configuration, o.run_files.front());
  analysis::AnalysisOptions options;
  options.criteria = o.criteria;
  options.periodic = config.text("run.protocol") == "periodic";
  options.frequency = config.real("shaker.frequency");
  const auto [phases, per_run] = estimate(run, options);
  const std::size_t samples = run.samples.empty() ? 0 : run.samples.samples();
  const auto crossing = crossings(runs, samples);
  if (!o.quiet)
    print_table(fmt::format("# {}: solver {}, {}, e = {}, program {} ({}); errors: {}",
                            fmt::join(o.run_files, " + "), run.solver, run.model_variant, run.e,
                            run.program_version, run.git_commit,
                            samples >= 2 ? fmt::format("jackknife over {} samples", samples)
                                         : std::string("none")),
                phases, per_run, crossing);
  if (!o.patterns_csv.empty()) {
    if (!o.quiet) fmt::print("{}", patterns.summary);
    write_text_atomically(o.patterns_csv, patterns.csv);
  }
  if (!o.json_file.empty())
    write_text_atomically(o.json_file, analysis_json(o.run_files, run, phases, per_run, crossing));
  if (!o.csv_file.empty()) write_text_atomically(o.csv_file, analysis_csv(phases));
  if (!o.profiles_csv.empty()) write_profiles_csv(run, o.profiles_csv);
  if (!o.pooled_file.empty()) write_run_file(o.pooled_file, run);
  return 0;
}

}  // namespace shaker
