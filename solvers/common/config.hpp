#pragma once
// Case configuration: one TOML file per case, every parameter declared once in a schema
// (key, type, default, allowed range, meaning). Loading rejects unknown keys, wrong types and
// out-of-range values with InputError naming the key, the value and the allowed range.
// The effective configuration (defaults + file + --set overrides) serialises back to TOML and
// is stored in every output file.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace shaker::config {

using Value = std::variant<double, std::int64_t, bool, std::string, std::vector<double>>;
enum class Kind { real, integer, boolean, text, real_list };

/// Allowed interval of a number; open or closed at each end.
struct Range {
  double lo = -1e308, hi = 1e308;
  bool lo_open = false, hi_open = false;
  bool contains(double x) const;
  std::string describe() const;
};
Range closed(double lo, double hi);
Range positive(double hi = 1e308);      ///< (0, hi]
Range at_least(double lo, double hi = 1e308);

/// The solvers whose restart from a checkpoint keeps a key (ParameterSpec::kept_on_restart).
enum RestartSolvers : unsigned { restart_md = 1u, restart_continuum = 2u };

struct ParameterSpec {
  std::string key;  ///< "section.name"
  Kind kind;
  Value default_value;
  Range range;                       ///< numbers and each element of a list
  std::vector<std::string> choices;  ///< text: allowed values (empty: any text)
  std::string meaning;               ///< what it controls
  std::string units = {};  ///< docs/units.md: "sigma", "g sigma", ...; "1" dimensionless; "-" no quantity
  /// RestartSolvers whose run continued from a checkpoint must state the checkpoint's value.
  unsigned restart_solvers = 0;
  /// Declares the units: real("md.tc", ...).in("sqrt(sigma/g)"); every key has them.
  ParameterSpec in(std::string u) && {
    units = std::move(u);
    return std::move(*this);
  }
  /// Declares that a restart of these solvers keeps the key: .kept_on_restart(restart_md).
  ParameterSpec kept_on_restart(unsigned solvers) && {
    restart_solvers = solvers;
    return std::move(*this);
  }
};

// Builders keep the schema tables short and readable.
ParameterSpec real(std::string key, double dflt, Range range, std::string meaning);
ParameterSpec integer(std::string key, std::int64_t dflt, Range range, std::string meaning);
ParameterSpec boolean(std::string key, bool dflt, std::string meaning);
ParameterSpec text(std::string key, std::string dflt, std::vector<std::string> choices,
                   std::string meaning);
ParameterSpec real_list(std::string key, std::vector<double> dflt, Range range,
                        std::string meaning);

/// The whole schema: common keys, then the MD and continuum sections.
const std::vector<ParameterSpec>& schema();
// Each part of the schema is declared beside the code that reads it.
std::vector<ParameterSpec> common_parameters();
std::vector<ParameterSpec> md_parameters();
std::vector<ParameterSpec> continuum_parameters();

std::string format_value(const Value& value);  ///< TOML literal

class Config {
 public:
  /// Defaults only.
  Config();
  /// Defaults, then the file (if non-empty path), then "key=value" overrides in order.
  static Config load(const std::filesystem::path& file, const std::vector<std::string>& overrides);
  /// Parses a TOML document given as text (used for configurations stored in output files).
  static Config from_toml(const std::string& toml_text, const std::string& origin);

  /// Applies one "key=value" override (--set); throws InputError.
  void set(const std::string& assignment);
  void set_value(const std::string& key, const Value& value);

  double real(const std::string& key) const;
  std::int64_t integer(const std::string& key) const;
  bool boolean(const std::string& key) const;
  const std::string& text(const std::string& key) const;
  const std::vector<double>& real_list(const std::string& key) const;

  /// The full effective configuration as TOML, every key of the schema, in schema order.
  std::string to_toml() const;
  /// The value of `key` as a TOML literal.
  std::string value_text(const std::string& key) const { return format_value(values_.at(key)); }
  /// A short stable hash of to_toml(), for reusing finished runs.
  std::string hash() const;

 private:
  const Value& get(const std::string& key, Kind kind) const;
  std::map<std::string, Value> values_;
};

/// The restart rule (docs/output-schema.md): a run of `solver` (RestartSolvers) continued from
/// a checkpoint must state the values that the checkpoint's run had (its stored configuration,
/// `saved_toml`) of every key the schema declares kept on its restart; a difference is refused
/// with InputError naming the key and both values.
void require_same_keys(const Config& now, const std::string& saved_toml, RestartSolvers solver,
                       const std::string& checkpoint);

const ParameterSpec& find_spec(const std::string& key);  ///< throws InputError if unknown

}  // namespace shaker::config
