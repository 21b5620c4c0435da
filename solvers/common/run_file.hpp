#pragma once
// The HDF5 run file, schema version `output_schema_version` (documented in
// docs/output-schema.md). Both solvers write it; the analysis reads it.
#include <hdf5.h>

#include <array>
#include <filesystem>

#include "common/profile.hpp"

namespace shaker {

/// The time-series columns of every run file, whichever solver wrote it.
inline constexpr std::array<const char*, 4> required_series_columns{"t", "phase", "plate_z", "com_z"};

/// Root attribute `kind` of the other HDF5 files a run writes for reading back (the 3D fields
/// file, the checkpoints), which a run file does not have: read_run_file names it in its refusal.
inline constexpr const char* file_kind_attribute = "kind";

/// The root attributes of a run file (docs/output-schema.md): schema version, program
/// version, commit, date, and the record's solver, model variant, configuration and e.
/// Every file a run writes for analysis carries them, so that each says what made it.
/// The current UTC time, ISO 8601 (the `created` attribute of every output).
std::string utc_now();
void write_run_attributes(hid_t file, const RunRecord& record);
/// Writes the record atomically; provenance (schema, version, commit, date) is added here.
/// Throws std::invalid_argument, writing nothing, if the series lacks a required column or a
/// replica's series (RunRecord::replica_series) has other columns than the series.
void write_run_file(const std::filesystem::path& path, const RunRecord& record);
/// Reads a run file; throws InputError naming the file and what is missing or malformed.
RunRecord read_run_file(const std::filesystem::path& path);

/// The group /cycle_samples of a run file (docs/output-schema.md). `ragged`: the phases may
/// hold different numbers of samples (a checkpoint written mid-cycle), the shorter ones padded
/// with empty samples; a run file's phases hold the same number (std::logic_error otherwise).
void write_samples(hid_t file, const CycleSamples& samples, bool ragged);
/// Reads it back for `phases` phases of `bins` bins; InputError if it is malformed, or holds
/// a sum that is not finite.
CycleSamples read_samples(hid_t file, std::size_t phases, std::size_t bins, bool ragged);

}  // namespace shaker
