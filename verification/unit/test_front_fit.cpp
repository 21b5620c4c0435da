// Unit tests of fit_front (solvers/analysis/front_fit.hpp) on synthetic fronts of known truth:
// T(z) = a + b tanh((z - z0) / w) averaged over each bin exactly, as MD bins and continuum
// cells are averages, with Gaussian noise of a stated standard error per bin. The statistics
// over seeds (coverage of the error bars, bias, agreement across bin sizes, false detections)
// are printed, so that a reader of the test log sees the measured numbers, not only a pass.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/front_fit.hpp"
#include "synthetic_fronts.hpp"

namespace {

using shaker::analysis::fit_front;
using shaker::analysis::FrontFit;
using shaker::testing::bin_mean;

struct Front {
  double a = 1.0, b = -0.5;  ///< jump 2 b = -1: T falls across the shock going up
  double z0 = 15.0, w = 1.0;
};

struct Sampled {
  std::vector<double> z, f, se;
};

/// Bins of height h over [0, 30], noise of standard error se in every bin (none if se = 0).
Sampled sample(const Front& front, double h, double se, std::mt19937_64* rng) {
  Sampled s;
  std::normal_distribution<double> noise(0.0, 1.0);
  const int bins = static_cast<int>(std::lround(30.0 / h));
  for (int i = 0; i < bins; ++i) {
    const double zc = (i + 0.5) * h;
    s.z.push_back(zc);
    s.f.push_back(bin_mean(zc, h, front.a, front.b, front.z0, front.w) +
                  (rng ? se * noise(*rng) : 0.0));
    if (se > 0.0) s.se.push_back(se);
  }
  return s;
}

/// The same number of samples spread over more bins: the standard error per bin grows as
/// 1 / sqrt(h). se_at_bin_1 = 0.03 of a jump of 1 is the level of MD temperatures pooled
/// over cycles.
double se_per_bin(double h, double se_at_bin_1 = 0.03) { return se_at_bin_1 / std::sqrt(h); }

struct Statistics {
  int seeds = 0, fits = 0;
  /// fits whose width error is below the width: a front thinner than a bin can give a fit
  /// whose width the data hardly constrain (an error of 1e8 and more)
  int resolved = 0;
  double mean_width = 0, width_sd = 0, mean_width_error = 0, median_width_error = 0;
  double width_coverage = 0, location_coverage = 0;
  double standard_error_of_mean() const { return width_sd / std::sqrt(fits); }
  double bias(double truth) const { return mean_width - truth; }
};

/// Fits `seeds` noisy realisations of `front` (its centre moved by a random fraction of a bin
/// each time, so that no seed is favoured by where the front sits in its bin).
Statistics over_seeds(Front front, double h, int seeds, std::uint64_t first_seed) {
  Statistics st;
  st.seeds = seeds;
  double sum = 0, sum2 = 0, sum_error = 0;
  int width_covered = 0, location_covered = 0;
  std::vector<double> errors;
  const double true_width = 2.0 * front.w;
  for (int k = 0; k < seeds; ++k) {
    std::mt19937_64 rng(first_seed + static_cast<std::uint64_t>(k));
    Front f = front;
    f.z0 += h * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    const Sampled s = sample(f, h, se_per_bin(h), &rng);
    const auto fit = fit_front(s.z, s.f, s.se, f.z0 - 10.0, f.z0 + 10.0);
    if (!fit) continue;
    ++st.fits;
    sum += fit->width;
    sum2 += fit->width * fit->width;
    sum_error += fit->width_error;
    errors.push_back(fit->width_error);
    st.resolved += fit->width_error < fit->width;
    width_covered += std::abs(fit->width - true_width) <= fit->width_error;
    location_covered += std::abs(fit->location - f.z0) <= fit->location_error;
  }
  if (st.fits == 0) return st;
  st.mean_width = sum / st.fits;
  st.width_sd = std::sqrt(std::max(0.0, sum2 / st.fits - st.mean_width * st.mean_width) *
                          st.fits / std::max(1, st.fits - 1));
  st.mean_width_error = sum_error / st.fits;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  st.median_width_error = errors[errors.size() / 2];
  st.width_coverage = static_cast<double>(width_covered) / st.fits;
  st.location_coverage = static_cast<double>(location_covered) / st.fits;
  return st;
}

std::string describe(const Statistics& st, double h, double truth) {
  std::ostringstream out;
  out << std::setprecision(4) << "bin " << h << ", true width " << truth << ": " << st.fits << "/"
      << st.seeds << " fits (" << st.resolved << " with width error < width), mean width "
      << st.mean_width << " +- " << st.standard_error_of_mean() << " (bias " << st.bias(truth)
      << " = " << st.bias(truth) / st.mean_width_error << " of the mean error "
      << st.mean_width_error << "; median error " << st.median_width_error
      << "), coverage width " << st.width_coverage << ", location " << st.location_coverage;
  return out.str();
}

// ---- Noise-free: the fit is exact -----------------------------------------------------

TEST(FrontFit, RecoversANoiseFreeFrontAtEveryBinSize) {
  double worst_width = 0, worst_location = 0, worst_level = 0;
  for (double h : {1.0, 0.5, 0.25})
    for (double w : {0.25, 0.5, 1.0, 2.0, 4.0})        // widths 2 w = 0.5 .. 8
      for (double offset : {0.0, 0.3, 0.5}) {          // centre on an edge, inside, on a centre
        for (double b : {-0.5, 0.5}) {                 // falling and rising fronts
          Front front;
          front.w = w, front.b = b, front.z0 = 15.0 + offset * h;
          const Sampled s = sample(front, h, 0.01, nullptr);
          const auto fit = fit_front(s.z, s.f, s.se, front.z0 - 10.0, front.z0 + 10.0);
          ASSERT_TRUE(fit) << "bin " << h << ", w " << w << ", offset " << offset;
          const double width_error = std::abs(fit->width / (2.0 * w) - 1.0);
          const double location_error = std::abs(fit->location / front.z0 - 1.0);
          const double level_error = std::max(std::abs(fit->low - (front.a - b)),
                                              std::abs(fit->high - (front.a + b)));
          EXPECT_LT(width_error, 1e-6) << "bin " << h << ", w " << w << ", offset " << offset;
          EXPECT_LT(location_error, 1e-6) << "bin " << h << ", w " << w << ", offset " << offset;
          EXPECT_LT(level_error, 1e-6) << "bin " << h << ", w " << w << ", offset " << offset;
          EXPECT_EQ(fit->points, std::count_if(s.z.begin(), s.z.end(), [&](double z) {
                      return std::abs(z - front.z0) <= 10.0;
                    }));
          worst_width = std::max(worst_width, width_error);
          worst_location = std::max(worst_location, location_error);
          worst_level = std::max(worst_level, level_error);
        }
      }
  std::cout << "noise-free, bins 1/0.5/0.25, w 0.25..4: worst relative error of the width "
            << worst_width << ", of the location " << worst_location
            << "; worst absolute error of the levels " << worst_level << "\n";
  RecordProperty("worst_relative_width_error", std::to_string(worst_width));
}

// ---- Noise at the MD level: error bars, bias, bin independence ---------------------------

constexpr int kSeeds = 200;
// Separate seed streams per bin size, so that the three means are independent estimates.
std::uint64_t first_seed(double h) { return 1'000'000 + static_cast<std::uint64_t>(4.0 / h) * 10'000; }

TEST(FrontFit, ErrorBarsCoverTheTruthAndTheWidthIsUnbiased) {
  Front front;
  front.w = 1.0;  // width 2: resolved at every bin size
  for (double h : {1.0, 0.5, 0.25}) {
    const Statistics st = over_seeds(front, h, kSeeds, first_seed(h));
    std::cout << describe(st, h, 2.0 * front.w) << "\n";
    EXPECT_EQ(st.fits, kSeeds) << "bin " << h;
    EXPECT_NEAR(st.width_coverage, 0.68, 0.07) << describe(st, h, 2.0 * front.w);
    EXPECT_NEAR(st.location_coverage, 0.68, 0.07) << describe(st, h, 2.0 * front.w);
    EXPECT_LT(std::abs(st.bias(2.0 * front.w)), 0.2 * st.mean_width_error)
        << describe(st, h, 2.0 * front.w);
  }
}

TEST(FrontFit, UnweightedErrorsFromTheScatterAlsoCover) {
  // Without standard errors the chi^2 of the fit stands in for the noise.
  Front front;
  const double h = 0.5;
  int fits = 0, covered = 0;
  for (int k = 0; k < kSeeds; ++k) {
    std::mt19937_64 rng(2'000'000 + static_cast<std::uint64_t>(k));
    Sampled s = sample(front, h, se_per_bin(h), &rng);
    s.se.clear();
    const auto fit = fit_front(s.z, s.f, s.se, front.z0 - 10.0, front.z0 + 10.0);
    if (!fit) continue;
    ++fits;
    covered += std::abs(fit->width - 2.0 * front.w) <= fit->width_error;
  }
  const double coverage = static_cast<double>(covered) / fits;
  std::cout << "unweighted, bin " << h << ": " << fits << "/" << kSeeds
            << " fits, coverage of the width " << coverage << "\n";
  EXPECT_EQ(fits, kSeeds);
  EXPECT_NEAR(coverage, 0.68, 0.07);
}

TEST(FrontFit, WidthDoesNotDependOnTheBin) {
  // w = 0.5 and 1 (widths of 1 and 2 sigma): a front one bin wide at bin 1 is the hard case.
  for (double w : {0.5, 1.0}) {
    Front front;
    front.w = w;
    std::vector<std::pair<double, Statistics>> by_bin;
    for (double h : {1.0, 0.5, 0.25}) {
      by_bin.emplace_back(h, over_seeds(front, h, kSeeds, first_seed(h) + 500));
      std::cout << describe(by_bin.back().second, h, 2.0 * w) << "\n";
    }
    for (std::size_t i = 0; i < by_bin.size(); ++i) {
      const auto& [h, st] = by_bin[i];
      const double z_truth = st.bias(2.0 * w) / st.standard_error_of_mean();
      std::cout << "  bin " << h << ": mean width - truth = " << z_truth << " standard errors\n";
      EXPECT_LT(std::abs(z_truth), 3.0) << describe(st, h, 2.0 * w);
      for (std::size_t j = i + 1; j < by_bin.size(); ++j) {
        const auto& [h2, st2] = by_bin[j];
        const double z = (st.mean_width - st2.mean_width) /
                         std::hypot(st.standard_error_of_mean(), st2.standard_error_of_mean());
        std::cout << "  bin " << h << " vs " << h2 << ": difference " << z << " standard errors\n";
        EXPECT_LT(std::abs(z), 3.0) << "w " << w << ", bins " << h << " and " << h2;
      }
    }
  }
}

TEST(FrontFit, ResolvesFrontsDownToAboutABinWide) {
  // Where the bin averages stop showing the width: a front of width 2 w sitting inside one bin
  // leaves only that bin's value, which depends on where the front is, not on how thick it is.
  // "Recovered" means at least 95 % of the seeds give a fit whose width error is below the
  // width, and the mean width is within 3 of its standard errors of the truth. Two limits meet
  // here: below about a bin the averages hide the width, and on finer bins the noise per bin
  // grows as 1 / sqrt(h), so a front a bin wide is near the noise limit as well. Measured with
  // these seeds: 1 bin at bin 1, 1.5 bins at bins 0.5 and 0.25 (there a front 1 bin wide gives
  // a resolved fit in 86-88 % of the seeds, unbiased).
  for (double h : {1.0, 0.5, 0.25}) {
    std::optional<double> smallest;
    for (double bins_wide : {2.0, 1.5, 1.0, 0.75, 0.5}) {
      Front front;
      front.w = 0.5 * bins_wide * h;
      const Statistics st = over_seeds(front, h, kSeeds, first_seed(h) + 1000);
      const bool recovered =
          st.resolved >= 0.95 * kSeeds &&
          std::abs(st.bias(2.0 * front.w)) <= 3.0 * st.standard_error_of_mean();
      std::cout << "  " << bins_wide << " bins wide: " << (recovered ? "recovered" : "NOT recovered")
                << "; " << describe(st, h, 2.0 * front.w) << "\n";
      if (!recovered) break;
      smallest = bins_wide;
    }
    std::cout << "bin " << h << ": smallest width recovered "
              << (smallest ? std::to_string(*smallest) + " bins" : "none") << "\n";
    ASSERT_TRUE(smallest) << "bin " << h;
    EXPECT_LE(*smallest, 1.5) << "bin " << h;
  }
}

// ---- No front, bad input --------------------------------------------------------------

TEST(FrontFit, FlatNoiseIsRarelyTakenForAFront) {
  for (double h : {1.0, 0.25}) {
    int fits = 0, detections = 0;
    for (int k = 0; k < kSeeds; ++k) {
      std::mt19937_64 rng(3'000'000 + static_cast<std::uint64_t>(k));
      Front flat;
      flat.b = 0.0;
      const Sampled s = sample(flat, h, se_per_bin(h), &rng);
      const auto fit = fit_front(s.z, s.f, s.se, 5.0, 25.0);
      if (!fit) continue;
      ++fits;
      detections += std::abs(fit->high - fit->low) > 3.0 * fit->jump_error;
    }
    const double rate = static_cast<double>(detections) / kSeeds;
    std::cout << "flat noise, bin " << h << ": " << fits << "/" << kSeeds << " fits, "
              << detections << " with |jump| > 3 errors: false-detection rate " << rate << "\n";
    EXPECT_LE(rate, 0.05) << "bin " << h;
  }
}

TEST(FrontFit, ReturnsNothingForTooFewPointsEmptyInputOrNaN) {
  Front front;
  const Sampled s = sample(front, 1.0, 0.03, nullptr);
  EXPECT_FALSE(fit_front({}, {}, {}, 0.0, 30.0));
  EXPECT_FALSE(fit_front(s.z, s.f, s.se, 13.0, 17.0));  // 4 bins
  EXPECT_TRUE(fit_front(s.z, s.f, s.se, 13.0, 18.0));   // 5 bins
  Sampled with_nan = s;
  with_nan.f[15] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(fit_front(with_nan.z, with_nan.f, with_nan.se, 5.0, 25.0));
  with_nan.f[15] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(fit_front(with_nan.z, with_nan.f, with_nan.se, 5.0, 25.0));
  // A NaN outside the window does not matter.
  with_nan.f[15] = s.f[15];
  with_nan.f[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fit_front(with_nan.z, with_nan.f, with_nan.se, 5.0, 25.0));
  // A window that holds the data but not the front's centre.
  EXPECT_FALSE(fit_front(s.z, s.f, s.se, 18.0, 30.0));
  // Lengths that differ are a programming error.
  EXPECT_THROW(fit_front(s.z, std::vector<double>(3, 1.0), {}, 0.0, 30.0), std::invalid_argument);
}

}  // namespace
