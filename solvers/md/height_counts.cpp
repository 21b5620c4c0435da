#include "md/height_counts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace shaker::md {

// A crossing earlier in a flight under way is counted at the particle's next update, which
// looks at the whole flight, so it is subtracted here (a flight crosses at most once, so
// what it did before now it still has done then). Distinct particles need no such correction:
// their flights are cut at the start instead.
void HeightCounts::start(std::vector<double> heights, double cycle_frequency, double gravity,
                         double now, const std::vector<Particle>& particles) {
  heights_ = std::move(heights);
  cycle_frequency_ = cycle_frequency;
  gravity_ = gravity;
  start_time_ = now;
  half_inverse_gravity_ = 0.5 / gravity;
  gate_height_ = std::numeric_limits<double>::infinity();
  if (!heights_.empty()) {
    const double lowest = *std::min_element(heights_.begin(), heights_.end());
    gate_height_ = lowest - 1e-9 * std::fabs(lowest);
  }
  crossings_.assign(heights_.size(), 0);
  distinct_.assign(heights_.size(), 0);
  const std::vector<std::uint64_t> before = crossings_at(particles, now);
  for (std::size_t k = 0; k < heights_.size(); ++k) crossings_[k] = -static_cast<std::int64_t>(before[k]);
  last_counted_cycle_.assign(particles.size() * heights_.size(),
                             static_cast<std::int32_t>(cycle_at(now) - 1));
}

std::int64_t HeightCounts::cycle_at(double t) const {
  auto cycle = static_cast<std::int64_t>(std::floor(t * cycle_frequency_));
  while (cycle_start(cycle + 1) <= t) ++cycle;  // t * f rounds across a boundary at most by one
  while (cycle_start(cycle) > t) --cycle;
  return cycle;
}

HeightCounts::CyclesReached HeightCounts::cycles_reaching(const Particle& p, double h, double from,
                                                          double to, std::int64_t after) const {
  CyclesReached reached{0, after};
  if (!(from < to)) return reached;
  for (std::int64_t c = std::max(cycle_at(from), after + 1); cycle_start(c) < to; ++c) {
    const double begin = std::max(from, cycle_start(c)), end = std::min(to, cycle_start(c + 1));
    if (flight_peak(p, begin, end, gravity_) >= h) {
      ++reached.count;
      reached.last = c;
    }
  }
  return reached;
}

void HeightCounts::count_high_flight(std::int32_t i, const Particle& p, double now) {
  const double from = counted_from(p);
  for (std::size_t k = 0; k < heights_.size(); ++k) {
    const double h = heights_[k];
    crossings_[k] += rises_through(p, now, gravity_, h) ? 1 : 0;
    std::int32_t& last = last_counted(i, k);
    const CyclesReached reached = cycles_reaching(p, h, from, now, last);
    distinct_[k] += reached.count;
    last = static_cast<std::int32_t>(reached.last);
  }
}

std::vector<std::uint64_t> HeightCounts::crossings_at(const std::vector<Particle>& particles,
                                                      double t) const {
  std::vector<std::int64_t> counts = crossings_;
  for (const Particle& p : particles) {
    if (apex_bound(p) < gate_height_) continue;
    for (std::size_t k = 0; k < heights_.size(); ++k)
      counts[k] += rises_through(p, t, gravity_, heights_[k]) ? 1 : 0;
  }
  return std::vector<std::uint64_t>(counts.begin(), counts.end());
}

std::vector<std::uint64_t> HeightCounts::distinct_particles_at(const std::vector<Particle>& particles,
                                                               double t) const {
  std::vector<std::uint64_t> counts = distinct_;
  const std::size_t heights = heights_.size();
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Particle& p = particles[i];
    if (apex_bound(p) < gate_height_) continue;
    for (std::size_t k = 0; k < heights; ++k)
      counts[k] += cycles_reaching(p, heights_[k], counted_from(p), t, last_counted_cycle_[i * heights + k]).count;
  }
  return counts;
}

void HeightCounts::renumber(const std::vector<std::int32_t>& old_of_new) {
  const std::size_t heights = heights_.size();
  if (heights == 0) return;
  const std::vector<std::int32_t> before = last_counted_cycle_;
  for (std::size_t k = 0; k < old_of_new.size(); ++k) {
    const auto old = static_cast<std::size_t>(old_of_new[k]);
    std::copy_n(before.begin() + static_cast<std::ptrdiff_t>(old * heights), heights,
                last_counted_cycle_.begin() + static_cast<std::ptrdiff_t>(k * heights));
  }
}

}  // namespace shaker::md
