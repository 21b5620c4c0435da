#pragma once
// The HDF5 run file, schema version `output_schema_version` (documented in
// docs/output-schema.md). Both solvers write it; the analysis reads it.
#include <array>
#include <filesystem>

#include "common/profile.hpp"

namespace shaker {

/// The time-series columns of every run file, whichever solver wrote it.
inline constexpr std::array<const char*, 4> required_series_columns{"t", "phase", "plate_z", "com_z"};

/// Writes the record atomically; provenance (schema, version, commit, date) is added here.
/// Throws std::invalid_argument, writing nothing, if the series lacks a required column.
void write_run_file(const std::filesystem::path& path, const RunRecord& record);
/// Reads a run file; throws InputError naming the file and what is missing or malformed.
RunRecord read_run_file(const std::filesystem::path& path);

}  // namespace shaker
