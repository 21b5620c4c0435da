// Cache lines the MD solver fetches from memory per pair collision, counted by valgrind's cache
// simulation instead of timed: the large-N loss of collisions per second is memory traffic,
// and this count is the same on a quiet and on a loaded machine. The elastic gas of bench_md
// (nu = 0.3, seed 1) is melted for 5 N pair collisions outside the measurement, then `count`
// pair collisions are measured. Run it through md-cache-lines.sh, which sets the simulated
// caches and prints misses per pair collision; on its own it measures nothing.
#include <valgrind/callgrind.h>

#include <cstdio>
#include <cstdlib>

#include "md/initial_states.hpp"
#include "md/simulation.hpp"

int main(int argc, char** argv) {
  using namespace shaker::md;
  if (argc != 3) {
    std::fprintf(stderr, "usage: md_cache_lines N COUNT  (N particles >= 100, COUNT pair collisions >= 1)\n");
    return 2;
  }
  const long n = std::strtol(argv[1], nullptr, 10), count = std::strtol(argv[2], nullptr, 10);
  if (n < 100 || count < 1) {
    std::fprintf(stderr, "md_cache_lines: N = %s (allowed >= 100) and COUNT = %s (allowed >= 1)\n", argv[1], argv[2]);
    return 2;
  }
  const Geometry g = periodic_box(static_cast<std::size_t>(n), 0.3);
  CollisionRules rules;
  rules.restitution = shaker::Restitution{shaker::Restitution::Kind::constant, 1.0};
  Simulation sim(g, rules, homogeneous_gas(g, static_cast<std::size_t>(n), 0.3, 1.0, 1));
  while (sim.tally().pair < 5 * static_cast<std::uint64_t>(n)) sim.step();
  const Tally before = sim.tally();
  CALLGRIND_START_INSTRUMENTATION;
  while (sim.tally().pair < before.pair + static_cast<std::uint64_t>(count)) sim.step();
  CALLGRIND_STOP_INSTRUMENTATION;
  const Tally& after = sim.tally();
  std::printf("N %ld pair %llu cell %llu stale %llu\n", n, static_cast<unsigned long long>(after.pair - before.pair),
              static_cast<unsigned long long>(after.cell - before.cell),
              static_cast<unsigned long long>(after.stale - before.stale));
  return 0;
}
