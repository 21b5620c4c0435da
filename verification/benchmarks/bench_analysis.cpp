// `shaker analyze` throughput on an MD run of the size users store: 100 phases of 200 bins,
// 10 sampled cycles. One iteration is what the command computes: the analysis of the pooled
// profiles and of each leave-one-cycle-out replicate (run_analysis.hpp), file input aside.
// Counters: runs analysed per second and seconds per run (the budget is 0.5 s a run).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>

#include "analysis/run_analysis.hpp"
#include "common/cycle_samples.hpp"
#include "common/profile.hpp"
#include "common/run_file.hpp"

namespace {

using namespace shaker;

constexpr std::size_t kPhases = 100, kBins = 200, kSamples = 10;
constexpr double kBinHeight = 1.0, kBinVolume = 400.0, kFrequency = 0.095;

/// A base-case-like layer (nu about 0.3 between 5 and 35 sigma above the plate) with a shock
/// that crosses it between f t = 0.1 and 0.35: hot and at rest below the front, cold and
/// falling above (warming with distance from the front, as the undisturbed layer does);
/// Gaussian noise of a few per cent per bin and cycle.
RunRecord synthetic_run() {
  std::mt19937_64 rng(20261202);
  std::normal_distribution<double> gauss(0.0, 1.0);
  RunRecord run;
  run.solver = "synthetic";
  run.e = 0.9;
  run.samples = CycleSamples(kPhases, kBins, kBinVolume);
  std::vector<BinSums> snapshot(kBins);
  for (std::size_t s = 0; s < kSamples; ++s)
    for (std::size_t k = 0; k < kPhases; ++k) {
      const double phase = static_cast<double>(k) / kPhases;
      const bool shocked = phase >= 0.1 && phase < 0.35;
      const double front = 5.0 + 100.0 * (phase - 0.1);
      for (std::size_t j = 0; j < kBins; ++j) {
        const double z = (static_cast<double>(j) + 0.5) * kBinHeight;
        const double density = (z > 5.0 && z < 35.0) ? 0.55 : 0.002;
        const bool below = shocked && z < front;
        const double T = below ? 4.0 : 0.3 + 0.1 * std::abs(z - front), uz = below ? 0.0 : -3.0;
        const double count = std::max(0.0, density * kBinVolume * (1.0 + 0.05 * gauss(rng)));
        const double u = uz + 0.05 * std::sqrt(T) * gauss(rng);
        snapshot[j] = {count, 0.0, 0.0, count * u, count * (3.0 * T + u * u)};
      }
      run.samples.add_cycle(k, snapshot);
    }
  for (std::size_t k = 0; k < kPhases; ++k) {
    Profile p;
    p.phase = static_cast<double>(k) / kPhases;
    p.time = p.phase / kFrequency;
    p.bin_height = kBinHeight;
    for (std::size_t j = 0; j < kBins; ++j) p.z.push_back((static_cast<double>(j) + 0.5) * kBinHeight);
    run.samples.pool(k, p);
    run.profiles.push_back(std::move(p));
  }
  return run;
}

void BM_AnalyzeRunWithJackknife(benchmark::State& state) {
  const RunRecord run = synthetic_run();
  analysis::AnalysisOptions options;
  options.frequency = kFrequency;
  double seconds = 0.0;
  std::size_t shock_phases = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    auto central = analysis::analyze_profiles(run.profiles, run.e, options);
    for (std::size_t s = 0; s < kSamples; ++s)
      benchmark::DoNotOptimize(
          analysis::analyze_profiles(analysis::profiles_without(run, s), run.e, options));
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    shock_phases = central.shock ? central.shock->phases.size() : 0;
  }
  const double runs = static_cast<double>(state.iterations());
  state.counters["runs_per_second"] = benchmark::Counter(runs / seconds);
  state.counters["seconds_per_run"] = seconds / runs;
  state.counters["phases"] = kPhases;
  state.counters["bins"] = kBins;
  state.counters["samples"] = kSamples;
  // Nonzero: the fronts were found and fitted, so the timing includes the fits.
  state.counters["shock_phases"] = static_cast<double>(shock_phases);
}
BENCHMARK(BM_AnalyzeRunWithJackknife)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
