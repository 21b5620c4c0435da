#pragma once
// What reaches given lab-frame heights, counted exactly along the free flights: upward
// crossings, and distinct particles per oscillation cycle. Both are counted when a particle is
// updated (its flight since its local time is complete then), and flights still under way are
// added when a count is read, without touching the particles. Not part of a checkpoint: every
// run starts its counts afresh at a cycle boundary, so a restarted run counts each cycle as an
// uninterrupted one does.
#include <cstdint>
#include <vector>

#include "md/particles.hpp"

namespace shaker::md {

class HeightCounts {
 public:
  /// Starts both counts at zero at time `now`. Cycle c is [c / cycle_frequency, (c + 1) /
  /// cycle_frequency), the run loop's own cycle boundaries.
  void start(std::vector<double> heights, double cycle_frequency, double gravity, double now,
             const std::vector<Particle>& particles);

  /// Counts the free flight of particle i (state p) from its local time to now; called before
  /// the particle is advanced, at every update, so the common case must stay cheap.
  void count_flight(std::int32_t i, const Particle& p, double now) {
    if (heights_.empty() || apex_bound(p) < gate_height_) return;
    count_high_flight(i, p, now);
  }

  /// Per height: upward crossings since start() up to t (no earlier than any local time).
  std::vector<std::uint64_t> crossings_at(const std::vector<Particle>& particles, double t) const;
  /// Per height: the sum over the cycles since start() of the number of distinct particles at
  /// or above the height at some instant of the cycle, up to t (the cycle of t so far).
  std::vector<std::uint64_t> distinct_particles_at(const std::vector<Particle>& particles,
                                                   double t) const;

  /// Follows a renumbering of the particles (new id k was old id old_of_new[k]).
  void renumber(const std::vector<std::int32_t>& old_of_new);
  std::size_t bytes_per_particle() const { return heights_.size() * sizeof(std::int32_t); }

 private:
  struct CyclesReached {
    std::uint64_t count = 0;
    std::int64_t last = 0;  ///< the last cycle counted (`after` if none)
  };

  /// Never below the flight's highest point from p.t on, and cheap: the apex, or the start if
  /// p is falling (infinite or NaN without gravity, so such flights are always looked at).
  double apex_bound(const Particle& p) const {
    const double rise = p.v.z > 0.0 ? p.v.z : 0.0;
    return p.r.z + rise * rise * half_inverse_gravity_;
  }
  void count_high_flight(std::int32_t i, const Particle& p, double now);
  /// The cycles after `after` in which the flight of p over [from, to) reaches h.
  CyclesReached cycles_reaching(const Particle& p, double h, double from, double to,
                                std::int64_t after) const;
  /// Where counting starts in p's flight: flights under way at start() count from there.
  double counted_from(const Particle& p) const { return p.t > start_time_ ? p.t : start_time_; }
  double cycle_start(std::int64_t cycle) const { return static_cast<double>(cycle) / cycle_frequency_; }
  /// The cycle c with cycle_start(c) <= t < cycle_start(c + 1), exactly for these boundaries.
  std::int64_t cycle_at(double t) const;
  std::int32_t& last_counted(std::int32_t i, std::size_t k) {
    return last_counted_cycle_[static_cast<std::size_t>(i) * heights_.size() + k];
  }

  std::vector<double> heights_;
  double cycle_frequency_ = 1.0, gravity_ = 1.0, start_time_ = 0.0;
  double half_inverse_gravity_ = 0.0;
  /// Slightly below the lowest height, so that the rounding of apex_bound never skips a
  /// flight that reaches it.
  double gate_height_ = 0.0;
  /// Crossings counted at particle updates, less those before start() in flights under way.
  std::vector<std::int64_t> crossings_;
  std::vector<std::uint64_t> distinct_;
  /// Per particle and height (particle-major): the last cycle in which it was counted. A cycle
  /// index fits in 32 bits for any run that can finish.
  std::vector<std::int32_t> last_counted_cycle_;
};

}  // namespace shaker::md
