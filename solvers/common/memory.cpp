#include "common/memory.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "common/errors.hpp"

namespace shaker {

std::uint64_t available_memory() {
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    std::istringstream fields(line);
    std::string name;
    std::uint64_t kib = 0;
    if (fields >> name >> kib && name == "MemAvailable:") return kib * 1024;
  }
  return 0;
}

void check_memory(double bytes, const std::string& what, const std::string& advice) {
  const std::uint64_t available = available_memory();
  if (available == 0 || bytes <= static_cast<double>(available)) return;
  throw InputError(fmt::format("{} needs about {:.3g} bytes, {} bytes available (MemAvailable of "
                               "/proc/meminfo); {}", what, bytes, available, advice));
}

}  // namespace shaker
