#pragma once
// When will the next event of a particle happen? Pair contact (a quadratic: under a common
// gravity the relative motion is a straight line), ceiling contact (a quadratic), cell
// crossing, and plate contact (transcendental: conservative advancement + Brent polish).
#include <gsl/gsl_roots.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "md/geometry.hpp"
#include "md/particles.hpp"

namespace shaker::md {

inline constexpr double never = std::numeric_limits<double>::infinity();

/// Time until two spheres at relative position r and relative velocity v touch, if earlier
/// than `bound`, else `never`. Approaching spheres that already overlap (by rounding) touch now.
inline double pair_contact_delay(const Vec3& r, const Vec3& v, double bound = never) {
  const double b = dot(r, v);
  if (b >= 0.0) return never;
  const double c = dot(r, r) - 1.0;
  if (c <= 0.0) return 0.0;
  if (c >= -2.0 * b * bound) return never;  // the root is at least c / (-2 b): skip the sqrt
  const double v2 = dot(v, v);
  const double discriminant = b * b - v2 * c;
  if (discriminant < 0.0) return never;
  return c / (-b + std::sqrt(discriminant));  // the smaller root, free of cancellation
}

/// Candidate partners of one particle in structure-of-arrays form: their ids and periodic image
/// shifts, then relative positions and velocities (particle minus candidate, shift included)
/// for up to `capacity` candidates. The arrays are left uninitialised (a prediction fills only
/// what it uses).
struct PairBatch {
  static constexpr int capacity = 64;
  int count = 0;
  std::int32_t id[capacity];
  double shift_x[capacity], shift_y[capacity], shift_z[capacity];
  double rx[capacity], ry[capacity], rz[capacity];
  double vx[capacity], vy[capacity], vz[capacity];
  double delay[capacity];
};

/// pair_contact_delay for every candidate of the batch at once: delay[k] is the contact delay
/// of candidate k (exactly the value pair_contact_delay gives), `never` if it does not touch.
/// Whether a neighbour approaches is a coin toss, so the tests are combined without branches (a
/// mispredicted branch costs more than the square root and division it would save); the loop
/// vectorises (an AVX2 clone where the CPU has it; no FMA, so every value is rounded exactly as
/// in the scalar form).
void pair_contact_delays(PairBatch& batch);

/// Time until z(t) = z + vz t - g t^2/2 reaches `level` from below (moving up), or `never`.
inline double rise_delay(double z, double vz, double g, double level) {
  if (vz <= 0.0) return never;
  const double d = std::max(level - z, 0.0);
  const double discriminant = vz * vz - 2.0 * g * d;
  if (discriminant < 0.0) return never;
  return 2.0 * d / (vz + std::sqrt(discriminant));
}

/// Time until z(t) falls to `level` (possibly after rising first), or `never` (g = 0, vz >= 0).
inline double fall_delay(double z, double vz, double g, double level) {
  const double d = std::max(z - level, 0.0);
  if (g == 0.0) return vz < 0.0 ? d / -vz : never;
  if (vz < 0.0) return 2.0 * d / (-vz + std::sqrt(vz * vz + 2.0 * g * d));
  return (vz + std::sqrt(vz * vz + 2.0 * g * d)) / g;
}

/// Finds the first plate contact of a free-flying particle. Owns the GSL solver so that no
/// prediction allocates.
class PlateContactFinder {
 public:
  PlateContactFinder();
  ~PlateContactFinder();
  PlateContactFinder(const PlateContactFinder&) = delete;
  PlateContactFinder& operator=(const PlateContactFinder&) = delete;
  PlateContactFinder(PlateContactFinder&& other) noexcept : solver_(other.solver_) {
    other.solver_ = nullptr;
  }
  PlateContactFinder& operator=(PlateContactFinder&&) = delete;

  /// Absolute time of the first contact at or after `now` of a particle at height z with
  /// vertical velocity vz at `now`, or `never` if there is none before `horizon`.
  double first_contact(double z, double vz, double now, double horizon, const Geometry& g);

  /// Gap below which a particle counts as touching the plate (a graze).
  static constexpr double contact_gap = 1e-12;

 private:
  gsl_root_fsolver* solver_;
};

}  // namespace shaker::md
