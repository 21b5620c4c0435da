#include "common/config.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <toml.hpp>

#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/output_paths.hpp"

namespace shaker::config {

// ---- Ranges and builders ----------------------------------------------------------------

bool Range::contains(double x) const {
  if (!std::isfinite(x)) return false;
  const bool above = lo_open ? x > lo : x >= lo;
  const bool below = hi_open ? x < hi : x <= hi;
  return above && below;
}

std::string Range::describe() const {
  const bool has_lo = lo > -1e307, has_hi = hi < 1e307;
  std::string s;
  if (has_lo) s += fmt::format("{} {} ", lo, lo_open ? "<" : "<=");
  s += "value";
  if (has_hi) s += fmt::format(" {} {}", hi_open ? "<" : "<=", hi);
  return s;
}

Range closed(double lo, double hi) { return Range{lo, hi, false, false}; }
Range positive(double hi) { return Range{0.0, hi, true, false}; }
Range at_least(double lo, double hi) { return Range{lo, hi, false, false}; }

ParameterSpec real(std::string key, double dflt, Range range, std::string meaning) {
  return {std::move(key), Kind::real, dflt, range, {}, std::move(meaning)};
}
ParameterSpec integer(std::string key, std::int64_t dflt, Range range, std::string meaning) {
  return {std::move(key), Kind::integer, dflt, range, {}, std::move(meaning)};
}
ParameterSpec boolean(std::string key, bool dflt, std::string meaning) {
  return {std::move(key), Kind::boolean, dflt, {}, {}, std::move(meaning)};
}
ParameterSpec text(std::string key, std::string dflt, std::vector<std::string> choices,
                   std::string meaning) {
  return {std::move(key), Kind::text, std::move(dflt), {}, std::move(choices), std::move(meaning)};
}
ParameterSpec real_list(std::string key, std::vector<double> dflt, Range range,
                        std::string meaning) {
  return {std::move(key), Kind::real_list, std::move(dflt), range, {}, std::move(meaning)};
}

const std::vector<ParameterSpec>& schema() {
  static const std::vector<ParameterSpec> all = [] {
    std::vector<ParameterSpec> specs = common_parameters();
    for (auto& part : {md_parameters(), continuum_parameters()})
      specs.insert(specs.end(), part.begin(), part.end());
    return specs;
  }();
  return all;
}

namespace {

/// Keys and values of earlier versions, with what replaced them: a case file that still holds
/// one is refused with the new key's name; a configuration stored in an older output file
/// skips them (they named that run's files, not its physics).
struct Retired {
  const char* key;
  const char* value;  ///< nullptr: any value
  const char* instead;
};
constexpr const char* restart_key = "run.restart_from = FILE (the checkpoint to continue from; nothing else is needed)";
constexpr const char* checkpoint_key = "run.checkpoint = FILE (where the final, periodic and stop-signal checkpoints go)";
constexpr Retired retired_keys[] = {
    {"md.checkpoint", nullptr, restart_key},
    {"continuum.restart", nullptr, restart_key},
    {"md.initial_state", "checkpoint", restart_key},
    {"md.checkpoint_output", nullptr, checkpoint_key},
    {"continuum.checkpoint", nullptr, checkpoint_key},
};

const Retired* retired(const std::string& key, const std::string* value) {
  for (const Retired& r : retired_keys)
    if (key == r.key && (r.value == nullptr || (value != nullptr && *value == r.value))) return &r;
  return nullptr;
}

}  // namespace

const ParameterSpec& find_spec(const std::string& key) {
  if (const Retired* r = retired(key, nullptr))
    throw InputError(fmt::format("configuration key '{}' was replaced: use {}", key, r->instead));
  const auto& specs = schema();
  const auto it =
      std::find_if(specs.begin(), specs.end(), [&](const auto& s) { return s.key == key; });
  if (it == specs.end()) {
    // Name the section's keys so that a typo is easy to fix.
    const std::string section = key.substr(0, key.find('.'));
    std::vector<std::string> known;
    for (const auto& s : specs)
      if (s.key.rfind(section + ".", 0) == 0) known.push_back(s.key);
    throw InputError(fmt::format("unknown configuration key '{}'{}", key,
                                 known.empty() ? std::string(" (no such section)")
                                               : fmt::format(" (known in [{}]: {})", section,
                                                             fmt::join(known, ", "))));
  }
  return *it;
}

// ---- Values -------------------------------------------------------------------------------

namespace {

std::string kind_name(Kind kind) {
  switch (kind) {
    case Kind::real: return "a real number";
    case Kind::integer: return "an integer";
    case Kind::boolean: return "true or false";
    case Kind::text: return "a string";
    case Kind::real_list: return "a list of real numbers";
  }
  return "?";
}

/// A TOML basic string: quotes, backslashes and control characters escaped, so that any
/// text (a Windows path, a name with quotes) reads back unchanged.
std::string quote_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
          out += fmt::format("\\u{:04X}", static_cast<unsigned char>(c));
        else
          out += c;
    }
  }
  return out + "\"";
}

std::string format_real(double x) {
  std::string s = fmt::format("{}", x);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // TOML floats need a dot
  return s;
}

void check_range(const ParameterSpec& spec, double x, const std::string& shown) {
  if (!spec.range.contains(x))
    throw InputError(fmt::format("configuration key '{}' = {} is out of range (allowed: {})",
                                 spec.key, shown, spec.range.describe()));
}

/// Checks a value against its spec and returns it in the spec's own type.
Value validate(const ParameterSpec& spec, Value value) {
  if (spec.kind == Kind::real && std::holds_alternative<std::int64_t>(value))
    value = static_cast<double>(std::get<std::int64_t>(value));
  const bool right_type = value.index() == spec.default_value.index();
  if (!right_type)
    throw InputError(fmt::format("configuration key '{}' = {} has the wrong type (expected {})",
                                 spec.key, format_value(value), kind_name(spec.kind)));
  switch (spec.kind) {
    case Kind::real: check_range(spec, std::get<double>(value), format_value(value)); break;
    case Kind::integer:
      check_range(spec, static_cast<double>(std::get<std::int64_t>(value)), format_value(value));
      break;
    case Kind::real_list:
      for (double x : std::get<std::vector<double>>(value)) check_range(spec, x, format_real(x));
      break;
    case Kind::text: {
      const auto& s = std::get<std::string>(value);
      if (const Retired* r = retired(spec.key, &s))
        throw InputError(fmt::format("configuration key '{}' = \"{}\" was replaced: use {}", spec.key, s,
                                     r->instead));
      if (!spec.choices.empty() &&
          std::find(spec.choices.begin(), spec.choices.end(), s) == spec.choices.end())
        throw InputError(fmt::format("configuration key '{}' = \"{}\" is not allowed (allowed: {})",
                                     spec.key, s, fmt::join(spec.choices, ", ")));
      break;
    }
    case Kind::boolean: break;
  }
  return value;
}

Value from_toml_value(const std::string& key, const toml::value& v) {
  if (v.is_floating()) return v.as_floating();
  if (v.is_integer()) return static_cast<std::int64_t>(v.as_integer());
  if (v.is_boolean()) return v.as_boolean();
  if (v.is_string()) return v.as_string().str;
  if (v.is_array()) {
    std::vector<double> xs;
    for (const auto& x : v.as_array()) {
      if (x.is_floating()) xs.push_back(x.as_floating());
      else if (x.is_integer()) xs.push_back(static_cast<double>(x.as_integer()));
      else
        throw InputError(fmt::format(
            "configuration key '{}' has the wrong type (expected a list of real numbers)", key));
    }
    return xs;
  }
  throw InputError(fmt::format("configuration key '{}' has an unsupported type", key));
}

/// Flattens nested tables to dotted keys.
void flatten(const toml::value& table, const std::string& prefix,
             std::vector<std::pair<std::string, toml::value>>& out) {
  for (const auto& [name, v] : table.as_table()) {
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    if (v.is_table()) flatten(v, key, out);
    else out.emplace_back(key, v);
  }
}

template <class T> bool parse_number(const std::string& s, T& out) {
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && ptr == end;
}

/// Deepest nesting in a TOML text: arrays and inline tables, plus the components of a dotted
/// key or table header (a.b.c is a table in a table), with strings and comments skipped as
/// TOML delimits them (basic "...", literal '...', multi-line """...""" and '''...''').
/// toml11 parses nesting by recursion (a hostile depth overflows the stack) and slows down
/// quadratically with a key's components (docs/performance.md), so texts deeper than
/// max_toml_nesting are refused before parsing.
constexpr int max_toml_nesting = 32;
int toml_nesting(const std::string& text) {
  int depth = 0, deepest = 0, key_dots = 0;
  const std::size_t size = text.size();
  for (std::size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      const std::string quotes(3, c);
      const bool multi_line = text.compare(i, 3, quotes) == 0;
      for (i += multi_line ? 3 : 1; i < size; ++i) {
        if (c == '"' && text[i] == '\\') {
          ++i;  // an escape: the next character is content
        } else if (multi_line ? text.compare(i, 3, quotes) == 0 : text[i] == c) {
          // A multi-line string may hold up to two quotes right before its closing three: the
          // whole run of quotes ends it.
          if (multi_line)
            while (i + 1 < size && text[i + 1] == c) ++i;
          break;
        } else if (!multi_line && text[i] == '\n') {
          break;  // an unterminated one-line string: toml11 stops there
        }
      }
      continue;  // a quoted key component keeps the dotted-key count going
    }
    if (c == '#') {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
      key_dots = 0;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      key_dots = 0;
    } else if (c == ']' || c == '}') {
      --depth;
      key_dots = 0;
    } else if (c == '.') {
      deepest = std::max(deepest, depth + ++key_dots);
    } else if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == ' ' || c == '\t')) {
      key_dots = 0;  // '=', ',', a newline...: the end of a key
    }
  }
  return deepest;
}

/// Offset of the first byte that does not begin a valid UTF-8 sequence (overlong forms,
/// surrogates and code points above U+10FFFF are invalid), or npos.
std::size_t invalid_utf8_at(const std::string& text) {
  const auto byte = [&](std::size_t i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(text[i])); };
  for (std::size_t i = 0; i < text.size();) {
    const std::uint32_t lead = byte(i);
    std::size_t length = 1;
    std::uint32_t code = lead, smallest = 0;
    if (lead >= 0x80) {
      if ((lead & 0xE0) == 0xC0) length = 2, code = lead & 0x1F, smallest = 0x80;
      else if ((lead & 0xF0) == 0xE0) length = 3, code = lead & 0x0F, smallest = 0x800;
      else if ((lead & 0xF8) == 0xF0) length = 4, code = lead & 0x07, smallest = 0x10000;
      else return i;
      if (i + length > text.size()) return i;
      for (std::size_t k = 1; k < length; ++k) {
        if ((byte(i + k) & 0xC0) != 0x80) return i;
        code = (code << 6) | (byte(i + k) & 0x3F);
      }
      if (code < smallest || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return i;
    }
    i += length;
  }
  return std::string::npos;
}

/// The checks made before toml11 sees a text: UTF-8 (TOML requires it, and toml11's report of
/// an invalid sequence in a literal string reads past the end of its buffer: it rewinds a copy
/// of the location to an iterator of the original), then the nesting depth.
void check_before_parsing(const std::string& text, const std::string& origin) {
  if (const std::size_t at = invalid_utf8_at(text); at != std::string::npos)
    throw InputError(fmt::format("{}: not valid UTF-8 at byte {} (line {}, byte 0x{:02x}); allowed: "
                                 "UTF-8 text, as TOML requires", origin, at,
                                 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'),
                                 static_cast<unsigned char>(text[at])));
  const int depth = toml_nesting(text);
  if (depth > max_toml_nesting)
    throw InputError(fmt::format("{}: arrays, tables or dotted-key parts nested {} deep; allowed: at most {}",
                                 origin, depth, max_toml_nesting));
}

/// The value of "key = RAW" read as TOML, or nothing if RAW is not a TOML value.
std::optional<toml::value> toml_value(const std::string& raw) {
  try {
    std::istringstream in("value = " + raw + "\n");
    const toml::value document = toml::parse(in, "--set");
    if (document.as_table().size() == 1) return toml::find(document, "value");
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

Value parse_override(const ParameterSpec& spec, const std::string& raw) {
  check_before_parsing(raw, fmt::format("--set {}", spec.key));
  // A TOML value ("foo" with its quotes, 1e-6, [10, 20.5], true) is read as TOML; a bare word
  // is a string for text keys, and numbers and lists keep the plain forms below (80,90).
  if (const auto v = toml_value(raw)) {
    if (spec.kind == Kind::text) {
      if (v->is_string()) return v->as_string().str;
    } else if (spec.kind != Kind::real_list || v->is_array() || v->is_string()) {
      return from_toml_value(spec.key, *v);
    }
  }
  auto bad = [&] {
    return InputError(fmt::format("--set {}={}: cannot read '{}' as {}", spec.key, raw, raw,
                                  kind_name(spec.kind)));
  };
  switch (spec.kind) {
    case Kind::real: {
      double x;
      if (!parse_number(raw, x)) throw bad();
      return x;
    }
    case Kind::integer: {
      std::int64_t x;
      if (!parse_number(raw, x)) throw bad();
      return x;
    }
    case Kind::boolean:
      if (raw == "true") return true;
      if (raw == "false") return false;
      throw bad();
    case Kind::text: return raw;
    case Kind::real_list: {
      std::string body = raw;
      std::erase_if(body, [](char c) { return c == '[' || c == ']' || c == ' '; });
      std::vector<double> xs;
      std::stringstream ss(body);
      for (std::string item; std::getline(ss, item, ',');) {
        double x;
        if (!parse_number(item, x)) throw bad();
        xs.push_back(x);
      }
      return xs;
    }
  }
  throw bad();
}

}  // namespace

std::string format_value(const Value& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using V = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<V, double>) return format_real(v);
        else if constexpr (std::is_same_v<V, std::int64_t>) return fmt::format("{}", v);
        else if constexpr (std::is_same_v<V, bool>) return v ? "true" : "false";
        else if constexpr (std::is_same_v<V, std::string>) return quote_string(v);
        else {
          std::vector<std::string> items;
          for (double x : v) items.push_back(format_real(x));
          return fmt::format("[{}]", fmt::join(items, ", "));
        }
      },
      value);
}

// ---- Config -------------------------------------------------------------------------------

Config::Config() {
  for (const auto& spec : schema()) values_[spec.key] = spec.default_value;
}

namespace {
/// `stored`: a configuration stored in an output file, which may hold retired keys.
Config parse_document(std::istream& in, const std::string& origin, bool stored) {
  toml::value document;
  try {
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    check_before_parsing(text, origin);
    std::istringstream copy(text);
    document = toml::parse(copy, origin);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& error) {
    throw InputError(fmt::format("{}: not valid TOML:\n{}", origin, error.what()));
  }
  std::vector<std::pair<std::string, toml::value>> entries;
  flatten(document, "", entries);
  std::sort(entries.begin(), entries.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  Config config;
  for (const auto& [key, v] : entries) {
    if (stored && retired(key, v.is_string() ? &v.as_string().str : nullptr)) continue;
    try {
      config.set_value(key, from_toml_value(key, v));
    } catch (const InputError& error) {
      throw InputError(fmt::format("{}: {}", origin, error.what()));
    }
  }
  return config;
}
}  // namespace

Config Config::load(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  Config config;
  if (!file.empty()) {
    if (std::filesystem::is_directory(file))
      throw InputError(fmt::format("configuration file '{}' is a directory: give the case file (TOML)",
                                   file.string()));
    check_input_file({"configuration file", file});
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(fmt::format("cannot open configuration file '{}'", file.string()));
    config = parse_document(in, file.string(), false);
  }
  for (const auto& assignment : overrides) config.set(assignment);
  return config;
}

Config Config::from_toml(const std::string& toml_text, const std::string& origin) {
  std::istringstream in(toml_text);
  return parse_document(in, origin, true);
}

void Config::set(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set '{}': expected key=value", assignment));
  const std::string key = assignment.substr(0, eq);
  const auto& spec = find_spec(key);
  values_[key] = validate(spec, parse_override(spec, assignment.substr(eq + 1)));
}

void Config::set_value(const std::string& key, const Value& value) {
  values_[key] = validate(find_spec(key), value);
}

const Value& Config::get(const std::string& key, Kind kind) const {
  const auto& spec = find_spec(key);
  if (spec.kind != kind)
    throw std::logic_error(fmt::format("configuration key '{}' read as the wrong type", key));
  return values_.at(key);
}

double Config::real(const std::string& key) const { return std::get<double>(get(key, Kind::real)); }
std::int64_t Config::integer(const std::string& key) const {
  return std::get<std::int64_t>(get(key, Kind::integer));
}
bool Config::boolean(const std::string& key) const {
  return std::get<bool>(get(key, Kind::boolean));
}
const std::string& Config::text(const std::string& key) const {
  return std::get<std::string>(get(key, Kind::text));
}
const std::vector<double>& Config::real_list(const std::string& key) const {
  return std::get<std::vector<double>>(get(key, Kind::real_list));
}

std::string Config::to_toml() const {
  std::string out;
  std::string section;
  for (const auto& spec : schema()) {
    const auto dot = spec.key.find('.');
    const std::string this_section = spec.key.substr(0, dot);
    if (this_section != section) {
      out += fmt::format("{}[{}]\n", out.empty() ? "" : "\n", this_section);
      section = this_section;
    }
    out += fmt::format("{} = {}\n", spec.key.substr(dot + 1), format_value(values_.at(spec.key)));
  }
  return out;
}

std::string Config::hash() const {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a, 64 bit
  for (unsigned char c : to_toml()) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return fmt::format("{:016x}", h);
}

void require_same_keys(const Config& now, const std::string& saved_toml, RestartSolvers solver,
                       const std::string& checkpoint) {
  Config saved;
  try {
    saved = Config::from_toml(saved_toml, "its stored configuration");
  } catch (const InputError& error) {
    throw InputError(fmt::format("{} is not a valid checkpoint: {}", checkpoint, error.what()));
  }
  for (const ParameterSpec& spec : schema()) {
    if (!(spec.restart_solvers & solver)) continue;
    const std::string& key = spec.key;
    if (now.value_text(key) != saved.value_text(key))
      throw InputError(fmt::format(
          "{} = {} but the checkpoint {} was written with {} = {}; a restart keeps the checkpoint's "
          "{}: allowed: {} = {} (or start a new run without the checkpoint)", key,
          now.value_text(key), checkpoint, key, saved.value_text(key), key, key,
          saved.value_text(key)));
  }
}

}  // namespace shaker::config
