#pragma once
#include <vector>

#include "common/config.hpp"
#include "common/hdf5_file.hpp"

namespace shaker::md {
/// Runs `shaker md` on a validated configuration; returns the process exit code.
/// Runs the case. `inputs` are files read besides those the configuration names (the case
/// file): no output may overwrite one of them. Bad input throws InputError before any work.
int run(const config::Config& config, const std::vector<NamedPath>& inputs = {});
}  // namespace shaker::md
