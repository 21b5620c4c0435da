// Unit tests of the HDF5 run file (solvers/common/run_file.hpp, hdf5_file.hpp): exact round
// trip, provenance, atomic writes and the errors a reader gives for foreign or damaged files.
// The same file layout is read independently with h5py by test_run_file_h5py.py.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/atomic_output.hpp"
#include "common/config.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "common/version.hpp"
#include "sample_run.hpp"
#include "test_support.hpp"

namespace {

using shaker::InputError;
using shaker::Profile;
using shaker::RunRecord;
using shaker::testing::make_sample_record;
using shaker::testing::TemporaryDirectory;

/// Bitwise equality, so that -0.0, NaN payloads and the last ulp all count.
void expect_same_bits(const std::vector<double>& a, const std::vector<double>& b,
                      const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a[i]), std::bit_cast<std::uint64_t>(b[i]))
        << what << "[" << i << "]: " << a[i] << " vs " << b[i];
}

void expect_same_record(const RunRecord& written, const RunRecord& read) {
  EXPECT_EQ(read.solver, written.solver);
  EXPECT_EQ(read.model_variant, written.model_variant);
  EXPECT_EQ(read.configuration, written.configuration);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(read.e), std::bit_cast<std::uint64_t>(written.e));
  ASSERT_EQ(read.profiles.size(), written.profiles.size());
  for (std::size_t k = 0; k < written.profiles.size(); ++k) {
    const Profile &w = written.profiles[k], &r = read.profiles[k];
    expect_same_bits({r.time, r.phase, r.plate_z, r.plate_v, r.bin_height},
                     {w.time, w.phase, w.plate_z, w.plate_v, w.bin_height}, "scalars");
    expect_same_bits(r.z, w.z, "z");
    expect_same_bits(r.n, w.n, "n");
    expect_same_bits(r.nu, w.nu, "nu");
    expect_same_bits(r.uz, w.uz, "uz");
    expect_same_bits(r.T, w.T, "T");
    expect_same_bits(r.samples, w.samples, "samples");
    expect_same_bits(r.n_se, w.n_se, "n_se");
    expect_same_bits(r.uz_se, w.uz_se, "uz_se");
    expect_same_bits(r.T_se, w.T_se, "T_se");
  }
  EXPECT_EQ(read.series.names, written.series.names);
  for (const auto& name : written.series.names)
    expect_same_bits(read.series.column(name), written.series.column(name), "series " + name);
  ASSERT_EQ(read.replica_series.size(), written.replica_series.size());
  for (std::size_t r = 0; r < written.replica_series.size(); ++r) {
    const shaker::TimeSeries &w = written.replica_series[r], &got = read.replica_series[r];
    EXPECT_EQ(got.names, w.names) << "replica " << r + 1;
    for (const auto& name : w.names)
      expect_same_bits(got.column(name), w.column(name), "replica " + std::to_string(r + 1) + " " + name);
  }
}

/// The sample as an ensemble of three replicas (md.replicas): replicas 1 and 2 have series of
/// their own, of other lengths (as a single shock's replicas, which run more cycles).
RunRecord ensemble_record() {
  RunRecord record = make_sample_record(true);
  for (std::size_t rows : {6u, 8u}) {
    shaker::TimeSeries replica;
    for (const auto& name : record.series.names) {
      std::vector<double> column;
      for (std::size_t i = 0; i < rows; ++i)
        column.push_back(static_cast<double>(rows) + 0.125 * static_cast<double>(i));
      replica.add(name, column);
    }
    record.replica_series.push_back(replica);
  }
  record.replica_series[1].columns[3][5] = -0.0;
  return record;
}

/// The sample plus values that only survive an exact binary round trip.
RunRecord awkward_record(bool with_standard_errors) {
  RunRecord record = make_sample_record(with_standard_errors);
  Profile& p = record.profiles[1];
  p.n[0] = 0.1;
  p.n[1] = 1.0 / 3.0;
  p.nu[2] = std::numeric_limits<double>::denorm_min();
  p.uz[3] = -0.0;
  p.T[4] = std::numeric_limits<double>::max();
  p.time = std::nextafter(10.25, 11.0);
  record.e = 0.1 + 0.2;
  return record;
}

std::vector<std::filesystem::path> files_in(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files.push_back(entry.path());
  return files;
}

TEST(RunFile, RoundTripWithStandardErrorsIsExact) {
  const TemporaryDirectory dir;
  const RunRecord written = awkward_record(true);
  RunRecord with_nan = written;
  // A column that is NaN by design in a run's first cycle.
  with_nan.series.add("com_z_change_from_previous_cycle",
                      {1.0, std::numeric_limits<double>::quiet_NaN(), 3.5, 4.0});
  for (const RunRecord& record : {written, with_nan}) {
    shaker::write_run_file(dir / "run.h5", record);
    expect_same_record(record, shaker::read_run_file(dir / "run.h5"));
  }
}

TEST(RunFile, AColumnWithoutDeclaredUnitsIsRefused) {
  const TemporaryDirectory dir;
  RunRecord record = awkward_record(true);
  record.series.add("shock_z", {1.0, 2.0, 3.5, 4.0});
  EXPECT_THROW(shaker::write_run_file(dir / "run.h5", record), std::logic_error);
  EXPECT_FALSE(std::filesystem::exists(dir / "run.h5"));
}

TEST(RunFile, RoundTripWithoutStandardErrorsKeepsThemAbsent) {
  const TemporaryDirectory dir;
  const RunRecord written = awkward_record(false);
  shaker::write_run_file(dir / "continuum.h5", written);
  const RunRecord read = shaker::read_run_file(dir / "continuum.h5");
  expect_same_record(written, read);
  for (const auto& p : read.profiles) {
    EXPECT_TRUE(p.samples.empty());
    EXPECT_TRUE(p.n_se.empty() && p.uz_se.empty() && p.T_se.empty());
  }
}

TEST(RunFile, RecordsProvenanceAndTheEffectiveConfiguration) {
  const TemporaryDirectory dir;
  const RunRecord written = make_sample_record(true);
  shaker::write_run_file(dir / "run.h5", written);
  const RunRecord read = shaker::read_run_file(dir / "run.h5");
  EXPECT_EQ(read.schema_version, shaker::output_schema_version);
  EXPECT_EQ(read.program_version, shaker::program_version());
  EXPECT_EQ(read.git_commit, shaker::git_commit());
  EXPECT_FALSE(read.program_version.empty());
  EXPECT_FALSE(read.git_commit.empty());
  EXPECT_EQ(read.created.size(), 20u) << read.created;  // 2026-01-31T12:00:00Z
  EXPECT_EQ(read.created.back(), 'Z') << read.created;
  // The stored configuration reproduces the effective configuration exactly.
  shaker::config::Config expected;
  expected.set("material.e=0.8");
  expected.set("case.name=sample run");
  const auto stored = shaker::config::Config::from_toml(read.configuration, "stored");
  EXPECT_EQ(stored.to_toml(), expected.to_toml());
  EXPECT_EQ(stored.hash(), expected.hash());
}

TEST(RunFile, EnsembleRoundTripKeepsEveryReplicasSeriesInReplicaOrder) {
  const TemporaryDirectory dir;
  const RunRecord written = ensemble_record();
  shaker::write_run_file(dir / "ensemble.h5", written);
  expect_same_record(written, shaker::read_run_file(dir / "ensemble.h5"));
  // The layout docs/output-schema.md gives: replica 0 in /timeseries, replica r in
  // /replica_timeseries/replica_0000r, the group's attribute `replicas` = K.
  shaker::h5::Handle file = shaker::h5::open_file(dir / "ensemble.h5");
  shaker::h5::Handle group = shaker::h5::open_group(file.id(), "replica_timeseries");
  EXPECT_EQ(shaker::h5::read_integer_attribute(group.id(), "replicas"), 3);
  EXPECT_EQ(shaker::h5::members(group.id()), (std::vector<std::string>{"replica_00001", "replica_00002"}));
  shaker::h5::Handle second = shaker::h5::open_group(group.id(), "replica_00002");
  EXPECT_EQ(shaker::h5::read_string_attribute(second.id(), "columns"), "t,phase,plate_z,com_z");
  EXPECT_EQ(shaker::h5::shape(second.id(), "com_z"), (std::vector<std::size_t>{8}));
  // A single run has no replica group.
  shaker::write_run_file(dir / "single.h5", make_sample_record(true));
  shaker::h5::Handle single = shaker::h5::open_file(dir / "single.h5");
  EXPECT_FALSE(shaker::h5::exists(single.id(), "replica_timeseries"));
  EXPECT_TRUE(shaker::read_run_file(dir / "single.h5").replica_series.empty());
}

TEST(RunFile, RefusesAReplicaSeriesWithOtherColumns) {
  const TemporaryDirectory dir;
  RunRecord record = ensemble_record();
  shaker::TimeSeries shorter;
  for (std::size_t i = 0; i + 1 < record.series.names.size(); ++i)
    shorter.add(record.series.names[i], record.replica_series[1].columns[i]);
  record.replica_series[1] = shorter;
  try {
    shaker::write_run_file(dir / "run.h5", record);
    ADD_FAILURE() << "a replica's series without com_z was written";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("replica 2"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(files_in(dir.path()).empty()) << "left behind: " << files_in(dir.path()).front();
}

TEST(RunFile, RunWithoutProfilesRoundTrips) {
  const TemporaryDirectory dir;
  RunRecord record = make_sample_record(false);
  record.profiles.clear();
  shaker::write_run_file(dir / "series-only.h5", record);
  expect_same_record(record, shaker::read_run_file(dir / "series-only.h5"));
}

TEST(RunFile, RefusesASeriesWithoutARequiredColumn) {
  const TemporaryDirectory dir;
  for (const char* missing : shaker::required_series_columns) {
    RunRecord record = make_sample_record(true);
    shaker::TimeSeries kept;
    for (std::size_t i = 0; i < record.series.names.size(); ++i)
      if (record.series.names[i] != missing) kept.add(record.series.names[i], record.series.columns[i]);
    record.series = kept;
    try {
      shaker::write_run_file(dir / "run.h5", record);
      ADD_FAILURE() << "a series without " << missing << " was written";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(std::string("'") + missing + "'"), std::string::npos)
          << error.what();
    }
    EXPECT_TRUE(files_in(dir.path()).empty()) << "left behind: " << files_in(dir.path()).front();
  }
}

TEST(RunFile, FailedWriteLeavesNothingUnderTheFinalNameAndNoTemporaryFile) {
  const TemporaryDirectory dir;
  RunRecord ragged = make_sample_record(true);
  ragged.profiles[2].z.push_back(9.0);  // profiles of different lengths
  ragged.profiles[2].n.push_back(9.0);
  EXPECT_ANY_THROW(shaker::write_run_file(dir / "run.h5", ragged));
  EXPECT_TRUE(files_in(dir.path()).empty()) << "left behind: " << files_in(dir.path()).front();

  RunRecord short_field = make_sample_record(true);
  short_field.profiles[1].T_se.pop_back();  // one field of the wrong length
  EXPECT_ANY_THROW(shaker::write_run_file(dir / "run.h5", short_field));
  EXPECT_TRUE(files_in(dir.path()).empty());

  // A failed rewrite leaves an existing file untouched.
  const RunRecord good = make_sample_record(true);
  shaker::write_run_file(dir / "run.h5", good);
  EXPECT_ANY_THROW(shaker::write_run_file(dir / "run.h5", ragged));
  ASSERT_EQ(files_in(dir.path()).size(), 1u);
  expect_same_record(good, shaker::read_run_file(dir / "run.h5"));
}

TEST(AtomicOutput, RemovesTheTemporaryFileUnlessCommitted) {
  const TemporaryDirectory dir;
  std::filesystem::path temporary;
  {
    shaker::AtomicOutput output(dir / "out.txt");
    temporary = output.temporary_path();
    EXPECT_EQ(temporary.parent_path(), dir.path()) << "the rename must stay on one file system";
    std::ofstream(temporary) << "half";
    EXPECT_FALSE(std::filesystem::exists(dir / "out.txt"));
  }
  EXPECT_FALSE(std::filesystem::exists(temporary));
  EXPECT_TRUE(files_in(dir.path()).empty());
  shaker::write_text_atomically(dir / "out.txt", "complete\n");
  std::ifstream in(dir / "out.txt");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "complete");
  EXPECT_EQ(files_in(dir.path()).size(), 1u);
}

// ---- reading foreign or damaged files ------------------------------------------------------

void expect_read_error(const std::filesystem::path& path,
                       const std::vector<std::string>& fragments) {
  try {
    shaker::read_run_file(path);
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& error) {
    const std::string message = error.what();
    for (const auto& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message '" << message << "' does not contain '" << fragment << "'";
  } catch (const std::exception& error) {
    ADD_FAILURE() << "threw something other than InputError: " << error.what();
  }
}

/// Copies the sample run and damages the copy with the raw HDF5 API.
std::filesystem::path damaged_copy(const TemporaryDirectory& dir, const std::string& name,
                                   void (*damage)(hid_t file),
                                   const RunRecord& record = make_sample_record(true)) {
  const auto path = dir / name;
  shaker::write_run_file(path, record);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  EXPECT_GE(file, 0);
  damage(file);
  H5Fclose(file);
  return path;
}

TEST(RunFile, Version1SeriesColumnsAreReadUnderTheirPresentNames) {
  const TemporaryDirectory dir;
  RunRecord record = make_sample_record(true);
  record.solver = "md";
  record.series.add("kinetic_energy", {1.0, 2.0, 3.0, 4.0});
  record.series.add("accumulated_drive_work", {0.0, 0.5, 1.5, 2.5});
  record.series.add("accumulated_collisional_loss", {0.0, 0.25, 0.75, 1.0});
  record.series.add("energy_budget_relative_residual", {0.0, 1e-15, 2e-15, 1e-15});
  const auto path = damaged_copy(
      dir, "version-1.h5",
      [](hid_t f) {
        shaker::h5::write_attribute(f, "schema_version", std::int64_t{1});
        const hid_t g = H5Gopen2(f, "timeseries", H5P_DEFAULT);
        for (const auto& [present, old] : {std::pair{"kinetic_energy", "kinetic"}, {"accumulated_drive_work", "plate_work"},
                                           {"accumulated_collisional_loss", "collisional_loss"},
                                           {"energy_budget_relative_residual", "energy_closure"}})
          H5Lmove(g, present, g, old, H5P_DEFAULT, H5P_DEFAULT);
        shaker::h5::write_attribute(g, "columns", std::string("t,phase,plate_z,com_z,kinetic,plate_work,"
                                                              "collisional_loss,energy_closure"));
        H5Gclose(g);
      },
      record);
  const RunRecord read = shaker::read_run_file(path);
  EXPECT_EQ(read.schema_version, 1);
  EXPECT_EQ(read.series.names, record.series.names);
  for (const std::string& name : record.series.names)
    expect_same_bits(read.series.column(name), record.series.column(name), name);
}

TEST(RunFile, ReadingForeignOrDamagedFilesThrowsInputError) {
  const TemporaryDirectory dir;
  std::ofstream(dir / "text.h5") << "not an HDF5 file\n";
  expect_read_error(dir / "text.h5", {"text.h5", "not an HDF5 file"});
  expect_read_error(dir / "missing.h5", {"missing.h5", "does not exist"});
  std::ofstream(dir / "empty.h5").close();
  expect_read_error(dir / "empty.h5", {"empty.h5"});

  expect_read_error(
      damaged_copy(dir, "no-profiles.h5", [](hid_t f) { H5Ldelete(f, "profiles", H5P_DEFAULT); }),
      {"no-profiles.h5", "profiles", "missing"});
  expect_read_error(
      damaged_copy(dir, "no-series.h5", [](hid_t f) { H5Ldelete(f, "timeseries", H5P_DEFAULT); }),
      {"no-series.h5", "timeseries", "missing"});
  expect_read_error(
      damaged_copy(dir, "no-T.h5", [](hid_t f) { H5Ldelete(f, "profiles/T", H5P_DEFAULT); }),
      {"no-T.h5", "'T'", "missing"});
  expect_read_error(damaged_copy(dir, "no-column.h5",
                                 [](hid_t f) { H5Ldelete(f, "timeseries/com_z", H5P_DEFAULT); }),
                    {"no-column.h5", "com_z", "missing"});
  expect_read_error(
      damaged_copy(dir, "no-configuration.h5", [](hid_t f) { H5Adelete(f, "configuration"); }),
      {"no-configuration.h5", "configuration", "missing"});
  expect_read_error(
      damaged_copy(
          dir, "future.h5",
          [](hid_t f) { shaker::h5::write_attribute(f, "schema_version", std::int64_t{99}); }),
      {"future.h5", "schema version 99"});
  expect_read_error(damaged_copy(dir, "flat-T.h5",
                                 [](hid_t f) {
                                   H5Ldelete(f, "profiles/T", H5P_DEFAULT);
                                   const hid_t g = H5Gopen2(f, "profiles", H5P_DEFAULT);
                                   shaker::h5::write(g, "T", std::vector<double>(15, 1.0));
                                   H5Gclose(g);
                                 }),
                    {"flat-T.h5", "profiles/T"});
  expect_read_error(damaged_copy(
                        dir, "no-replica.h5",
                        [](hid_t f) { H5Ldelete(f, "replica_timeseries/replica_00002", H5P_DEFAULT); },
                        ensemble_record()),
                    {"no-replica.h5", "replica_timeseries", "replica_00002"});
  expect_read_error(damaged_copy(
                        dir, "one-replica.h5",
                        [](hid_t f) {
                          const hid_t g = H5Gopen2(f, "replica_timeseries", H5P_DEFAULT);
                          shaker::h5::write_attribute(g, "replicas", std::int64_t{1});
                          H5Gclose(g);
                        },
                        ensemble_record()),
                    {"one-replica.h5", "replicas = 1"});
}

}  // namespace
