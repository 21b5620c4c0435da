#pragma once
// The HDF5 run file, schema version `output_schema_version` (documented in
// docs/output-schema.md). Both solvers write it; the analysis reads it.
#include <filesystem>

#include "common/profile.hpp"

namespace shaker {

/// Writes the record atomically; provenance (schema, version, commit, date) is added here.
void write_run_file(const std::filesystem::path& path, const RunRecord& record);
/// Reads a run file; throws InputError naming the file and what is missing or malformed.
RunRecord read_run_file(const std::filesystem::path& path);

}  // namespace shaker
