#pragma once
// An MD profile is a mean over sampled cycles. Its raw sums are kept per sample (one cycle,
// or a block of consecutive cycles once there are many), so that any subset of samples can be
// pooled again exactly: the analysis leaves one sample out at a time (jackknife), and repeated
// runs of one configuration are pooled by appending their samples.
#include <cstddef>
#include <vector>

namespace shaker {

struct Profile;

/// Sums over the particles found in one bin at one sampling instant.
struct BinSums {
  double count = 0.0, vx = 0.0, vy = 0.0, vz = 0.0, v2 = 0.0;
};

class CycleSamples {
 public:
  /// Beyond this many samples per phase, neighbouring samples are merged pairwise (blocks of
  /// 2, 4, ... cycles), which bounds the memory and keeps the samples nearly independent.
  static constexpr std::size_t max_samples = 32;

  CycleSamples() = default;
  CycleSamples(std::size_t phases, std::size_t bins, double bin_volume);

  /// Adds one snapshot at phase k as that phase's next cycle.
  void add_cycle(std::size_t k, const std::vector<BinSums>& snapshot);
  /// Appends the samples of another run of the same phases and bins.
  void append(const CycleSamples& other);

  bool empty() const { return sums_.empty(); }
  std::size_t phases() const { return sums_.size(); }
  std::size_t bins() const { return bins_; }
  double bin_volume() const { return bin_volume_; }
  /// Samples at phase k (equal for every phase once a run has finished).
  std::size_t samples(std::size_t k = 0) const { return cycles_.empty() ? 0 : cycles_[k].size(); }
  /// Cycles pooled into each sample of phase k.
  const std::vector<double>& cycles(std::size_t k) const { return cycles_[k]; }
  const std::vector<BinSums>& sums(std::size_t k) const { return sums_[k]; }  ///< [sample][bin]

  /// Sets n, nu, uz, T, samples and the standard errors over samples (n_se, uz_se, T_se) of
  /// `into` (bin centres and scalars untouched) from the samples of phase k that `use`
  /// selects (every sample if `use` is empty). What is undefined is NaN: uz in a bin without
  /// particles, T in a bin with fewer than two, a standard error from fewer than two samples
  /// (of the bin with a particle, for uz_se; with two, for T_se). n and nu are always defined.
  void pool(std::size_t k, Profile& into, const std::vector<char>& use = {}) const;

  /// Rebuilds a store from its stored form (run files); throws std::invalid_argument if the
  /// shapes disagree.
  static CycleSamples from_arrays(std::size_t bins, double bin_volume,
                                  std::vector<std::vector<double>> cycles,
                                  std::vector<std::vector<BinSums>> sums);

 private:
  void merge_pairs(std::size_t k);
  std::size_t bins_ = 0;
  double bin_volume_ = 1.0;
  std::vector<std::vector<double>> cycles_;  // [phase][sample]
  std::vector<std::vector<BinSums>> sums_;   // [phase][sample * bins + bin]
};

}  // namespace shaker
