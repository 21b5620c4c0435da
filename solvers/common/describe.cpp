#include "common/describe.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cctype>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "common/config.hpp"

namespace shaker::config {
namespace {

std::string type_name(Kind kind) {
  switch (kind) {
    case Kind::real: return "real";
    case Kind::integer: return "integer";
    case Kind::boolean: return "boolean";
    case Kind::text: return "string";
    case Kind::real_list: return "list of reals";
  }
  return "?";
}

/// What values the key accepts, in words.
std::string allowed(const ParameterSpec& spec, bool markdown) {
  const auto quote = [&](const std::string& s) { return markdown ? "`" + s + "`" : s; };
  switch (spec.kind) {
    case Kind::real:
    case Kind::integer: return spec.range.describe();
    case Kind::real_list: return "each element: " + spec.range.describe();
    case Kind::boolean: return "true or false";
    case Kind::text: {
      if (spec.choices.empty()) return "any string";
      std::vector<std::string> quoted;
      for (const auto& c : spec.choices) quoted.push_back(quote(c));
      return "one of " + fmt::format("{}", fmt::join(quoted, ", "));
    }
  }
  return "?";
}

/// What a restart from a checkpoint requires of the key, if anything.
std::string restart_note(const ParameterSpec& spec) {
  const bool md = spec.restart_solvers & restart_md, continuum = spec.restart_solvers & restart_continuum;
  if (!md && !continuum) return "";
  return fmt::format("; a run continued from a checkpoint{} must keep the checkpoint's value",
                     md && continuum ? "" : md ? " of the MD" : " of the continuum");
}

std::string units_of(const ParameterSpec& spec) {
  if (spec.units.empty())
    throw std::logic_error("configuration key " + spec.key + " declares no units");
  return spec.units;
}

std::string section_of(const std::string& key) { return key.substr(0, key.find('.')); }

/// A Markdown table cell: no bare '|', and no '<' that would open an HTML tag ("<h>"); a '<'
/// before a space or digit ("0 < value") stays as it is.
std::string escape_cell(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char next = i + 1 < s.size() ? s[i + 1] : ' ';
    if (s[i] == '|') out += "\\|";
    else if (s[i] == '<' && (std::isalpha(static_cast<unsigned char>(next)) || next == '/' || next == '!'))
      out += "&lt;";
    else out += s[i];
  }
  return out;
}

}  // namespace

std::string describe_schema(bool markdown) {
  std::string out;
  if (markdown) {
    out += "# Configuration keys\n\n"
           "<!-- Generated: do not edit. Regenerate with\n"
           "     build/release/solvers/app/shaker config --describe --markdown > docs/configuration.md\n"
           "     (the test repository.ConfigurationDoc.IsCurrent fails when this file differs). -->\n\n"
           "One TOML file per case; a key not given takes its default, and the defaults are the\n"
           "paper's base case, so an empty file is the base case. Keys are written as `section.name`\n"
           "here and on the command line (`--set section.name=value`), and as `name = value` under\n"
           "`[section]` in a file. Unknown keys, wrong types and values outside the allowed range are\n"
           "rejected (exit status 2). Units are those of [units.md](units.md): lengths in particle\n"
           "diameters sigma, times in sqrt(sigma/g), temperatures in g sigma; `1` marks a dimensionless\n"
           "number (`1 (f t)` a phase, in cycles), `cycles` a number of plate cycles, `-` a value that\n"
           "is not a physical quantity (a name, a file, a choice, a seed, a number of stages).\n";
  }
  std::string section;
  for (const auto& spec : schema()) {
    const std::string units = units_of(spec);
    const std::string meaning = spec.meaning + restart_note(spec);
    const std::string dflt = format_value(spec.default_value);
    if (section_of(spec.key) != section) {
      section = section_of(spec.key);
      if (markdown)
        out += fmt::format("\n## [{}]\n\n| key | type | default | allowed | units | meaning |\n"
                           "| --- | --- | --- | --- | --- | --- |\n",
                           section);
      else
        out += fmt::format("{}[{}]\n", out.empty() ? "" : "\n", section);
    }
    if (markdown) {
      out += fmt::format("| `{}` | {} | `{}` | {} | {} | {} |\n", spec.key, type_name(spec.kind),
                         escape_cell(dflt), escape_cell(allowed(spec, true)), escape_cell(units),
                         escape_cell(meaning));
    } else {
      out += fmt::format("{}\n  type: {}; default: {}; allowed: {}; units: {}\n  {}\n", spec.key,
                         type_name(spec.kind), dflt, allowed(spec, false), units, meaning);
    }
  }
  return out;
}

std::string annotate_units(const std::string& toml_text) {
  std::istringstream in(toml_text);
  std::string out, line, section;
  while (std::getline(in, line)) {
    const auto eq = line.find(" = ");
    if (line.size() > 2 && line.front() == '[' && line.back() == ']') {
      section = line.substr(1, line.size() - 2);
    } else if (eq != std::string::npos && line.find('#') == std::string::npos) {
      const std::string& units = find_spec(section + "." + line.substr(0, eq)).units;
      if (!units.empty() && units[0] != '1' && units != "-") line += "  # " + units;
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace shaker::config
