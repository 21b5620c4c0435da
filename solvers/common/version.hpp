#pragma once
namespace shaker {
const char* program_version();
const char* git_commit();
/// Version of the HDF5 output layout (docs/output-schema.md); bump on any change.
inline constexpr int output_schema_version = 2;
/// Run files of this version and later are read (older time-series column names are mapped
/// to the present ones).
inline constexpr int oldest_readable_schema_version = 1;
}  // namespace shaker
