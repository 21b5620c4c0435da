#pragma once
// MD sampling convergence of the real problem:
// how the standard error of the MD fields and quantities of interest falls with the number K
// of sampled cycles, and whether the sampling bin size (sigma against sigma/2) changes the
// fields by more than their standard error.
//
// Statistics. The cycles of a periodic state are taken as independent samples; that is the
// claim under test. For K cycles the estimate of se^2 = s^2 / K (s^2 the unbiased sample
// variance over the cycles) has E[se^2] = sigma^2 / K exactly, for any distribution; se
// itself is biased low at small K (E[s] = c4(K) sigma, c4(2) = 0.80), which alone would turn
// the expected slope over K = 2, 4, 8 from -0.5 into about -0.36. So every standard error here
// is the square root of a mean of squared standard errors, never a mean of standard errors.
// To reduce the scatter at small K one trajectory of M cycles is cut into the M / K disjoint
// blocks of K consecutive cycles and se^2 is averaged over the blocks (Flyvbjerg & Petersen,
// J. Chem. Phys. 91 (1989) 461: if the cycles were correlated, se would fall more slowly
// than K^-1/2 with the block length, and the fit would fail).
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "common/profile.hpp"
#include "support/convergence.hpp"
#include "support/error_table.hpp"

namespace shaker::convergence {

// ---- statistics -------------------------------------------------------------------------

/// The standard error of a K-cycle mean from the floor(size / K) disjoint blocks of K
/// consecutive values (a remainder is left out). A NaN marks a cycle without a value (e.g. no
/// shock detected in that cycle's profile): block b then holds n_b <= K values, blocks with
/// n_b < 2 are left out, se^2 = mean_b s_b^2 / n_b and E[se^2] = sigma^2 / K_eff with
/// 1 / K_eff = mean_b 1 / n_b (K_eff = K when nothing is missing), so ln se is fitted against
/// ln K_eff.
struct BlockEstimate {
  std::size_t block_size = 0;          ///< K
  double standard_error = 0.0;         ///< sqrt(mean_b s_b^2 / n_b); NaN if no block is usable
  double effective_count = 0.0;        ///< K_eff
  std::size_t blocks = 0;              ///< blocks used
  std::size_t degrees_of_freedom = 0;  ///< sum_b (n_b - 1)
  std::size_t missing = 0;             ///< NaN values in the blocks
};
/// Throws std::invalid_argument for K < 2 or K > size.
BlockEstimate block_estimate(std::span<const double> per_cycle, std::size_t K);

/// block_estimate(...).standard_error; throws std::invalid_argument on a NaN value as well.
double block_standard_error(std::span<const double> per_cycle, std::size_t K);

/// An estimate without missing values: floor(cycles / K) blocks of K, dof = blocks (K - 1).
BlockEstimate complete_blocks(std::size_t cycles, std::size_t K, double standard_error);

/// Expected standard deviation of the least-squares slope of ln se against ln K_eff when each
/// se has the Gaussian degrees of freedom of its estimate (var ln se = 1 / (2 dof) to first
/// order) and the estimates at different K are taken as independent. They share cycles and
/// are positively correlated, which makes the slope scatter smaller, so this is an upper
/// estimate (MdSamplingStatistics measures it).
double expected_slope_scatter(std::span<const BlockEstimate> estimates);
/// The same for complete blocks of each K out of `cycles`.
double expected_slope_scatter(std::span<const std::size_t> block_sizes, std::size_t cycles);

/// Band half-width of the slope check in units of expected_slope_scatter.
inline constexpr double slope_band_sigmas = 3.0;

/// ln se against ln K_eff for one quantity; passes when |slope + 1/2| <= band.
struct SamplingFit {
  std::string study, quantity;
  double phase = 0.0;  ///< f t of the quantity; NaN for a quantity over all phases
  std::vector<BlockEstimate> estimates;  ///< one per K
  OrderFit fit;
  double expected_slope = -0.5;
  double band = 0.0;
  bool pass() const;
};
/// Fits the standard errors against K_eff (convergence::fit_order) with the band
/// slope_band_sigmas * expected_slope_scatter(estimates). A NaN or zero se fails.
SamplingFit fit_sampling(const std::string& study, const std::string& quantity, double phase,
                         std::vector<BlockEstimate> estimates);

// ---- bin size ---------------------------------------------------------------------------

/// Indices of the bins inside the layer, nu > analysis::layer_volume_fraction.
std::vector<std::size_t> layer_bins(const Profile& p);

/// A sigma/2 profile brought onto sigma bins: each pair of half bins is replaced by the plain
/// mean of its two values (the midpoint estimate of the field at the sigma bin's centre) and
/// the standard errors combine as independent, sqrt(se_a^2 + se_b^2) / 2. Pooled counts add.
/// The number density (and nu) of the pair is exactly the sigma bin's (same particles, the
/// bin volume halves); T and u_z are not: a sigma bin weights its halves by their counts and
/// its T includes the spread of the mean flow across it. Those are the bin-size effects.
Profile pair_average(const Profile& fine);

/// Agreement of one field between a sigma profile and a pair-averaged sigma/2 profile over
/// the sigma profile's layer bins: |a - b| < sigmas * sqrt(se_a^2 + se_b^2).
struct FieldAgreement {
  std::size_t bins = 0, within = 0;
  double max_abs_difference = 0.0;
  double max_difference_in_se = 0.0;  ///< largest |a - b| / combined se
  double worst_z = 0.0;               ///< height of that bin
  double fraction() const { return bins ? static_cast<double>(within) / static_cast<double>(bins) : 0.0; }
};
/// field: "T", "uz" or "nu" (nu has no standard error: its combined se is taken from n_se
/// through nu = (pi / 6) n). Throws std::invalid_argument on different bin counts.
FieldAgreement compare_fields(const Profile& coarse, const Profile& paired, const std::string& field,
                              double sigmas = 2.0);

/// One bin-size check as a table row. criterion: "at_least" (value >= limit passes) or
/// "at_most" (value <= limit passes).
struct BinSizeCheck {
  std::string study, quantity;
  double phase = 0.0;
  double sigma_value = 0.0, half_sigma_value = 0.0;  ///< the two results (NaN for a field)
  std::string statistic, criterion;
  double value = 0.0, limit = 0.0;
  bool pass() const;
};

// ---- the MD study -----------------------------------------------------------------------

/// One trajectory of the MD solver, driven by the run loop as `shaker md` drives it (flat-layer
/// start at t = 0, the transient, then the sampled cycles at run.phases_per_cycle phases), sampled by
/// the solver's own PhaseSampler: blocks of each K at md.bin_height, one sampler per cycle at
/// md.bin_height and at fine_bin_height, and both pooled over all cycles.
struct SamplingTrajectory {
  std::size_t cycles = 0;            ///< sampled cycles M
  std::vector<Profile> pooled;       ///< all M cycles, md.bin_height, per phase
  std::vector<Profile> pooled_fine;  ///< all M cycles, fine_bin_height
  std::vector<Profile> first_block;  ///< the first block of block_sizes.front() cycles
  /// se of each block: [block size index][block][phase] -> per bin.
  std::vector<std::vector<std::vector<std::vector<double>>>> n_se, T_se;
  /// Quantities of each cycle (NaN where there is none): centre of mass at f t = 0, 0.25,
  /// 0.5, 0.75 and shock location at 0.22 (bin height md.bin_height), shock location at 0.22
  /// at fine_bin_height.
  std::vector<std::string> quantity_names;
  std::vector<double> quantity_phases;
  std::vector<std::vector<double>> per_cycle;        ///< [quantity][cycle]
  std::vector<double> per_cycle_shock_fine;
  double seconds = 0.0;  ///< wall-clock time of the trajectory
};

/// run.sampled_cycles must be a multiple of every block size; phases_per_cycle must put
/// f t = 0.22 and 0.25 on the phase grid (e.g. 100).
SamplingTrajectory run_sampling_trajectory(const config::Config& config,
                                           std::span<const std::size_t> block_sizes,
                                           double fine_bin_height);

/// The profile at phase index round(phase * phases).
const Profile& at_phase(const std::vector<Profile>& profiles, double phase);

/// RMS over the layer bins of `pooled[phase]` (and over blocks) of one block size's se
/// (sqrt of the mean of se^2, see the header comment); phase < 0: over every phase.
double layer_rms_standard_error(const std::vector<std::vector<std::vector<double>>>& blocks_se,
                                const std::vector<Profile>& pooled, double phase);

// ---- tables -----------------------------------------------------------------------------
//   <name>.sampling.csv      study,quantity,phase,K,blocks,degrees_of_freedom,effective_K,
//                            missing,standard_error
//   <name>.sampling-fit.csv  study,quantity,phase,fit_points,fitted_slope,slope_std_error,
//                            expected_slope,band,pass
//   <name>.bin-size.csv      study,quantity,phase,sigma_value,half_sigma_value,statistic,value,
//                            criterion,limit,pass
// (phase nan: over all phases). Written atomically into `directory` and, when set, into
// SHAKER_CONVERGENCE_DIR; returns every file written.
std::vector<std::filesystem::path> write_sampling_study(const std::filesystem::path& directory,
                                                        const std::string& name,
                                                        std::span<const SamplingFit> fits,
                                                        std::span<const BinSizeCheck> bin_checks);

}  // namespace shaker::convergence
