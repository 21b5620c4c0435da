#pragma once
// Reproducible starting states (same seed, same state on every machine: the random numbers
// come from std::mt19937_64, whose sequence the standard fixes, through our own transforms).
#include <cstdint>
#include <random>

#include "md/geometry.hpp"
#include "md/particles.hpp"

namespace shaker::md {

/// Uniform and Gaussian deviates with a fixed, portable algorithm.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double gaussian();  ///< Box-Muller
  std::uint64_t below(std::uint64_t n) { return engine_() % n; }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// The paper's start: a slightly randomised stack of horizontal layers at rest just above the
/// plate at its lowest point (t = 0). With column_lift > 0 each vertical column of sites is
/// raised by its own uniform random height in [0, column_lift) (md.initial_perturbation, a
/// seed of patterns); 0 leaves the layer exactly as without it. Throws InputError if n does
/// not fit below the ceiling.
State flat_layer(const Geometry& geometry, std::size_t n, std::uint64_t seed, double column_lift = 0.0);

/// A homogeneous gas at volume fraction nu and temperature T, without overlaps, zero total
/// momentum and exactly temperature T. Periodic geometry: fills the box (nu is then implied by
/// n and the box, and only checked); walls: fills a slab above the plate at volume fraction nu.
State homogeneous_gas(const Geometry& geometry, std::size_t n, double nu, double T,
                      std::uint64_t seed);

/// The periodic cube without gravity that n particles fill at volume fraction nu (the box of
/// the gas tests and benchmarks).
Geometry periodic_box(std::size_t n, double nu);

}  // namespace shaker::md
