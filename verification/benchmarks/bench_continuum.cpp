// Continuum solver throughput: cell updates per second (cells x steps / wall time), one cycle
// of the 1D base case at 0.1 sigma (paper transport), a slice of a cycle of the 3D base case
// (11 x 11 x 80 at 0.5 sigma) with its per-cycle estimate, and memory per 3D cell measured
// from the heap (mallinfo2) around the solver's construction; and, run under `mpirun -np P`,
// the decomposed 3D box's weak scaling (BM_Continuum3D_DecomposedBlock, docs/parallel.md).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/ranks.hpp"
#include "continuum/halo.hpp"
#include "continuum/setup.hpp"

namespace {

using namespace shaker;

continuum::ContinuumCase base_case(int dimension, double h, const char* transport,
                                   const char* diffusion = "auto", int stages = 2) {
  config::Config c;
  c.set(std::string("continuum.diffusion_integrator=") + diffusion);
  c.set("continuum.integrator_stages=" + std::to_string(stages));
  c.set("continuum.dimension=" + std::to_string(dimension));
  c.set("continuum.cell_size=" + std::to_string(h));
  c.set(std::string("continuum.transport=") + transport);
  return continuum::continuum_case(c);
}

/// Times `make()`'s solver advancing to t_end, `cycles` cycles of the case, per iteration.
template <class MakeSolver>
void time_cycles(benchmark::State& state, const continuum::ContinuumCase& c, MakeSolver make,
                 double t_end, double cycles) {
  double seconds = 0, steps = 0, cpu_seconds = 0, rejected = 0, communication = 0;
  bool decomposed = false;
  for (auto _ : state) {
    state.PauseTiming();
    continuum::TimeIntegrator solver = make();
    state.ResumeTiming();
    const continuum::Halo* halo = solver.op().halo();
    decomposed = halo != nullptr;
    const double communicated = halo ? halo->communication_seconds() : 0.0;
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    solver.advance_to(t_end);
    cpu_seconds += static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    communication += halo ? halo->communication_seconds() - communicated : 0.0;
    steps += static_cast<double>(solver.counters().steps);
    rejected += static_cast<double>(solver.counters().rejected_steps);
  }
  const double cells = static_cast<double>(c.grid.interior_cells());
  const double per_cycle = 1.0 / (static_cast<double>(state.iterations()) * cycles);
  state.counters["cell_updates_per_second"] = benchmark::Counter(cells * steps / seconds);
  state.counters["steps_per_cycle"] = steps * per_cycle;
  state.counters["rejected_steps_per_cycle"] = rejected * per_cycle;
  state.counters["seconds_per_cycle"] = seconds * per_cycle;
  state.counters["cells"] = cells;
  // The machine is shared: process CPU seconds per cycle compare across runs under load.
  state.counters["cpu_seconds_per_cycle"] = cpu_seconds * per_cycle;
  // Rank 0's time in messages and reductions, waiting for the other ranks included.
  if (decomposed) state.counters["communication_fraction"] = communication / seconds;
}

/// The first `fraction` of a cycle from the case's initial state (the flat layer at rest).
void run_fraction(benchmark::State& state, const continuum::ContinuumCase& c, double fraction) {
  time_cycles(state, c, [&] { return continuum::make_solver(c); },
              fraction * c.parameters.shaker.period(), fraction);
}

void BM_Continuum1D_BaseCase_Paper(benchmark::State& state) {
  run_fraction(state, base_case(1, 0.1, "paper"), 1.0);
}
BENCHMARK(BM_Continuum1D_BaseCase_Paper)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// The same with the diffusive terms backward-Euler (Strang split): the step is then the
// acoustic limit of the packed layer on the plate instead of the explicit diffusive one.
void BM_Continuum1D_BaseCase_PaperImplicitDiffusion(benchmark::State& state) {
  run_fraction(state, base_case(1, 0.1, "paper", "implicit"), 1.0);
}
BENCHMARK(BM_Continuum1D_BaseCase_PaperImplicitDiffusion)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// The integrator that meets the 2 s per cycle asked of the 1D base case: SSP-RK(s,2) (s right-hand sides per step,
// a step s - 1 times Heun's at the same Courant number per stage) with the diffusive half
// steps backward Euler, Richardson-extrapolated to second order (3 solves each). Its base-case
// quantities against the case's own configuration:
// grid-studies.NightlyRealProblem/FastIntegrators.
void BM_Continuum1D_BaseCase_PaperExtrapolatedImplicitStages(benchmark::State& state) {
  run_fraction(state,
               base_case(1, 0.1, "paper", "implicit_extrapolated", static_cast<int>(state.range(0))), 1.0);
}
BENCHMARK(BM_Continuum1D_BaseCase_PaperExtrapolatedImplicitStages)
    ->Arg(2)->Arg(4)->Arg(10)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// Full transport with plain backward-Euler diffusion (the default until the extrapolated step
// replaced it; kept under its name so that its history stays comparable) and with the
// default, the extrapolated step (3 solves per diffusive half step instead of 1).
void BM_Continuum1D_BaseCase_Full(benchmark::State& state) {
  run_fraction(state, base_case(1, 0.1, "full", "implicit"), 1.0);
}
BENCHMARK(BM_Continuum1D_BaseCase_Full)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_Continuum1D_BaseCase_FullExtrapolatedImplicit(benchmark::State& state) {
  run_fraction(state, base_case(1, 0.1, "full", "implicit_extrapolated"), 1.0);
}
BENCHMARK(BM_Continuum1D_BaseCase_FullExtrapolatedImplicit)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// The base case in its periodic state, as the users run it (10 transient cycles, then sampled
// ones): the first cycle from the flat layer at rest costs several times a periodic one (the
// packed layer's sound speed sets the step until the layer first leaves the plate), so the
// figures above overstate a cycle. The periodic state is reached once per cell size with
// paper transport, the extrapolated implicit diffusion and SSP-RK(4,2) (the fast setting that
// agrees with the reference, grid-studies.NightlyRealProblem/FastIntegrators) over `transient`
// cycles; every benchmark below starts from that state, which all integrators share to within the
// grid uncertainty, and times one whole cycle.
constexpr int transient_cycles = 8;

const continuum::State& periodic_column(double h) {
  static std::map<double, continuum::State> states;
  auto found = states.find(h);
  if (found != states.end()) return found->second;
  continuum::TimeIntegrator column = continuum::make_solver(base_case(1, h, "paper", "implicit_extrapolated", 4));
  column.advance_to(transient_cycles * column.op().settings().shaker.period());
  return states.emplace(h, column.state()).first->second;
}

/// Sets every column of `solver`'s box (or block) to the 1D `column` state of the same cell size.
void every_column_from(const continuum::State& column, continuum::TimeIntegrator& solver) {
  const continuum::Grid& g = solver.op().grid();
  const continuum::Grid column_grid = continuum::make_grid(1, 1.0, 1.0, g.height(), g.h);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        for (int v = 0; v < continuum::variable_count; ++v)
          solver.state().q[v][g.index(i, j, k)] = column.q[v][column_grid.index(0, 0, k)];
}

/// Times one cycle (or its first `fraction`) from the periodic state of the column at the case's cell size; in 3D every
/// column of the box starts as that column (a horizontally uniform state, which the 3D
/// solver keeps to round-off: test Uniform3D.MatchesOneDimensionalRunToRoundOff). Under
/// `mpirun -np P` the box is decomposed over the P ranks and each fills its own block.
void run_periodic_cycle(benchmark::State& state, const continuum::ContinuumCase& c, double fraction = 1.0) {
  const continuum::State& column = periodic_column(c.grid.h);
  const double period = c.parameters.shaker.period();
  const auto halo = c.grid.dimension == 3 && launched_by_mpi()
                        ? std::make_shared<const continuum::Halo>(c.grid, Ranks::world().size())
                        : nullptr;
  const auto from_periodic_state = [&] {
    continuum::TimeIntegrator solver = continuum::make_solver(c, halo);
    every_column_from(column, solver);
    solver.set_time(transient_cycles * period);
    if (halo) MPI_Barrier(MPI_COMM_WORLD);
    return solver;
  };
  time_cycles(state, c, from_periodic_state, (transient_cycles + fraction) * period, fraction);
  state.counters["ranks"] = halo ? halo->size() : 1;
}

// The integrators of the from-rest benchmarks above, and paper transport with explicit
// diffusion and SSP-RK(10,2), which gives the default's answer (Heun, s = 2) within the grid
// uncertainty (grid-studies.NightlyRealProblem/FastIntegrators.*/paper_explicit_s10).
void BM_Continuum1D_PeriodicCycle_PaperStages(benchmark::State& state) {
  run_periodic_cycle(state, base_case(1, 0.1, "paper", "explicit", static_cast<int>(state.range(0))));
}
BENCHMARK(BM_Continuum1D_PeriodicCycle_PaperStages)
    ->Arg(2)->Arg(10)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_Continuum1D_PeriodicCycle_PaperImplicitDiffusion(benchmark::State& state) {
  run_periodic_cycle(state, base_case(1, 0.1, "paper", "implicit"));
}
BENCHMARK(BM_Continuum1D_PeriodicCycle_PaperImplicitDiffusion)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_Continuum1D_PeriodicCycle_PaperExtrapolatedImplicitStages(benchmark::State& state) {
  run_periodic_cycle(state, base_case(1, 0.1, "paper", "implicit_extrapolated", static_cast<int>(state.range(0))));
}
BENCHMARK(BM_Continuum1D_PeriodicCycle_PaperExtrapolatedImplicitStages)
    ->Arg(2)->Arg(4)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_Continuum1D_PeriodicCycle_Full(benchmark::State& state) {
  run_periodic_cycle(state, base_case(1, 0.1, "full", "implicit"));
}
BENCHMARK(BM_Continuum1D_PeriodicCycle_Full)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_Continuum1D_PeriodicCycle_FullExtrapolatedImplicit(benchmark::State& state) {
  run_periodic_cycle(state, base_case(1, 0.1, "full", "implicit_extrapolated"));
}
BENCHMARK(BM_Continuum1D_PeriodicCycle_FullExtrapolatedImplicit)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// One whole cycle of the 3D base case (11 x 11 x 80 at 0.5 sigma) on every core OpenMP is
// given (OMP_NUM_THREADS; the machine's 2 by default): paper transport with explicit
// diffusion and SSP-RK(s,2), s = 2 (Heun, the default) and 10 (the same answer in 1D at cell
// 0.1, where the step is 3 times the 3D one: FastIntegrators.*/paper_explicit_s10). A cycle
// takes minutes: three repetitions, whatever the command line asks (the nightly asks nine).
void BM_Continuum3D_PeriodicCycle_PaperStages(benchmark::State& state) {
  run_periodic_cycle(state, base_case(3, 0.5, "paper", "explicit", static_cast<int>(state.range(0))));
}
BENCHMARK(BM_Continuum3D_PeriodicCycle_PaperStages)
    ->Arg(2)->Arg(10)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->UseRealTime();

// The first tenth of that cycle: a run short enough to alternate old and new binaries in one session when a kernel changes.
void BM_Continuum3D_PeriodicCycleSlice_PaperStages(benchmark::State& state) {
  run_periodic_cycle(state, base_case(3, 0.5, "paper", "explicit", static_cast<int>(state.range(0))), 0.1);
}
BENCHMARK(BM_Continuum3D_PeriodicCycleSlice_PaperStages)
    ->Arg(10)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_Continuum3D_PeriodicCycleSlice_PaperRkl2Stages(benchmark::State& state) {
  run_periodic_cycle(state, base_case(3, 0.5, "paper", "rkl2", static_cast<int>(state.range(0))), 0.1);
}
BENCHMARK(BM_Continuum3D_PeriodicCycleSlice_PaperRkl2Stages)
    ->Arg(10)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// One evaluation of the right-hand side (every term: inviscid and viscous fluxes, closure,
// sources) of that box at the periodic state's phase 0 in one process, repeated: its short
// iterations average over a noisy machine, so a kernel's old and new versions can be compared
// in minutes. The counter is cell updates per second of a single stage.
void BM_Continuum3D_OperatorRhs(benchmark::State& state) {
  const continuum::ContinuumCase c = base_case(3, 0.5, "paper", "explicit", 10);
  continuum::TimeIntegrator solver = continuum::make_solver(c);
  every_column_from(periodic_column(c.grid.h), solver);
  const continuum::Grid& g = solver.op().grid();
  continuum::State dUdt;
  dUdt.resize(g.size());
  const double t = transient_cycles * c.parameters.shaker.period();
  for (auto _ : state) {
    solver.op().rhs(t, solver.state(), dUdt);
    benchmark::DoNotOptimize(dUdt.q[0].data());
  }
  state.counters["cell_updates_per_second"] = benchmark::Counter(
      static_cast<double>(g.interior_cells()) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Continuum3D_OperatorRhs)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

// The 1D base case's fastest setting that agrees with the reference (paper transport,
// extrapolated implicit diffusion, SSP-RK(4,2)) on the 3D box: the step is the advective
// limit, and the diffusive half steps are conjugate-gradient solves.
void BM_Continuum3D_PeriodicCycle_PaperExtrapolatedImplicitStages(benchmark::State& state) {
  run_periodic_cycle(state, base_case(3, 0.5, "paper", "implicit_extrapolated", static_cast<int>(state.range(0))));
}
BENCHMARK(BM_Continuum3D_PeriodicCycle_PaperExtrapolatedImplicitStages)
    ->Arg(4)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->UseRealTime();

// SSP-RK(s,2) with the diffusive half steps RKL2 super time steps (Strang split): the step is
// the advective limit, which in the base case's box is 1.6 times the explicit diffusive one.
void BM_Continuum3D_PeriodicCycle_PaperRkl2Stages(benchmark::State& state) {
  run_periodic_cycle(state, base_case(3, 0.5, "paper", "rkl2", static_cast<int>(state.range(0))));
}
BENCHMARK(BM_Continuum3D_PeriodicCycle_PaperRkl2Stages)
    ->Arg(10)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->UseRealTime();

// A whole 3D cycle from rest takes too long to time here. Its cost is estimated from the
// measured 3D cell-update rate and the steps of a whole 1D cycle at the same resolution, times 3: the
// 3D advective and diffusive limits sum over three directions (horizontal motion is
// negligible in the base case), which makes the 3D step a third of the 1D one.
void BM_Continuum3D_BaseCase_Paper(benchmark::State& state) {
  const auto three = base_case(3, 0.5, "paper");
  run_fraction(state, three, 0.02);
  continuum::TimeIntegrator column = continuum::make_solver(base_case(1, 0.5, "paper"));
  column.advance_to(three.parameters.shaker.period());
  const double steps_3d = 3.0 * static_cast<double>(column.counters().steps);
  const double rate = state.counters["cell_updates_per_second"];
  state.counters["steps_per_cycle_estimate"] = steps_3d;
  state.counters["seconds_per_cycle_estimate"] = steps_3d * static_cast<double>(three.grid.interior_cells()) / rate;
}
BENCHMARK(BM_Continuum3D_BaseCase_Paper)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_Continuum3D_MemoryPerCell(benchmark::State& state) {
  const continuum::ContinuumCase c = base_case(3, 0.5, "paper");
  double bytes = 0;
  for (auto _ : state) {
    const auto before = mallinfo2().uordblks;
    continuum::TimeIntegrator solver(c.grid, c.physics, c.integration);
    const auto after = mallinfo2().uordblks;
    bytes = static_cast<double>(after - before);
    benchmark::DoNotOptimize(solver.state().q[0].data());
  }
  state.counters["bytes_per_cell"] = bytes / static_cast<double>(c.grid.interior_cells());
}
BENCHMARK(BM_Continuum3D_MemoryPerCell)->Iterations(1);

// Weak scaling of the decomposed 3D box: every rank owns a block of W x W columns (W the
// argument) of the base case's height at cell 0.5 (160 planes). Under `mpirun -np P` the box
// is (px W) x (py W) cells, px x py = Halo::layout(P); without a launcher W x W on one
// process (the serial path). Twenty steps of the paper transport with explicit diffusion from
// the flat layer, timed between barriers; cell updates per second of the whole box and per
// rank (per core with OMP_NUM_THREADS=1), and the fraction of rank 0's time spent in messages
// and reductions.
void BM_Continuum3D_DecomposedBlock(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const bool launched = launched_by_mpi();
  const int ranks = Ranks::world().size();
  const auto [px, py] = launched ? continuum::Halo::layout(ranks) : std::pair{1, 1};
  continuum::ContinuumCase c = base_case(3, 0.5, "paper", "explicit");
  c.grid.nx = px * width;
  c.grid.ny = py * width;
  const auto halo = launched ? std::make_shared<const continuum::Halo>(c.grid, ranks) : nullptr;
  const auto barrier = [&] {
    if (launched) MPI_Barrier(MPI_COMM_WORLD);
  };
  constexpr int steps = 20;
  double seconds = 0, communication = 0;
  for (auto _ : state) {
    state.PauseTiming();
    continuum::TimeIntegrator solver = continuum::make_solver(c, halo);
    barrier();
    state.ResumeTiming();
    const double communicated = halo ? halo->communication_seconds() : 0.0;
    const auto start = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) solver.step(std::numeric_limits<double>::infinity());
    barrier();
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    communication += halo ? halo->communication_seconds() - communicated : 0.0;
  }
  const double cells = static_cast<double>(c.grid.interior_cells());
  const double rate = cells * steps * static_cast<double>(state.iterations()) / seconds;
  state.counters["ranks"] = ranks;
  state.counters["cells_per_rank"] = cells / ranks;
  state.counters["cell_updates_per_second"] = rate;
  state.counters["cell_updates_per_second_per_rank"] = rate / ranks;
  // Rank 0's time in messages and reductions (waiting for the others included) / wall time.
  state.counters["communication_fraction"] = communication / seconds;
}
BENCHMARK(BM_Continuum3D_DecomposedBlock)->Arg(16)->Arg(32)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

// Under mpirun every rank runs the benchmarks (the decomposed ones together, each rank its own
// copy of the others: filter with --benchmark_filter); rank 0 alone reports and writes files.
int main(int argc, char** argv) {
  std::vector<char*> arguments(argv, argv + argc);
  if (!shaker::Ranks::world().root()) {
    std::erase_if(arguments, [](const char* a) { return std::string(a).rfind("--benchmark_out", 0) == 0; });
    if (std::freopen("/dev/null", "w", stdout) == nullptr) return 1;
  }
  int count = static_cast<int>(arguments.size());
  benchmark::Initialize(&count, arguments.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  shaker::Ranks::finalize();
  return 0;
}
