#pragma once
// What both solvers produce and the analysis consumes: horizontally averaged profiles at
// stored phases, time series, and the provenance of the run (one HDF5 file per run).
#include <string>
#include <vector>

#include "common/cycle_samples.hpp"

namespace shaker {

/// Horizontally averaged fields at one instant, heights in the lab frame.
struct Profile {
  double time = 0.0;        ///< simulation time of the (first) sample
  double phase = 0.0;       ///< f t in [0, 1)
  double plate_z = 0.0;     ///< plate height at this phase
  double plate_v = 0.0;     ///< plate velocity at this phase
  double bin_height = 1.0;  ///< thickness of a bin or cell
  std::vector<double> z;    ///< bin or cell centres
  std::vector<double> n, nu, uz, T;
  /// MD: particles counted in each bin over all sampled cycles (empty for the continuum).
  std::vector<double> samples;
  /// Standard errors over sampled cycles (empty when not known).
  std::vector<double> n_se, uz_se, T_se;

  std::size_t size() const { return z.size(); }
};

/// Named columns of equal length, kept in insertion order.
struct TimeSeries {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;

  void add(const std::string& name, std::vector<double> values);
  const std::vector<double>& column(const std::string& name) const;  ///< throws if absent
  bool has(const std::string& name) const;
};

/// Everything a run file holds.
struct RunRecord {
  std::string solver;         ///< "md", "continuum" or "synthetic"
  std::string model_variant;  ///< e.g. "constant e" / "paper transport"
  std::string configuration;  ///< effective configuration, TOML
  double e = 0.9;             ///< restitution the analysis uses for the sound speed
  std::vector<Profile> profiles;
  /// MD: the sums of each sampled cycle behind the profiles (empty for the continuum).
  CycleSamples samples;
  TimeSeries series;  ///< of replica 0 in an MD ensemble (md.replicas)
  /// MD ensembles (md.replicas = K > 1): the time series of replicas 1 .. K-1, in replica
  /// order, with the columns of `series`; empty for a single run.
  std::vector<TimeSeries> replica_series;
  /// What the run found doubtful about its own result (docs/output-schema.md, `warnings`);
  /// empty when nothing was.
  std::vector<std::string> warnings;
  // Filled when read back from a file:
  int schema_version = 0;
  std::string program_version, git_commit, created;
};

/// MD runs of one configuration (repeats, or the replicas of an ensemble) pooled into one
/// record: their samples appended in the order given, the profiles rebuilt from all samples;
/// everything else (time series, replicas' time series, configuration) is the first run's. Throws InputError if a
/// run lacks samples or the runs differ in their phases or bins.
RunRecord pool_runs(const std::vector<RunRecord>& runs);

}  // namespace shaker
