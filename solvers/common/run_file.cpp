#include "common/run_file.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <map>
#include <cmath>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>
#include <sstream>

#include "common/atomic_output.hpp"
#include "common/config.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/version.hpp"

namespace shaker {
namespace {

using FieldOf = std::vector<double> Profile::*;
struct FieldName {
  const char* name;
  FieldOf field;
  bool optional;
  const char* units;  ///< docs/units.md notation, stored as the dataset's attribute `units`
  bool may_be_undefined = false;  ///< NaN marks a bin where the field is undefined
};
// Per-phase fields stored as [phases x bins] matrices.
constexpr FieldName profile_fields[] = {
    {"z", &Profile::z, false, "sigma"},
    {"n", &Profile::n, false, "1/sigma^3"},
    {"nu", &Profile::nu, false, "1"},
    {"uz", &Profile::uz, false, "sqrt(g sigma)", true},
    {"T", &Profile::T, false, "g sigma", true},
    {"samples", &Profile::samples, true, "1"},
    {"n_se", &Profile::n_se, true, "1/sigma^3"},
    {"uz_se", &Profile::uz_se, true, "sqrt(g sigma)"},
    {"T_se", &Profile::T_se, true, "g sigma"},
};
using ScalarOf = double Profile::*;
struct ScalarName {
  const char* name;
  ScalarOf field;
  const char* units;
};
constexpr ScalarName profile_scalars[] = {{"time", &Profile::time, "sqrt(sigma/g)"},
                                          {"phase", &Profile::phase, "1"},
                                          {"plate_z", &Profile::plate_z, "sigma"},
                                          {"plate_v", &Profile::plate_v, "sqrt(g sigma)"},
                                          {"bin_height", &Profile::bin_height, "sigma"}};

/// The units of every time-series column either solver writes (docs/output-schema.md); the
/// per-height counters crossings_z<h> and particles_z<h> are counts. The MD's energies are the
/// system's, the continuum's per unit plate area.
std::string series_units(const std::string& column, const std::string& solver) {
  static const std::map<std::string, std::string> units{
      {"t", "sqrt(sigma/g)"}, {"phase", "1"}, {"plate_z", "sigma"}, {"com_z", "sigma"},
      {"energy_budget_relative_residual", "1"},
      // MD
      {"pair_collisions", "1"}, {"plate_collisions", "1"}, {"ceiling_collisions", "1"}, {"cell_crossings", "1"},
      {"guard_activations", "1"}, {"overlaps", "1"}, {"near_plate", "1"}, {"collisions", "1"},
      {"queue_consistent", "1"},
      // continuum
      {"total_mass", "m / sigma^2"}, {"collisional_loss_rate", "m g^(3/2) / sigma^(3/2)"},
      {"com_z_change_from_previous_cycle", "sigma"}, {"temperature_floor_uses", "1"},
      {"steps", "1"}, {"periodicity_last_two_cycles", "1"}, {"restitution", "1"}};
  static const std::set<std::string> energies{
      "kinetic_energy", "potential_energy", "thermal_energy", "frame_energy", "accumulated_drive_work",
      "accumulated_collisional_loss", "accumulated_floor_energy", "energy_budget_residual"};
  if (energies.count(column)) return solver == "continuum" ? "m g / sigma" : "m g sigma";
  if (const auto it = units.find(column); it != units.end()) return it->second;
  if (column.rfind("crossings_z", 0) == 0 || column.rfind("particles_z", 0) == 0) return "1";
  throw std::logic_error(fmt::format("time-series column '{}' has no units: declare them in "
                                     "series_units (run_file.cpp) and docs/output-schema.md", column));
}

/// The time-series columns that schema version 1 named otherwise, by their present names.
std::string present_column_name(const std::string& version_1_name) {
  static const std::map<std::string, std::string> renamed{
      {"kinetic", "kinetic_energy"}, {"potential", "potential_energy"},
      {"plate_work", "accumulated_drive_work"}, {"accumulated_body_work", "accumulated_drive_work"},
      {"collisional_loss", "accumulated_collisional_loss"}, {"energy_closure", "energy_budget_relative_residual"}};
  const auto it = renamed.find(version_1_name);
  return it == renamed.end() ? version_1_name : it->second;
}

void write_profiles(hid_t file, const std::vector<Profile>& profiles) {
  h5::Handle group = h5::create_group(file, "profiles");
  const std::size_t phases = profiles.size();
  const std::size_t bins = phases ? profiles.front().size() : 0;
  for (const auto& p : profiles)
    if (p.size() != bins) throw std::logic_error("profiles differ in their number of bins");
  for (const auto& [name, field, units] : profile_scalars) {
    std::vector<double> values;
    for (const auto& p : profiles) values.push_back(p.*field);
    h5::write(group.id(), name, values, {phases}, units);
  }
  for (const auto& [name, field, optional, units, may_be_undefined] : profile_fields) {
    const bool present = phases && !(profiles.front().*field).empty();
    if (!present && optional) continue;
    std::vector<double> matrix;
    matrix.reserve(phases * bins);
    for (const auto& p : profiles) {
      const auto& column = p.*field;
      if (column.size() != bins)
        throw std::logic_error(fmt::format("profile field '{}' has the wrong length", name));
      matrix.insert(matrix.end(), column.begin(), column.end());
    }
    h5::write(group.id(), name, matrix, {phases, bins}, units);
  }
}

std::vector<Profile> read_profiles(hid_t file) {
  h5::Handle group = h5::open_group(file, "profiles");
  const auto phase = h5::read_doubles(group.id(), "phase");
  std::vector<Profile> profiles(phase.size());
  for (const auto& [name, field, units] : profile_scalars) {
    const auto values = h5::read_doubles(group.id(), name);
    if (values.size() != profiles.size())
      throw InputError(fmt::format("profiles/{} has {} entries, expected {}", name, values.size(),
                                   profiles.size()));
    for (std::size_t k = 0; k < profiles.size(); ++k) profiles[k].*field = values[k];
  }
  std::optional<std::size_t> bins;  // of the first field (z); every other field must agree
  for (const auto& [name, field, optional, units, may_be_undefined] : profile_fields) {
    if (optional && !h5::exists(group.id(), name)) continue;
    const auto dims = h5::shape(group.id(), name);
    if (dims.size() != 2 || dims[0] != profiles.size())
      throw InputError(fmt::format("profiles/{} is not a [phases x bins] matrix of {} phases "
                                   "(profiles/phase has {})", name, profiles.size(), profiles.size()));
    if (!bins) bins = dims[1];
    if (dims[1] != *bins)
      throw InputError(fmt::format("profiles/{} has {} bins, profiles/z has {}; allowed: the same "
                                   "number of bins in every profile field", name, dims[1], *bins));
    const auto values = h5::read_doubles(group.id(), name);
    if (!optional)  // the fields the analysis computes with: finite, or NaN where undefined
      for (std::size_t i = 0; i < values.size(); ++i)
        if (!std::isfinite(values[i]) && !(may_be_undefined && std::isnan(values[i])))
          throw InputError(fmt::format("profiles/{} holds {} at phase index {}, bin {}; allowed: "
                                       "finite values{}", name, values[i], i / *bins, i % *bins,
                                       may_be_undefined ? " (NaN where undefined)" : ""));
    for (std::size_t k = 0; k < profiles.size(); ++k)
      profiles[k].*field = std::vector<double>(values.begin() + static_cast<long>(k * dims[1]),
                                               values.begin() + static_cast<long>((k + 1) * dims[1]));
  }
  return profiles;
}

// The sums of each sample, one [phases * samples x bins] matrix per sum; "cycles" gives the
// cycles pooled into each sample, [phases x samples].
struct SampleSum {
  const char* name;
  double BinSums::*member;
  const char* units;
};
constexpr SampleSum sample_sums[] = {{"count", &BinSums::count, "1"},
                                     {"vx", &BinSums::vx, "sqrt(g sigma)"},
                                     {"vy", &BinSums::vy, "sqrt(g sigma)"},
                                     {"vz", &BinSums::vz, "sqrt(g sigma)"},
                                     {"v2", &BinSums::v2, "g sigma"}};

}  // namespace

void write_samples(hid_t file, const CycleSamples& samples, bool ragged) {
  if (samples.empty()) return;
  const std::size_t phases = samples.phases(), bins = samples.bins();
  std::size_t m = 0;
  for (std::size_t k = 0; k < phases; ++k) m = std::max(m, samples.samples(k));
  h5::Handle group = h5::create_group(file, "cycle_samples");
  h5::write_attribute(group.id(), "bin_volume", samples.bin_volume());
  // A phase with fewer samples is padded with empty ones (0 cycles, zero sums).
  std::vector<double> cycles;
  for (std::size_t k = 0; k < phases; ++k) {
    if (!ragged && samples.samples(k) != m) throw std::logic_error("phases hold different sample counts");
    cycles.insert(cycles.end(), samples.cycles(k).begin(), samples.cycles(k).end());
    cycles.resize((k + 1) * m, 0.0);
  }
  h5::write(group.id(), "cycles", cycles, {phases, m}, "1");
  for (const auto& [name, member, units] : sample_sums) {
    std::vector<double> matrix;
    matrix.reserve(phases * m * bins);
    for (std::size_t k = 0; k < phases; ++k) {
      for (const BinSums& b : samples.sums(k)) matrix.push_back(b.*member);
      matrix.resize((k + 1) * m * bins, 0.0);
    }
    h5::write(group.id(), name, matrix, {phases * m, bins}, units);
  }
}

CycleSamples read_samples(hid_t file, std::size_t phases, std::size_t bins, bool ragged) {
  if (!h5::exists(file, "cycle_samples") || bins == 0) return {};
  h5::Handle group = h5::open_group(file, "cycle_samples");
  const double bin_volume = h5::read_double_attribute(group.id(), "bin_volume");
  const auto shape = h5::shape(group.id(), "cycles");
  if (shape.size() != 2 || shape[0] != phases || shape[1] == 0)
    throw InputError(fmt::format("cycle_samples/cycles is not a [{} phases x samples] matrix",
                                 phases));
  const std::size_t m = shape[1];
  // Every shape is checked before the sums are allocated, so that the data in the file, not
  // its attributes, bounds the allocation (4 phases x 30,000 bins of profiles and a 4 x 30,000
  // cycles matrix asked for 144 GB: std::bad_alloc instead of InputError).
  for (const auto& [name, member, units] : sample_sums) {
    const auto dims = h5::shape(group.id(), name);
    if (dims.size() != 2 || dims[0] != phases * m || dims[1] != bins)
      throw InputError(fmt::format("cycle_samples/{} is not a [{} x {}] matrix", name,
                                   phases * m, bins));
  }
  const auto flat_cycles = h5::read_doubles(group.id(), "cycles");
  std::vector<std::vector<double>> cycles(phases);
  std::vector<std::vector<BinSums>> sums(phases, std::vector<BinSums>(m * bins));
  for (std::size_t k = 0; k < phases; ++k) {
    cycles[k].assign(flat_cycles.begin() + static_cast<long>(k * m),
                     flat_cycles.begin() + static_cast<long>((k + 1) * m));
    // Padding (0 cycles) only after a phase's samples, and only where phases may differ.
    const auto padding = std::find(cycles[k].begin(), cycles[k].end(), 0.0);
    if (ragged && std::all_of(padding, cycles[k].end(), [](double c) { return c == 0.0; }))
      cycles[k].erase(padding, cycles[k].end());
    for (double c : cycles[k])
      if (!(c >= 1.0 && c == std::floor(c)))
        throw InputError(fmt::format("cycle_samples/cycles holds {}, allowed: whole numbers >= 1{}", c,
                                     ragged ? " (0 after a phase's last sample)" : ""));
  }
  for (const auto& [name, member, units] : sample_sums) {
    const auto values = h5::read_doubles(group.id(), name);
    for (std::size_t k = 0; k < phases; ++k) {
      sums[k].resize(cycles[k].size() * bins);
      for (std::size_t i = 0; i < sums[k].size(); ++i) {
        const double x = values[k * m * bins + i];
        if (!std::isfinite(x) || (member == &BinSums::count && x < 0.0))
          throw InputError(fmt::format("cycle_samples/{} holds {}; allowed: finite{}", name, x,
                                       member == &BinSums::count ? " counts >= 0" : " sums"));
        sums[k][i].*member = x;
      }
    }
  }
  if (!(bin_volume > 0.0 && std::isfinite(bin_volume)))
    throw InputError(fmt::format("cycle_samples: bin_volume = {}, allowed: > 0", bin_volume));
  try {
    return CycleSamples::from_arrays(bins, bin_volume, std::move(cycles), std::move(sums));
  } catch (const std::invalid_argument& error) {
    throw InputError(error.what());
  }
}

namespace {

/// A time series as a group: one 1D dataset per column with its units, and the string
/// attribute `columns` naming them in order (`/timeseries`, and each replica's in an ensemble).
void write_series(hid_t parent, const std::string& name, const TimeSeries& series, const std::string& solver) {
  h5::Handle group = h5::create_group(parent, name);
  h5::write_attribute(group.id(), "columns", fmt::format("{}", fmt::join(series.names, ",")));
  for (std::size_t i = 0; i < series.names.size(); ++i)
    h5::write(group.id(), series.names[i], series.columns[i], {series.columns[i].size()},
              series_units(series.names[i], solver));
}

TimeSeries read_series(hid_t parent, const std::string& name, std::int64_t schema_version) {
  h5::Handle group = h5::open_group(parent, name);
  TimeSeries series;
  std::stringstream names(h5::read_string_attribute(group.id(), "columns"));
  for (std::string stored; std::getline(names, stored, ',');) {
    auto values = h5::read_doubles(group.id(), stored);
    const std::string column = schema_version == 1 ? present_column_name(stored) : stored;
    if (series.has(column))
      throw InputError(fmt::format("{}: column '{}' is listed twice in attribute 'columns'; allowed: "
                                   "each column once", name, column));
    if (!series.columns.empty() && values.size() != series.columns.front().size())
      throw InputError(fmt::format("{}/{} has {} rows; allowed: {}, the rows of {}/{} (the columns "
                                   "of a series have equal lengths)", name, column, values.size(),
                                   series.columns.front().size(), name, series.names.front()));
    series.add(column, std::move(values));
  }
  return series;
}

// An MD ensemble's replicas 1 .. K-1 (replica 0's series is /timeseries): the group
// `replica_timeseries`, its int64 attribute `replicas` = K, and one series group per replica,
// `replica_00001` ... (five digits, so that name order is replica order for every allowed K).
constexpr const char* replica_group = "replica_timeseries";
std::string replica_name(std::size_t r) { return fmt::format("replica_{:05d}", r); }

void write_replica_series(hid_t file, const std::vector<TimeSeries>& replicas, const std::string& solver) {
  if (replicas.empty()) return;
  h5::Handle group = h5::create_group(file, replica_group);
  h5::write_attribute(group.id(), "replicas", static_cast<std::int64_t>(replicas.size() + 1));
  for (std::size_t r = 1; r <= replicas.size(); ++r)
    write_series(group.id(), replica_name(r), replicas[r - 1], solver);
}

std::vector<TimeSeries> read_replica_series(hid_t file, std::int64_t schema_version) {
  if (!h5::exists(file, replica_group)) return {};
  h5::Handle group = h5::open_group(file, replica_group);
  const std::int64_t replicas = h5::read_integer_attribute(group.id(), "replicas");
  if (replicas < 2)
    throw InputError(fmt::format("{}: attribute replicas = {}, allowed: >= 2 (the group is "
                                 "written for an ensemble only)", replica_group, replicas));
  std::vector<TimeSeries> series;
  for (std::size_t r = 1; r < static_cast<std::size_t>(replicas); ++r) {
    const std::string name = replica_name(r);
    if (!h5::exists(group.id(), name))
      throw InputError(fmt::format("{} has no group {} (attribute replicas = {}: one group per "
                                   "replica 1 .. {})", replica_group, name, replicas, replicas - 1));
    series.push_back(read_series(group.id(), name, schema_version));
  }
  return series;
}

}  // namespace

std::string utc_now() {
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::chrono::system_clock::now()));
}

void write_run_attributes(hid_t file, const RunRecord& record) {
  h5::write_attribute(file, "schema_version", std::int64_t{output_schema_version});
  h5::write_attribute(file, "program_version", std::string(program_version()));
  h5::write_attribute(file, "git_commit", std::string(git_commit()));
  h5::write_attribute(file, "created", utc_now());
  h5::write_attribute(file, "solver", record.solver);
  h5::write_attribute(file, "model_variant", record.model_variant);
  h5::write_attribute(file, "configuration", record.configuration);
  h5::write_attribute(file, "restitution_for_analysis", record.e);
  h5::write_attribute(file, "warnings", fmt::format("{}", fmt::join(record.warnings, "\n")));
}

void write_run_file(const std::filesystem::path& path, const RunRecord& record) {
  for (const char* name : required_series_columns)
    if (!record.series.has(name))
      throw std::invalid_argument(fmt::format(
          "run file '{}': the time series has no column '{}'; every run file has the columns {} "
          "(docs/output-schema.md)", path.string(), name, fmt::join(required_series_columns, ", ")));
  for (std::size_t r = 0; r < record.replica_series.size(); ++r)
    if (record.replica_series[r].names != record.series.names)
      throw std::invalid_argument(fmt::format(
          "run file '{}': the time series of replica {} has the columns {}, replica 0's {}; "
          "every replica has the same columns (docs/output-schema.md)", path.string(), r + 1,
          fmt::join(record.replica_series[r].names, ", "), fmt::join(record.series.names, ", ")));
  write_hdf5_atomically(path, [&](hid_t file) {
    write_run_attributes(file, record);
    write_profiles(file, record.profiles);
    write_samples(file, record.samples, false);
    write_series(file, "timeseries", record.series, record.solver);
    write_replica_series(file, record.replica_series, record.solver);
  });
}

RunRecord read_run_file(const std::filesystem::path& path) {
  try {
    h5::Handle file = h5::open_file(path);
    RunRecord record;
    // A fields file shares the run file's root attributes: refused by what it is, not later by
    // a missing group.
    if (h5::has_attribute(file.id(), file_kind_attribute))
      throw InputError(fmt::format("this is a '{}' file (root attribute {}), not a run file; "
                                   "allowed: the run.output file of shaker md or shaker continuum",
                                   h5::read_string_attribute(file.id(), file_kind_attribute),
                                   file_kind_attribute));
    const std::int64_t version = h5::read_integer_attribute(file.id(), "schema_version");
    if (version < oldest_readable_schema_version || version > output_schema_version)
      throw InputError(fmt::format("schema version {} is not supported (attribute schema_version; "
                                   "allowed: {} to {}, the versions this program reads)", version,
                                   oldest_readable_schema_version, output_schema_version));
    record.schema_version = static_cast<int>(version);
    record.program_version = h5::read_string_attribute(file.id(), "program_version");
    record.git_commit = h5::read_string_attribute(file.id(), "git_commit");
    record.created = h5::read_string_attribute(file.id(), "created");
    record.solver = h5::read_string_attribute(file.id(), "solver");
    record.model_variant = h5::read_string_attribute(file.id(), "model_variant");
    record.configuration = h5::read_string_attribute(file.id(), "configuration");
    record.e = h5::read_double_attribute(file.id(), "restitution_for_analysis");
    // Files written before runs judged themselves have no warnings attribute.
    if (h5::has_attribute(file.id(), "warnings")) {
      std::istringstream lines(h5::read_string_attribute(file.id(), "warnings"));
      for (std::string line; std::getline(lines, line);) record.warnings.push_back(line);
    }
    const config::Range restitution = config::find_spec("material.e").range;
    if (!std::isfinite(record.e) || !restitution.contains(record.e))
      throw InputError(fmt::format("attribute 'restitution_for_analysis' = {}; allowed: {} (material.e)",
                                   record.e, restitution.describe()));
    record.profiles = read_profiles(file.id());
    record.samples = read_samples(file.id(), record.profiles.size(),
                                  record.profiles.empty() ? 0 : record.profiles.front().size(), false);
    record.series = read_series(file.id(), "timeseries", version);
    record.replica_series = read_replica_series(file.id(), version);
    return record;
  } catch (const InputError& error) {
    throw InputError(fmt::format("run file '{}': {}", path.string(), error.what()));
  } catch (const std::runtime_error& error) {
    throw InputError(fmt::format("run file '{}' is unreadable: {}", path.string(), error.what()));
  }
}

}  // namespace shaker
