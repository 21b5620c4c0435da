#include "continuum/run_continuum.hpp"

#include <fmt/format.h>

namespace shaker::continuum {
int run(const config::Config&) {
  fmt::print(stderr, "shaker continuum: the continuum solver is not implemented yet (issue 4)\n");
  return 3;
}
}  // namespace shaker::continuum
