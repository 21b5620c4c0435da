// Grid convergence of the real problem (verification.md, "Convergence of the real problem"):
// the 1D base case (H = 9, e = 0.9, validation/cases/base.toml) at cell sizes 0.4, 0.2, 0.1,
// 0.05 with the quantities of interest of physics.md computed by solvers/analysis. For each:
// the observed order, Richardson extrapolation and Roache's GCI (Fs = 1.25) on the three finest
// grids and on the three coarsest, and the asymptotic-range check. Nightly only (minutes).
//
// Cost (measured on the 2-core machine, see the report): the run protocol is shortened to
// 5 transient cycles and one sampled cycle (at the case's 50 phases, so that the phase windows
// of the claims are the validation study's), so that the four
// resolutions fit in about half an hour. The quantities are then those of the cycle after the
// transient, the same cycle at every resolution, which is what a grid study compares.
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "analysis/analysis.hpp"
#include "common/run_file.hpp"
#include "continuum/run_continuum.hpp"
#include "error_table.hpp"

namespace conv = shaker::convergence;
namespace analysis = shaker::analysis;

namespace {

constexpr int transient_cycles = 5;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

const shaker::Profile& at_phase(const shaker::RunRecord& run, double phase) {
  const shaker::Profile* best = &run.profiles.front();
  for (const auto& p : run.profiles)
    if (std::abs(p.phase - phase) < std::abs(best->phase - phase)) best = &p;
  return *best;
}

std::map<std::string, double> quantities(const shaker::RunRecord& run) {
  std::map<std::string, double> q;
  const auto shock = analysis::find_shock(at_phase(run, 0.22));
  q["shock_location_ft0.22"] = shock ? shock->location : nan;
  const auto speed = analysis::shock_speed(run.profiles);
  q["shock_speed"] = speed ? *speed : nan;
  for (double phase : {0.0, 0.25, 0.5, 0.75})
    q["center_of_mass_ft" + std::to_string(phase).substr(0, 4)] =
        analysis::center_of_mass(at_phase(run, phase));
  double max_mach = 0.0;
  for (const auto& p : run.profiles) max_mach = std::max(max_mach, analysis::max_mach_in_layer(p, run.e));
  q["max_mach"] = max_mach;
  const auto shock25 = analysis::find_shock(at_phase(run, 0.25));
  q["width_over_mfp_ft0.25"] = shock25 ? shock25->width_over_mfp() : nan;
  // The base-case claims of reference-data/claims.toml whose continuum value is one number
  // of this case, computed as validation/quantities.py does, so that the validation report
  // can give their GCI: C5 (the shock width d at f t = 0.22) and C6 (the largest Ma in the
  // layer over the stored phases 0.08 <= f t <= 0.13).
  q["shock_width_ft0.22"] = shock ? shock->width : nan;
  double max_mach_window = nan;
  for (const auto& p : run.profiles)
    if (p.phase >= 0.08 - 1e-9 && p.phase <= 0.13 + 1e-9)
      max_mach_window = std::fmax(max_mach_window, analysis::max_mach_in_layer(p, run.e));
  q["max_mach_ft0.08-0.13"] = max_mach_window;
  return q;
}

TEST(NightlyRealProblem, BaseCase1DGridConvergence) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("shaker-mms-real-problem-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::vector<double> cells{0.4, 0.2, 0.1, 0.05};  // coarse to fine
  std::vector<std::map<std::string, double>> values;
  for (double h : cells) {
    const auto output = dir / ("base-h" + std::to_string(h) + ".h5");
    const auto config = shaker::config::Config::load(
        SHAKER_BASE_CASE,
        {"continuum.cell_size=" + std::to_string(h),
         "run.transient_cycles=" + std::to_string(transient_cycles), "run.sampled_cycles=1",
         "run.output=" + output.string()});
    ASSERT_EQ(shaker::continuum::run(config), 0) << "cell size " << h;
    values.push_back(quantities(shaker::read_run_file(output)));
    for (const auto& [name, v] : values.back()) std::printf("h %.3f %-26s %.6g\n", h, name.c_str(), v);
  }
  std::vector<conv::GciRow> rows;
  for (const auto& [name, unused] : values.front()) {
    const auto phi = [&](std::size_t level) { return values[level].at(name); };
    // Fine triple (0.05, 0.1, 0.2) and coarse triple (0.1, 0.2, 0.4): h1 < h2 < h3.
    for (std::size_t fine : {std::size_t{3}, std::size_t{2}}) {
      const std::string study = fine == 3 ? "real-1d-base-fine" : "real-1d-base-coarse";
      if (std::isnan(phi(fine)) || std::isnan(phi(fine - 1)) || std::isnan(phi(fine - 2))) {
        ADD_FAILURE() << name << ": not found on every grid of " << study;
        continue;
      }
      rows.push_back(conv::make_gci_row(study, name, cells[fine], cells[fine - 1],
                                        cells[fine - 2], phi(fine), phi(fine - 1),
                                        phi(fine - 2)));
      const auto& r = rows.back().result;
      std::printf("%-20s %-26s order %.3f  extrapolated %.6g  GCI21 %.3e  ratio %.3f  %s\n",
                  study.c_str(), name.c_str(), r.order, r.phi_extrapolated, r.gci21,
                  r.asymptotic_ratio, conv::to_string(r.kind).c_str());
      EXPECT_TRUE(rows.back().pass()) << study << " " << name << ": asymptotic ratio "
                                      << r.asymptotic_ratio << ", order " << r.order;
    }
  }
  conv::ErrorTable table;
  const auto files = conv::write_study(dir, "real-1d-base", table, {}, rows);
  EXPECT_FALSE(files.empty());
}

}  // namespace
