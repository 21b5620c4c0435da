// Fuzz target: the run-file reader shaker::read_run_file (what `shaker analyze` and
// `shaker compare` read). Its contract: a missing or malformed item throws shaker::InputError;
// anything else escaping (another exception, a crash, a sanitizer report, a hang) is a finding.
// Input: a recipe (hdf5_recipe.hpp) of the run file.
#include <cstdint>

#include "common/errors.hpp"
#include "common/run_file.hpp"
#include "hdf5_recipe.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto path = shaker::fuzz::private_input_file("run-file");
  shaker::fuzz::write_hdf5_recipe(path, data, size);
  try {
    shaker::read_run_file(path);
  } catch (const shaker::InputError&) {
  }
  return 0;
}
