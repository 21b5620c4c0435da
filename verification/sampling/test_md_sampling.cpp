// MD sampling convergence of the real problem: the base case (validation/cases/base.toml:
// H = 9, e = 0.9, 3937 particles).
//
// 1. Standard error against the number K of sampled cycles. One trajectory (explicit seed,
//    fixed transient, M sampled cycles at 100 phases so that f t = 0.22 and 0.25 are on the
//    grid) is cut into blocks of K = 2, 4, ... M cycles (md_sampling.hpp says why blocks and
//    why the square root of mean se^2). Field level: the RMS over the layer's bins of the
//    solver's own n_se and T_se (PhaseSampler, one per block) at f t = 0.22 and over all
//    phases. Quantities of interest: centre of mass at f t = 0, 0.25, 0.5, 0.75 and shock
//    location at 0.22, each from its per-cycle values (the run file keeps only pooled fields,
//    so the values of each cycle come from a sampler per cycle). The centre of mass of the
//    pooled profile is exactly the mean of the per-cycle ones (all particles are in the bins);
//    the shock location of a pooled profile is not, so its se is that of the per-cycle mean.
//    A single cycle's profile is noisy and its shock is sometimes not detected (3 of 32 cycles
//    in the nightly run): those cycles are left out of their blocks and the fit uses K_eff
//    (block_estimate); at least 90% of the cycles must have a shock.
//    ln se is fitted against ln K (convergence::fit_order) and must have slope -1/2 within
//    3 sigma_p, sigma_p the slope scatter expected from the degrees of freedom of each se
//    (expected_slope_scatter; the test MdSamplingStatistics checks that it bounds the actual
//    scatter of independent Gaussian cycles and that correlated cycles fail).
// 2. Bin size: the same trajectory sampled with bins of sigma and sigma/2 (two `shaker md` runs
//    with the same seed follow the same trajectory, sampling never changes it). The sigma/2
//    profile is averaged in pairs onto the sigma bins (pair_average). Criteria at f t = 0.22:
//    T and u_z differ by less than 2 combined standard errors in at least 90% of the layer's
//    bins: for pure noise 95.4% would be expected, and with ~30-40 layer bins the binomial
//    scatter of that fraction is ~0.035, so 0.9 is ~1.5 of it below; here both profiles see
//    the same particles, so the noise largely cancels and what remains is the bin-size effect,
//    which the check requires to be below the statistical error. nu of the pair is the sigma
//    bin's nu exactly (same particles, half the volume): checked to rounding as a consistency
//    check of the two samplers. The shock location moves by at most 2 combined se + half a
//    sigma bin (the location is a bin edge, so it is quantised to the bin).
// 3. Cross-check: `shaker md` (shaker::md::run) over the first block's cycles writes a run file
//    whose profiles equal this driver's first block, bit for bit, so the study is a study of the
//    solver's own output.
//
// The fast test (default set) uses 16 cycles after a short transient; the nightly one 32 after
// the base case's 10. Tables: <test name>.sampling.csv / .sampling-fit.csv / .bin-size.csv in
// the test's temp directory and in SHAKER_CONVERGENCE_DIR when set.
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "analysis/analysis.hpp"
#include "common/run_file.hpp"
#include "md/run_md.hpp"
#include "md_sampling.hpp"
#include "support/test_directory.hpp"

namespace conv = shaker::convergence;
namespace analysis = shaker::analysis;

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

using shaker::testing::test_directory;

// ---- the statistics, on synthetic cycles ------------------------------------------------

/// Gaussian values with lag-one correlation rho (rho = 0: independent), fixed seed.
std::vector<double> synthetic_cycles(std::size_t m, double rho, std::mt19937_64& engine) {
  std::normal_distribution<double> gaussian;
  std::vector<double> x(m);
  double previous = gaussian(engine);
  for (auto& v : x) {
    v = rho * previous + std::sqrt(1.0 - rho * rho) * gaussian(engine);
    previous = v;
  }
  return x;
}

double synthetic_slope(const std::vector<double>& x, const std::vector<std::size_t>& Ks) {
  std::vector<double> K, se;
  for (std::size_t k : Ks) {
    K.push_back(static_cast<double>(k));
    se.push_back(conv::block_standard_error(x, k));
  }
  return conv::fit_order(K, se).order;
}

TEST(MdSamplingStatistics, BlockStandardErrorOnKnownValues) {
  // Blocks {1, 3} and {2, 6}: s^2 = 2 and 8, se^2 = 1 and 4, sqrt(mean) = sqrt(2.5).
  const std::vector<double> x{1.0, 3.0, 2.0, 6.0, 100.0};  // the remainder is left out
  EXPECT_NEAR(conv::block_standard_error(x, 2), std::sqrt(2.5), 1e-15);
  EXPECT_EQ(conv::block_estimate(x, 2).degrees_of_freedom, 2u);
  EXPECT_THROW(conv::block_standard_error(x, 1), std::invalid_argument);
  EXPECT_THROW(conv::block_standard_error(std::vector<double>{1.0, nan}, 2), std::invalid_argument);
  // A missing cycle: blocks {1, 3, -} and {2, 6, 4}: se^2 = 2 / 2 and 4 / 3, mean 7 / 6;
  // K_eff = 2 / (1/2 + 1/3) = 2.4; dof = 1 + 2.
  const auto e = conv::block_estimate(std::vector<double>{1.0, 3.0, nan, 2.0, 6.0, 4.0}, 3);
  EXPECT_NEAR(e.standard_error, std::sqrt(7.0 / 6.0), 1e-15);
  EXPECT_NEAR(e.effective_count, 2.4, 1e-15);
  EXPECT_EQ(e.degrees_of_freedom, 3u);
  EXPECT_EQ(e.missing, 1u);
  EXPECT_EQ(e.blocks, 2u);
  // A block with fewer than two values is left out; none left: NaN, which fails a fit.
  const auto none = conv::block_estimate(std::vector<double>{1.0, nan, nan, 2.0}, 2);
  EXPECT_TRUE(std::isnan(none.standard_error));
  EXPECT_FALSE(conv::fit_sampling("s", "q", 0.0, {none, conv::complete_blocks(4, 4, 1.0)}).pass());
}

TEST(MdSamplingStatistics, SlopeBandBoundsTheScatterOfIndependentCycles) {
  // 2000 synthetic studies of independent Gaussian cycles with the fast and nightly designs:
  // the mean slope is -1/2, its actual scatter is below expected_slope_scatter (the band's
  // unit), and the 3-sigma band holds at least 99% of them.
  std::mt19937_64 engine(20261122);
  for (const auto& [cycles, Ks] :
       {std::pair<std::size_t, std::vector<std::size_t>>{16, {2, 4, 8, 16}},
        std::pair<std::size_t, std::vector<std::size_t>>{32, {2, 4, 8, 16, 32}}}) {
    const double sigma_p = conv::expected_slope_scatter(Ks, cycles);
    const int studies = 2000;
    double sum = 0.0, squares = 0.0;
    int inside = 0;
    for (int s = 0; s < studies; ++s) {
      const double slope = synthetic_slope(synthetic_cycles(cycles, 0.0, engine), Ks);
      sum += slope;
      squares += slope * slope;
      inside += std::abs(slope + 0.5) <= conv::slope_band_sigmas * sigma_p ? 1 : 0;
    }
    const double mean = sum / studies;
    const double scatter = std::sqrt(squares / studies - mean * mean);
    std::printf("M = %zu: expected slope scatter %.4f, actual %.4f, mean slope %.4f, inside band %.4f\n",
                cycles, sigma_p, scatter, mean, static_cast<double>(inside) / studies);
    EXPECT_NEAR(mean, -0.5, 0.02) << "M = " << cycles;
    EXPECT_LE(scatter, sigma_p) << "M = " << cycles;
    EXPECT_GE(static_cast<double>(inside) / studies, 0.99) << "M = " << cycles;
  }
}

TEST(MdSamplingStatistics, MissingCyclesKeepTheSlope) {
  // One cycle in 32 without a value (as a cycle without a detectable shock): fitted against
  // K_eff, the slope stays -1/2 and the band holds.
  std::mt19937_64 engine(99);
  const std::vector<std::size_t> Ks{2, 4, 8, 16, 32};
  const int studies = 2000;
  double sum = 0.0;
  int inside = 0;
  for (int s = 0; s < studies; ++s) {
    auto x = synthetic_cycles(32, 0.0, engine);
    x[engine() % 32] = nan;
    std::vector<conv::BlockEstimate> estimates;
    for (std::size_t K : Ks) estimates.push_back(conv::block_estimate(x, K));
    const auto fit = conv::fit_sampling("synthetic", "x", 0.0, estimates);
    sum += fit.fit.order;
    inside += fit.pass() ? 1 : 0;
  }
  std::printf("one missing cycle in 32: mean slope %.4f, inside band %.4f\n", sum / studies,
              static_cast<double>(inside) / studies);
  EXPECT_NEAR(sum / studies, -0.5, 0.02);
  EXPECT_GE(static_cast<double>(inside) / studies, 0.99);
}

TEST(MdSamplingStatistics, CorrelatedCyclesFailTheSlope) {
  // Cycles correlated from one to the next (rho = 0.8, a correlation time of ~4.5 cycles):
  // the se of short blocks is far too small and the slope flattens; the check must fail.
  std::mt19937_64 engine(7);
  const std::vector<std::size_t> Ks{2, 4, 8, 16, 32};
  const double band = conv::slope_band_sigmas * conv::expected_slope_scatter(Ks, 32);
  double sum = 0.0;
  const int studies = 200;
  for (int s = 0; s < studies; ++s) sum += synthetic_slope(synthetic_cycles(32, 0.8, engine), Ks);
  const double mean = sum / studies;
  std::printf("rho = 0.8: mean slope %.4f, band -0.5 +- %.4f\n", mean, band);
  EXPECT_GT(mean, -0.5 + band);
}

// ---- the MD study -------------------------------------------------------------------------

struct StudyDesign {
  std::string name;
  int transient_cycles;
  std::size_t cycles;
  std::vector<std::size_t> block_sizes;
  std::uint64_t seed;
};

shaker::config::Config study_config(const StudyDesign& d, std::size_t sampled, double bin_height,
                                    const std::filesystem::path& output) {
  return shaker::config::Config::load(
      SHAKER_BASE_CASE,
      {"run.seed=" + std::to_string(d.seed),
       "run.transient_cycles=" + std::to_string(d.transient_cycles),
       "run.sampled_cycles=" + std::to_string(sampled), "run.phases_per_cycle=100",
       "md.bin_height=" + std::to_string(bin_height), "run.output=" + output.string()});
}

double max_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    // NaN marks an undefined value (an empty bin): equal only to NaN.
    if (std::isnan(a[i]) != std::isnan(b[i])) return std::numeric_limits<double>::infinity();
    if (!std::isnan(a[i])) d = std::max(d, std::abs(a[i] - b[i]));
  }
  return d;
}

/// Block estimates of a per-cycle quantity. A cycle may lack a value (no shock detected in its
/// single-cycle profile): such cycles are left out of their block (block_estimate), but at
/// least 90% of the cycles must have one, so that the se describes the quantity of nearly
/// every cycle rather than of a selection.
std::vector<conv::BlockEstimate> estimates_of(const std::vector<double>& per_cycle,
                                              const std::vector<std::size_t>& Ks,
                                              const std::string& what) {
  std::size_t missing = 0;
  for (double v : per_cycle) missing += std::isnan(v) ? 1 : 0;
  const double found = static_cast<double>(per_cycle.size() - missing) / static_cast<double>(per_cycle.size());
  if (missing) std::printf("%s: found in %zu of %zu cycles\n", what.c_str(), per_cycle.size() - missing, per_cycle.size());
  EXPECT_GE(found, 0.9) << what << ": found in only " << per_cycle.size() - missing << " of "
                        << per_cycle.size() << " cycles";
  std::vector<conv::BlockEstimate> estimates;
  for (std::size_t K : Ks) estimates.push_back(conv::block_estimate(per_cycle, K));
  return estimates;
}

/// Standard error of the mean of the per-cycle values that exist (a single cycle's sigma/2
/// profile is noisy enough that its shock is sometimes not detected), and how many exist.
std::pair<double, std::size_t> mean_standard_error(const std::vector<double>& per_cycle) {
  std::vector<double> found;
  for (double v : per_cycle)
    if (!std::isnan(v)) found.push_back(v);
  if (found.size() < 2) return {nan, found.size()};
  return {conv::block_standard_error(found, found.size()), found.size()};
}

std::string phase_label(double phase) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", phase);
  return text;
}

/// `shaker md` (shaker::md::run) over the transient and the first block of cycles: its run file
/// must hold the driver's first block bit for bit.
void expect_driver_reproduces_shaker_md(const StudyDesign& d, const conv::SamplingTrajectory& run,
                                        const std::filesystem::path& dir) {
  const auto output = dir / "first-block.h5";
  ASSERT_EQ(shaker::md::run(study_config(d, d.block_sizes.front(), 1.0, output)), 0);
  const shaker::RunRecord record = shaker::read_run_file(output);
  ASSERT_EQ(record.profiles.size(), run.first_block.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < record.profiles.size(); ++k) {
    const auto& a = record.profiles[k];
    const auto& b = run.first_block[k];
    for (const auto& [x, y] : {std::pair{&a.n, &b.n}, std::pair{&a.T, &b.T}, std::pair{&a.uz, &b.uz},
                               std::pair{&a.n_se, &b.n_se}, std::pair{&a.T_se, &b.T_se}})
      worst = std::max(worst, max_abs_difference(*x, *y));
  }
  std::printf("shaker md over the first %zu cycles against the driver: max |difference| %.3g\n",
              d.block_sizes.front(), worst);
  EXPECT_EQ(worst, 0.0) << "the driver no longer reproduces shaker md's sampling";
  std::filesystem::remove(dir / "first-block.h5");
}

void run_study(const StudyDesign& d, bool cross_check) {
  const auto dir = test_directory(d.name);
  const double fine_bin = 0.5;
  const auto config = study_config(d, d.cycles, 1.0, dir / "unused.h5");
  const conv::SamplingTrajectory run = conv::run_sampling_trajectory(config, d.block_sizes, fine_bin);
  std::printf("%s: %d transient + %zu sampled cycles in %.1f s\n", d.name.c_str(),
              d.transient_cycles, d.cycles, run.seconds);

  if (cross_check) expect_driver_reproduces_shaker_md(d, run, dir);

  // ---- standard error against K ----
  std::vector<conv::SamplingFit> fits;
  auto add_fit = [&](const std::string& quantity, double phase, std::vector<conv::BlockEstimate> se) {
    fits.push_back(conv::fit_sampling(d.name, quantity, phase, std::move(se)));
    const auto& f = fits.back();
    std::printf("%-34s f t %-5s se:", quantity.c_str(), std::isnan(phase) ? "all" : phase_label(phase).c_str());
    for (const auto& e : f.estimates)
      std::printf(" K=%zu %.4g%s", e.block_size, e.standard_error,
                  e.missing ? (" (K_eff " + std::to_string(e.effective_count) + ")").c_str() : "");
    std::printf("  slope %.3f (fit se %.3f), band -0.5 +- %.3f: %s\n", f.fit.order,
                f.fit.order_std_error, f.band, f.pass() ? "pass" : "FAIL");
    EXPECT_TRUE(f.pass()) << quantity << " at f t = " << phase << ": slope " << f.fit.order
                          << " outside -0.5 +- " << f.band;
  };
  for (const auto& [field, blocks] : {std::pair{"n_se_layer_rms", &run.n_se}, std::pair{"T_se_layer_rms", &run.T_se}})
    for (double phase : {0.22, -1.0}) {
      std::vector<conv::BlockEstimate> se;
      for (std::size_t b = 0; b < d.block_sizes.size(); ++b)
        se.push_back(conv::complete_blocks(
            d.cycles, d.block_sizes[b], conv::layer_rms_standard_error((*blocks)[b], run.pooled, phase)));
      add_fit(field, phase < 0.0 ? nan : phase, se);
    }
  for (std::size_t q = 0; q < run.quantity_names.size(); ++q) {
    const std::string what = run.quantity_names[q] + " at f t = " + phase_label(run.quantity_phases[q]);
    add_fit(run.quantity_names[q], run.quantity_phases[q],
            estimates_of(run.per_cycle[q], d.block_sizes, what));
  }

  // ---- bin size ----
  std::vector<conv::BinSizeCheck> checks;
  const shaker::Profile& coarse = conv::at_phase(run.pooled, 0.22);
  const shaker::Profile paired = conv::pair_average(conv::at_phase(run.pooled_fine, 0.22));
  for (const std::string field : {"T", "uz"}) {
    const auto a = conv::compare_fields(coarse, paired, field);
    checks.push_back({d.name, field, 0.22, nan, nan, "fraction of layer bins within 2 combined se",
                      "at_least", a.fraction(), 0.9});
    std::printf("bin size %-2s: %zu of %zu layer bins within 2 combined se (%.3f), max |diff| %.4g, "
                "largest %.2f se at z = %.1f (plate at %.2f)\n", field.c_str(), a.within, a.bins,
                a.fraction(), a.max_abs_difference, a.max_difference_in_se, a.worst_z, coarse.plate_z);
    EXPECT_GE(a.fraction(), 0.9) << field << ": " << a.within << " of " << a.bins << " layer bins";
  }
  const auto nu = conv::compare_fields(coarse, paired, "nu");
  checks.push_back({d.name, "nu", 0.22, nan, nan, "max abs difference (identical by construction)",
                    "at_most", nu.max_abs_difference, 1e-12});
  std::printf("bin size nu: max |diff| %.3g over %zu layer bins\n", nu.max_abs_difference, nu.bins);
  EXPECT_LE(nu.max_abs_difference, 1e-12);

  const auto shock = analysis::find_shock(coarse);
  const auto shock_fine = analysis::find_shock(conv::at_phase(run.pooled_fine, 0.22));
  const auto [se, found] = mean_standard_error(run.per_cycle[4]);
  const auto [se_fine, found_fine] = mean_standard_error(run.per_cycle_shock_fine);
  const double limit = 2.0 * std::hypot(se, se_fine) + 0.5 * 1.0;
  const double location = shock ? shock->location : nan;
  const double location_fine = shock_fine ? shock_fine->location : nan;
  const double shift = std::abs(location - location_fine);
  checks.push_back({d.name, "shock_location", 0.22, location, location_fine,
                    "shift (limit 2 combined se + half a sigma bin; se from the " + std::to_string(found) +
                        " and " + std::to_string(found_fine) + " of " + std::to_string(d.cycles) +
                        " cycles with a shock)", "at_most", shift, limit});
  std::printf("bin size shock location: %.3f (sigma) %.3f (sigma/2), se %.3f %.3f (shock in %zu and %zu "
              "of %zu cycles), shift %.3f, limit %.3f\n", location, location_fine, se, se_fine, found,
              found_fine, d.cycles, shift, limit);
  EXPECT_TRUE(checks.back().pass()) << "shock location moved by " << shift << ", limit " << limit;

  const auto files = conv::write_sampling_study(dir, d.name, fits, checks);
  EXPECT_EQ(files.size() % 3, 0u);
}

// Default set: a short transient and 16 sampled cycles; K = 2, 4, 8, 16 come from the same 16
// cycles at no extra cost.
TEST(MdSampling, BaseCaseStandardErrorAndBinSize) {
  run_study({"md-sampling-fast", 3, 16, {2, 4, 8, 16}, 11}, false);
}

// The driver against `shaker md` in the default set, kept short (1 transient + 2 cycles each)
// and apart from the study so that ctest -j runs the two side by side.
TEST(MdSampling, DriverReproducesShakerMd) {
  const StudyDesign d{"md-sampling-driver", 1, 2, {2}, 13};
  const auto dir = test_directory(d.name);
  const auto run = conv::run_sampling_trajectory(study_config(d, d.cycles, 1.0, dir / "unused.h5"),
                                                 d.block_sizes, 0.5);
  expect_driver_reproduces_shaker_md(d, run, dir);
  std::filesystem::remove_all(dir);
}

// Nightly: the base case's transient of 10 cycles and 32 sampled cycles.
TEST(NightlyMdSampling, BaseCaseStandardErrorAndBinSize) {
  run_study({"md-sampling-nightly", 10, 32, {2, 4, 8, 16, 32}, 12}, true);
}

}  // namespace
