#pragma once
#include "common/config.hpp"

namespace shaker::continuum {
/// Runs `shaker continuum` on a validated configuration; returns the process exit code.
int run(const config::Config& config);
}  // namespace shaker::continuum
