#pragma once
// The configuration schema as documentation: `shaker config --describe` (plain text) and
// `shaker config --describe --markdown` (docs/configuration.md is that output), and the units
// beside the values of `shaker config`. Reads only the schema of common/config.hpp.
#include <string>

namespace shaker::config {

/// Every key of the schema, in schema order: type, default, allowed values, units, meaning.
/// Throws std::logic_error if a key declares no units (every key must).
std::string describe_schema(bool markdown);

/// A TOML text of Config::to_toml() with each dimensional key's units as a trailing comment
/// ("frequency = 0.095  # sqrt(g/sigma)"); dimensionless keys ("1...") and "-" are left bare.
std::string annotate_units(const std::string& toml_text);

}  // namespace shaker::config
