#include "md/run_md.hpp"

#include <fmt/format.h>

namespace shaker::md {
int run(const config::Config&) {
  fmt::print(stderr, "shaker md: the event-driven MD solver is not implemented yet (issue 3)\n");
  return 3;
}
}  // namespace shaker::md
