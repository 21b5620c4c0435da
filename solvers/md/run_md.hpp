#pragma once
#include "common/config.hpp"

namespace shaker::md {
/// Runs `shaker md` on a validated configuration; returns the process exit code.
int run(const config::Config& config);
}  // namespace shaker::md
