#pragma once
#include <vector>

#include "common/config.hpp"
#include "common/output_paths.hpp"
#include "common/progress.hpp"

namespace shaker::md {
/// Runs `shaker md` on a validated configuration; returns the process exit code.
/// Runs the case. `inputs` are files read besides those the configuration names (the case
/// file): no output may overwrite one of them. Bad input throws InputError before any work.
/// Progress goes to stderr as `progress` says.
int run(const config::Config& config, const std::vector<NamedPath>& inputs = {},
        const ProgressSettings& progress = {});
}  // namespace shaker::md
