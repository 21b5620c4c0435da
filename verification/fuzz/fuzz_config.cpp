// Fuzz target: a case file plus --set overrides, through the checks `shaker md` and
// `shaker continuum` make before any work (schema types and ranges, then the typed case
// settings of both solvers). Bad input must throw shaker::InputError; anything else escaping
// (another exception, a crash, a sanitizer report, a hang) is a finding.
//
// Input: the TOML document, then optional lines "--set KEY=VALUE" (from the first line that
// starts with "--set " on, each such line is one override, applied in order).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/case_parameters.hpp"
#include "common/config.hpp"
#include "common/errors.hpp"
#include "continuum/setup.hpp"
#include "md/protocol.hpp"

namespace {

struct Split {
  std::string document;
  std::vector<std::string> overrides;
};

Split split_input(const std::string& text) {
  Split s;
  const std::string marker = "--set ";
  std::size_t at = text.rfind(marker, 0) == 0 ? 0 : text.find("\n" + marker);
  if (at == std::string::npos) {
    s.document = text;
    return s;
  }
  if (at > 0) ++at;  // keep the document's last newline, start at the marker
  s.document = text.substr(0, at);
  for (std::size_t line = at; line < text.size();) {
    std::size_t end = text.find('\n', line);
    if (end == std::string::npos) end = text.size();
    if (text.compare(line, marker.size(), marker) == 0)
      s.overrides.push_back(text.substr(line + marker.size(), end - line - marker.size()));
    line = end + 1;
  }
  return s;
}

/// Cells of the continuum grid the configuration asks for (2 ghost layers ignored).
double continuum_cells(const shaker::config::Config& c) {
  const double h = c.real("continuum.cell_size");
  const double column = c.real("continuum.ceiling") / h;
  const double across = c.real("continuum.box_width") / h;
  return column * std::pow(across, static_cast<double>(c.integer("continuum.dimension") - 1));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Split input = split_input(std::string(reinterpret_cast<const char*>(data), size));
  try {
    shaker::config::Config config = shaker::config::Config::from_toml(input.document, "fuzz case file");
    for (const auto& assignment : input.overrides) config.set(assignment);
    shaker::CaseParameters::from(config);
    shaker::md::MdSettings::from(config);
    // continuum_case allocates a probe of the whole grid after the memory check against the
    // machine's free memory, which allows far more than the fuzzer's RSS limit: a grid beyond
    // a million cells is a legitimate large run here, not a finding (the memory check itself
    // is a row of verification/programs/bad_input_cases.toml).
    if (continuum_cells(config) <= 1e6) shaker::continuum::continuum_case(config);
    // The stored configuration of an output file is read back with from_toml: it must round-trip.
    shaker::config::Config::from_toml(config.to_toml(), "round trip");
  } catch (const shaker::InputError&) {
  }
  return 0;
}
