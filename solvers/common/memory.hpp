#pragma once
// The memory a run will need, checked against the machine before any work: a grid or a particle
// count too large is bad input (exit 2), not a std::bad_alloc after the output was announced.
#include <cstdint>
#include <string>

namespace shaker {

/// MemAvailable of /proc/meminfo in bytes (0 if it cannot be read).
std::uint64_t available_memory();

/// Throws InputError if `bytes` (an estimate; a double, so that a product of huge counts does
/// not overflow) exceed the available memory: "WHAT needs about N bytes, M bytes available
/// (MemAvailable of /proc/meminfo); ADVICE". Does nothing when MemAvailable is unknown.
void check_memory(double bytes, const std::string& what, const std::string& advice);

}  // namespace shaker
