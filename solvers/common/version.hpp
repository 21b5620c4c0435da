#pragma once
namespace shaker {
const char* program_version();
const char* git_commit();
/// Version of the HDF5 run-file layout (docs/output-schema in README); bump on any change.
inline constexpr int output_schema_version = 1;
}  // namespace shaker
