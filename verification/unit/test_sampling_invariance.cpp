// The shock's quantities do not depend on how finely a run is stored: the same synthetic MD
// run (synthetic_fronts.hpp: a base-case-like layer with a shock of known formation, speed
// and exit, MD-sized noise, explicit seeds) stored at 25, 50, 100 and 200 phases per cycle
// gives every per-run shock quantity of `shaker analyze` (read by name from run_values, as
// the JSON carries them) within its stated error at every resolution, and the formation,
// exit, lifetime and speed within their errors of the truth. A shock that decelerates does
// the same, and its speed states the rounding that the phase grid gives the ends of its fit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "analysis/run_analysis.hpp"
#include "synthetic_fronts.hpp"

namespace {

using namespace shaker::testing::synthetic;

const std::vector<std::size_t> kResolutions = {25, 50, 100, 200};
const std::vector<std::string> kQuantities = {"formation_phase", "exit_phase", "lifetime",
                                              "shock_speed", "shock_width_mean",
                                              "width_over_mfp_mean", "max_mach_peak"};

struct Estimate {
  double value = NAN, error = NAN;
};
using Estimates = std::map<std::string, Estimate>;

double named(const std::vector<an::NamedValues>& values, const std::string& name) {
  for (const auto& v : values)
    if (v.name == name) return v.values.front();
  return NAN;  // a quantity the analysis does not give
}

/// Every per-run quantity with its stated error, as `shaker analyze` states it: the central
/// value, and the jackknife error over the samples combined with the rounding error.
Estimates estimate(const RunRecord& run) {
  const auto central = an::run_values(an::analyze_profiles(run.profiles, run.e, options()));
  std::vector<std::vector<an::NamedValues>> replicates;
  for (std::size_t s = 0; s < run.samples.samples(); ++s)
    replicates.push_back(an::run_values(an::analyze_profiles(an::profiles_without(run, s), run.e, options())));
  Estimates e;
  for (const auto& name : kQuantities) {
    std::vector<double> left_out;
    for (const auto& r : replicates) left_out.push_back(named(r, name));
    double resolution = NAN;
    for (const auto& v : central)
      if (v.name == name && !v.resolution.empty()) resolution = v.resolution.front();
    const double value = named(central, name);
    e[name] = {value, an::standard_error(value, left_out, resolution)};
  }
  return e;
}

/// Mean over seeds of each quantity's value and stated error, and the fraction of seeds whose
/// error bar covers the truth (where there is one).
struct Summary {
  double mean = 0, error = 0, covered = 0;
  int found = 0;
};

/// The truth's quantities by name (the speed for a straight path only: a curved one has no
/// single speed).
std::map<std::string, double> truth_of(const Truth& tr) {
  std::map<std::string, double> truth{{"formation_phase", tr.formation_phase},
                                      {"exit_phase", tr.exit_phase()}, {"lifetime", tr.lifetime()}};
  if (tr.deceleration == 0.0) truth["shock_speed"] = tr.speed;
  return truth;
}

/// `seeds` runs stored at `phases` per cycle. Each seed's formation phase is drawn uniformly
/// within half a spacing of the coarsest grid (0.02 cycle) of the default, so that no
/// resolution is favoured by where the truth sits on its phase grid; the means are of
/// estimate - truth.
std::map<std::string, Summary> study(const Truth& base, std::size_t phases, int seeds,
                                     std::uint64_t first_seed) {
  std::map<std::string, Summary> out;
  for (int i = 0; i < seeds; ++i) {
    const std::uint64_t seed = first_seed + static_cast<std::uint64_t>(i);
    Truth tr = base;
    std::mt19937_64 offset(seed ^ 0x9e3779b97f4a7c15ULL);
    tr.formation_phase += 0.02 * std::uniform_real_distribution<double>(-1.0, 1.0)(offset);
    const auto truth = truth_of(tr);
    const Estimates e = estimate(synthetic_run(tr, 1.0, seed, phases));
    for (const auto& name : kQuantities) {
      Summary& s = out[name];
      const Estimate& x = e.at(name);
      if (!std::isfinite(x.value)) continue;
      ++s.found;
      const double deviation = truth.count(name) ? x.value - truth.at(name) : x.value;
      s.mean += deviation, s.error += x.error;
      if (truth.count(name)) s.covered += std::abs(deviation) <= x.error;
    }
  }
  for (auto& [name, s] : out)
    if (s.found) s.mean /= s.found, s.error /= s.found, s.covered /= s.found;
  return out;
}

constexpr int kSeeds = 24;

using Studies = std::map<std::size_t, std::map<std::string, Summary>>;

/// The study of `base` at every resolution, printed.
Studies studies_of(const Truth& base) {
  Studies s;
  for (std::size_t phases : kResolutions) s[phases] = study(base, phases, kSeeds, 21'000'000);
  const auto truth = truth_of(base);
  std::cout << std::setprecision(4) << "mean over " << kSeeds
            << " seeds (of estimate - truth where there is a truth) +- mean stated error:\n";
  for (const auto& name : kQuantities) {
    std::cout << "  " << name << (truth.count(name) ? " - truth" : "") << ":";
    for (std::size_t phases : kResolutions) {
      const Summary& x = s.at(phases).at(name);
      std::cout << "  " << phases << ": " << x.mean << " +- " << x.error;
      if (truth.count(name)) std::cout << " (covers " << x.covered << ")";
    }
    std::cout << "\n";
  }
  return s;
}

const Studies& by_resolution() {
  static const Studies studies = studies_of(Truth{});
  return studies;
}

/// A shock that decelerates from 10 to 4 sqrt(g sigma) over its life (the MD's fronts slow
/// down from about 17 to 3 through theirs): a straight line through its path has a slope
/// that depends on which part of the path the fit covers. Its mean speed is no single
/// number of the truth, so only the agreement between resolutions is tested.
const Studies& curved_by_resolution() {
  static const Studies studies = [] {
    Truth curved;
    curved.speed = 10.0, curved.deceleration = 3.0;
    return studies_of(curved);
  }();
  return studies;
}

/// The bias of `name` at `phases` per cycle is below its stated error, which covers the truth
/// in at least half of the seeds (a 68 % bar: 24 seeds give the coverage a binomial standard
/// error of 0.095).
void expect_truth_within_error(const std::string& name, std::size_t phases) {
  const Summary& s = by_resolution().at(phases).at(name);
  const std::string where = name + " at " + std::to_string(phases) + " phases per cycle";
  EXPECT_LT(std::abs(s.mean), s.error) << where;
  EXPECT_GE(s.covered, 0.5) << where;
}

/// Every shock quantity at every resolution: found for every seed, and the mean over seeds
/// agrees with the mean at 50 phases per cycle (the study's sampling) within the combined
/// error the two runs state.
void expect_agreement_across_resolutions(const Studies& studies) {
  for (const auto& name : kQuantities)
    for (std::size_t phases : kResolutions) {
      const Summary& s = studies.at(phases).at(name);
      const Summary& r = studies.at(50).at(name);
      const std::string where = name + " at " + std::to_string(phases) + " phases per cycle";
      EXPECT_EQ(s.found, kSeeds) << where;
      EXPECT_LT(std::abs(s.mean - r.mean), std::hypot(s.error, r.error)) << where;
    }
}

TEST(SamplingInvariance, ShockQuantitiesAgreeAcrossPhasesPerCycle) {
  expect_agreement_across_resolutions(by_resolution());
}

TEST(SamplingInvariance, ShockQuantitiesOfACurvedPathAgreeAcrossPhasesPerCycle) {
  expect_agreement_across_resolutions(curved_by_resolution());
}

/// The noise-free decelerating shock of curved_by_resolution, its formation at `offsets` phases
/// spread evenly over one spacing of the coarsest grid, at `phases` per cycle: the speed and
/// its stated error (without noise, the rounding error alone).
std::vector<Estimate> noise_free_curved_speeds(std::size_t phases, int offsets) {
  std::vector<Estimate> speeds;
  for (int i = 0; i < offsets; ++i) {
    Truth tr;
    tr.speed = 10.0, tr.deceleration = 3.0;
    tr.formation_phase += 0.04 * ((i + 0.5) / offsets - 0.5);
    speeds.push_back(estimate(synthetic_run(tr, 0.0, 1, phases)).at("shock_speed"));
  }
  return speeds;
}

TEST(SamplingInvariance, TheSpeedOfACurvedPathStatesTheRoundingOfItsFitWindow) {
  // Without noise the only error is where the phase grid puts the ends of the speed's fit
  // window. The speeds at two samplings of the same run then differ by that rounding, which
  // the stated errors must cover as a 68 % bar covers: in at least half of the placements.
  constexpr int kOffsets = 24;
  const auto finest = noise_free_curved_speeds(200, kOffsets);
  for (std::size_t phases : {25, 50, 100}) {
    const auto speeds = noise_free_curved_speeds(phases, kOffsets);
    int covered = 0;
    double largest = 0.0;
    for (int i = 0; i < kOffsets; ++i) {
      const double difference = std::abs(speeds[i].value - finest[i].value);
      covered += difference <= std::hypot(speeds[i].error, finest[i].error);
      largest = std::max(largest, difference);
    }
    std::cout << phases << " against 200 phases per cycle: covered " << covered << " of "
              << kOffsets << ", largest difference " << largest << ", stated error at "
              << phases << " " << speeds.front().error << "\n";
    EXPECT_GE(covered, kOffsets / 2) << phases;
  }
}

TEST(SamplingInvariance, SpeedAndTimesOfTheLifeMatchTheTruth) {
  for (std::size_t phases : kResolutions) expect_truth_within_error("shock_speed", phases);
  for (std::size_t phases : {25, 50}) expect_truth_within_error("formation_phase", phases);
  for (const char* name : {"exit_phase", "lifetime"})
    for (std::size_t phases : {25, 50, 100}) expect_truth_within_error(name, phases);
}

// At 100 and 200 phases per cycle the stated errors of the times (mostly the rounding error of
// the spacing) fall below two biases of the shock rule that coarser grids hide. Measured
// (seeds 21000000-21000023): formation +0.0031 at every resolution (the rule needs a developed
// front, so it sees the shock a little after it forms), against 0.0039 stated at 100 (covers
// 0.46) and 0.0017 at 200 (+0.0038, covers 0.13); at 200 the exit +0.020
// against 0.012 (detections near the layer's top extend the life; covers 0.21), lifetime
// +0.016 against 0.012 (covers 0.25).
TEST(SamplingInvariance, KnownFailureTimesOfTheLifeAtFineSampling) {
  expect_truth_within_error("formation_phase", 100);
  for (const char* name : {"formation_phase", "exit_phase", "lifetime"})
    expect_truth_within_error(name, 200);
}

/// The noise-free run at `phases` per cycle, with the shock rule missing the shock over the
/// phases in [from, to) (their profiles replaced by the layer in flight at phase 0.6).
std::vector<shaker::Profile> missed_between(std::size_t phases, double from, double to) {
  const RunRecord run = synthetic_run(Truth{}, 0.0, 1, phases);
  std::vector<shaker::Profile> profiles = run.profiles;
  const shaker::Profile& in_flight = run.profiles[static_cast<std::size_t>(0.6 * real(phases))];
  for (auto& p : profiles)
    if (p.phase >= from - 1e-12 && p.phase < to - 1e-12) {
      shaker::Profile replaced = in_flight;
      replaced.phase = p.phase, replaced.time = p.time;
      replaced.plate_z = p.plate_z, replaced.plate_v = p.plate_v;
      p = replaced;
    }
  return profiles;
}

TEST(SamplingInvariance, AShockMissedForLessThanTheGapToleranceKeepsItsLifeAtEveryResolution) {
  // Missed over 0.015 of a cycle in mid-life (truth 0.107 to 0.329): no stored phase at 25 and
  // 50 phases per cycle, one at 100, three at 200. A tolerance counted in stored phases (one)
  // breaks the life at 200 phases per cycle, which then starts after the gap at 0.22.
  const Truth tr;
  std::map<std::size_t, an::RunQuantities> r;
  for (std::size_t phases : kResolutions) {
    r[phases] = an::analyze_profiles(missed_between(phases, 0.205, 0.22), kRestitution, options());
    ASSERT_TRUE(r[phases].shock) << phases;
    std::cout << phases << " phases per cycle: formation " << r[phases].shock->formation_phase
              << ", exit " << r[phases].shock->exit_phase << ", speed " << r[phases].shock->speed
              << "\n";
  }
  for (std::size_t phases : kResolutions) {
    const double spacing = 1.0 / real(phases);
    // The formation within the rounding of the phase grid (the midpoint before the first
    // phase with a shock); the exit, the last phase with a shock (0.28 at every resolution)
    // plus exit_reach, within 0.005 of the truth (measured 0.0013 at every resolution).
    EXPECT_NEAR(r[phases].shock->formation_phase, tr.formation_phase, spacing) << phases;
    EXPECT_NEAR(r[phases].shock->exit_phase, tr.exit_phase(), 0.005) << phases;
    EXPECT_NEAR(r[phases].shock->speed, tr.speed, 0.05 * tr.speed) << phases;
  }
}

}  // namespace
