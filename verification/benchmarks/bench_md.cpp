// Collisions per second of the event-driven MD (the project's headline performance figure).
//   bench_md --benchmark_filter=ElasticGas   homogeneous elastic gas, nu = 0.3
//   bench_md --benchmark_filter=BaseCase     the paper's base case in its periodic state
#include <benchmark/benchmark.h>

#include <chrono>
#include <vector>

#include "common/config.hpp"
#include "common/case_parameters.hpp"
#include "md/initial_states.hpp"
#include "md/protocol.hpp"
#include "md/simulation.hpp"

namespace shaker::md {
namespace {

void run_pair_collisions(Simulation& sim, std::uint64_t count) {
  const std::uint64_t target = sim.tally().pair + count;
  while (sim.tally().pair < target) sim.step();
}

void ElasticGas(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Geometry g = periodic_box(n, 0.3);
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, 1.0};
  const QueueKind queue = state.range(1) == 0 ? QueueKind::heap : QueueKind::calendar;
  Simulation sim(g, rules, homogeneous_gas(g, n, 0.3, 1.0, 1), queue);
  run_pair_collisions(sim, 5 * n);  // melt the lattice
  const std::uint64_t batch = 1000000;
  std::uint64_t done = 0;
  for (auto _ : state) {
    run_pair_collisions(sim, batch);
    done += batch;
  }
  state.counters["collisions_per_second"] = benchmark::Counter(static_cast<double>(done), benchmark::Counter::kIsRate);
  state.counters["bytes_per_particle"] = static_cast<double>(sim.bytes_per_particle());
  state.counters["particles"] = static_cast<double>(n);
}
// Second argument: 0 indexed heap, 1 calendar queue (the default).
BENCHMARK(ElasticGas)
    ->ArgsProduct({{4000, 40000, 400000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);

/// The base case after `transient` cycles from the flat layer.
Simulation base_case(Restitution restitution, int transient, QueueKind queue) {
  const ShakerKinematics shaker{3.0, 0.095};
  Geometry g;
  g.plate = shaker;
  CollisionRules rules;
  rules.restitution = restitution;
  Simulation sim(g, rules, flat_layer(g, 3937, 1), queue);
  sim.advance_to(transient / shaker.frequency());
  return sim;
}

/// crossing_heights: counted as `shaker md` counts md.crossing_heights (none: not counted).
void BaseCaseCycle(benchmark::State& state, Restitution restitution, QueueKind queue,
                   std::vector<double> crossing_heights) {
  Simulation sim = base_case(restitution, 10, queue);
  if (!crossing_heights.empty()) sim.start_height_counts(crossing_heights, 0.095);
  const double period = 1.0 / 0.095;
  const std::uint64_t start = sim.tally().collisions();
  for (auto _ : state) sim.advance_to(sim.time() + period);
  state.counters["collisions_per_second"] =
      benchmark::Counter(static_cast<double>(sim.tally().collisions() - start), benchmark::Counter::kIsRate);
  state.counters["collisions_per_cycle"] = benchmark::Counter(
      static_cast<double>(sim.tally().collisions() - start), benchmark::Counter::kAvgIterations);
  state.counters["bytes_per_particle"] = static_cast<double>(sim.bytes_per_particle());
}
// The default queue (calendar), and the heap for comparison; the default crossing height
// counted (what a run pays for it).
BENCHMARK_CAPTURE(BaseCaseCycle, constant_e, Restitution{Restitution::Kind::constant, 0.9}, QueueKind::calendar,
                  std::vector<double>{})
    ->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK_CAPTURE(BaseCaseCycle, constant_e_crossings_z80, Restitution{Restitution::Kind::constant, 0.9},
                  QueueKind::calendar, std::vector<double>{80.0})
    ->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK_CAPTURE(BaseCaseCycle, velocity_dependent_e, Restitution{Restitution::Kind::velocity_dependent, 0.9},
                  QueueKind::calendar, std::vector<double>{})
    ->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK_CAPTURE(BaseCaseCycle, constant_e_heap, Restitution{Restitution::Kind::constant, 0.9},
                  QueueKind::heap, std::vector<double>{})
    ->Unit(benchmark::kMillisecond)->Iterations(5);

/// The whole base-case run as `shaker md` does it: 10 transient + 10 sampled cycles with
/// sampling, series and invariant checks (target: under 15 s).
void BaseCaseFullRun(benchmark::State& state) {
  const config::Config config;
  const CaseParameters parameters = CaseParameters::from(config);
  const MdSettings settings = MdSettings::from(config);
  double collisions = 0.0;
  for (auto _ : state) {
    Geometry g;
    g.height = settings.ceiling;
    g.plate = parameters.shaker;
    CollisionRules rules;
    rules.restitution = parameters.restitution;
    Simulation sim(g, rules, flat_layer(g, 3937, parameters.run.seed), settings.queue);
    const RunOutcome outcome = run_protocol(sim, parameters, settings);
    collisions += static_cast<double>(outcome.collisions);
    state.counters["run_seconds"] = outcome.seconds;
  }
  state.counters["collisions_per_second"] = benchmark::Counter(collisions, benchmark::Counter::kIsRate);
}
BENCHMARK(BaseCaseFullRun)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace shaker::md

BENCHMARK_MAIN();
