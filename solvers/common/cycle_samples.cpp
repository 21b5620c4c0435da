#include "common/cycle_samples.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/profile.hpp"
#include "common/units.hpp"

namespace shaker {
namespace {

constexpr double undefined = std::numeric_limits<double>::quiet_NaN();

/// Standard error of the mean from a sum and a sum of squares of m values (NaN if m < 2: one
/// value has no spread to estimate it from).
double standard_error(double sum, double squares, double m) {
  if (m < 2.0) return undefined;
  const double mean = sum / m;
  const double variance = std::max(0.0, (squares - m * mean * mean) / (m - 1.0));
  return std::sqrt(variance / m);
}

void add_into(BinSums& a, const BinSums& s) {
  a.count += s.count;
  a.vx += s.vx;
  a.vy += s.vy;
  a.vz += s.vz;
  a.v2 += s.v2;
}

/// Temperature of the particles behind a set of sums: the variance of their velocities / 3.
double temperature(const BinSums& s) {
  const double ux = s.vx / s.count, uy = s.vy / s.count, uz = s.vz / s.count;
  return (s.v2 / s.count - ux * ux - uy * uy - uz * uz) / 3.0;
}

}  // namespace

CycleSamples::CycleSamples(std::size_t phases, std::size_t bins, double bin_volume)
    : bins_(bins), bin_volume_(bin_volume), cycles_(phases), sums_(phases) {}

void CycleSamples::add_cycle(std::size_t k, const std::vector<BinSums>& snapshot) {
  if (snapshot.size() != bins_) throw std::logic_error("CycleSamples: snapshot of wrong size");
  if (cycles_[k].size() == max_samples) merge_pairs(k);
  auto& sums = sums_[k];
  // A merged store keeps filling its last block until that block holds as many cycles as
  // the others.
  if (!cycles_[k].empty() && cycles_[k].back() < cycles_[k].front()) {
    BinSums* last = &sums[(cycles_[k].size() - 1) * bins_];
    for (std::size_t j = 0; j < bins_; ++j) add_into(last[j], snapshot[j]);
    cycles_[k].back() += 1.0;
    return;
  }
  sums.insert(sums.end(), snapshot.begin(), snapshot.end());
  cycles_[k].push_back(1.0);
}

void CycleSamples::merge_pairs(std::size_t k) {
  auto& cycles = cycles_[k];
  auto& sums = sums_[k];
  std::vector<double> merged_cycles;
  std::vector<BinSums> merged;
  for (std::size_t s = 0; s < cycles.size(); s += 2) {
    merged.insert(merged.end(), sums.begin() + static_cast<long>(s * bins_),
                  sums.begin() + static_cast<long>((s + 1) * bins_));
    double c = cycles[s];
    if (s + 1 < cycles.size()) {
      BinSums* block = &merged[merged.size() - bins_];
      for (std::size_t j = 0; j < bins_; ++j) add_into(block[j], sums[(s + 1) * bins_ + j]);
      c += cycles[s + 1];
    }
    merged_cycles.push_back(c);
  }
  cycles = std::move(merged_cycles);
  sums = std::move(merged);
}

void CycleSamples::append(const CycleSamples& other) {
  if (other.empty()) return;
  if (empty()) {
    *this = other;
    return;
  }
  if (other.phases() != phases() || other.bins_ != bins_ ||
      std::abs(other.bin_volume_ - bin_volume_) > 1e-12 * bin_volume_)
    throw std::invalid_argument("the runs to pool differ in phases, bins or bin volume");
  for (std::size_t k = 0; k < phases(); ++k) {
    cycles_[k].insert(cycles_[k].end(), other.cycles_[k].begin(), other.cycles_[k].end());
    sums_[k].insert(sums_[k].end(), other.sums_[k].begin(), other.sums_[k].end());
  }
}

void CycleSamples::pool(std::size_t k, Profile& into, const std::vector<char>& use) const {
  const std::size_t m = samples(k);
  std::vector<BinSums> total(bins_);
  struct Moments {
    double n_sum = 0, n_sq = 0, uz_sum = 0, uz_sq = 0, uz_m = 0, T_sum = 0, T_sq = 0, T_m = 0;
  };
  std::vector<Moments> moments(bins_);
  double cycles = 0.0;
  for (std::size_t s = 0; s < m; ++s) {
    if (!use.empty() && !use[s]) continue;
    cycles += cycles_[k][s];
    const BinSums* sample = &sums_[k][s * bins_];
    for (std::size_t j = 0; j < bins_; ++j) {
      const BinSums& b = sample[j];
      add_into(total[j], b);
      Moments& a = moments[j];
      const double n = b.count / (cycles_[k][s] * bin_volume_);
      a.n_sum += n;
      a.n_sq += n * n;
      if (b.count >= 1.0) {
        const double uz = b.vz / b.count;
        a.uz_sum += uz;
        a.uz_sq += uz * uz;
        a.uz_m += 1.0;
      }
      if (b.count >= 2.0) {
        const double T = temperature(b);
        a.T_sum += T;
        a.T_sq += T * T;
        a.T_m += 1.0;
      }
    }
  }
  const double used = use.empty() ? static_cast<double>(m)
                                  : static_cast<double>(std::count(use.begin(), use.end(), 1));
  into.n.assign(bins_, 0.0);
  into.nu.assign(bins_, 0.0);
  // A bin without particles has no velocity, and one with a single particle no temperature
  // (the spread of one velocity): NaN, where n = 0 is a defined density.
  into.uz.assign(bins_, undefined);
  into.T.assign(bins_, undefined);
  into.samples.assign(bins_, 0.0);
  into.n_se.assign(bins_, 0.0);
  into.uz_se.assign(bins_, 0.0);
  into.T_se.assign(bins_, 0.0);
  for (std::size_t j = 0; j < bins_; ++j) {
    const BinSums& a = total[j];
    const double n = cycles > 0.0 ? a.count / (cycles * bin_volume_) : 0.0;
    into.n[j] = n;
    into.nu[j] = volume_fraction(n);
    if (a.count >= 1.0) into.uz[j] = a.vz / a.count;
    if (a.count >= 2.0) into.T[j] = std::max(0.0, temperature(a));
    into.samples[j] = a.count;
    const Moments& mo = moments[j];
    into.n_se[j] = standard_error(mo.n_sum, mo.n_sq, used);
    into.uz_se[j] = standard_error(mo.uz_sum, mo.uz_sq, mo.uz_m);
    into.T_se[j] = standard_error(mo.T_sum, mo.T_sq, mo.T_m);
  }
}

CycleSamples CycleSamples::from_arrays(std::size_t bins, double bin_volume,
                                       std::vector<std::vector<double>> cycles,
                                       std::vector<std::vector<BinSums>> sums) {
  if (cycles.size() != sums.size() || !(bin_volume > 0.0) || bins == 0)
    throw std::invalid_argument("cycle samples: inconsistent shapes");
  for (std::size_t k = 0; k < cycles.size(); ++k)
    if (sums[k].size() != cycles[k].size() * bins)
      throw std::invalid_argument("cycle samples: sums and cycle counts disagree");
  CycleSamples s;
  s.bins_ = bins;
  s.bin_volume_ = bin_volume;
  s.cycles_ = std::move(cycles);
  s.sums_ = std::move(sums);
  return s;
}

}  // namespace shaker
