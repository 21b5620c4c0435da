#pragma once
// Collision rules (docs/models.md): instantaneous binary collisions with the restitution model of
// solvers/common/restitution.hpp, infinitely massive walls with the same e, the optional TC
// guard against inelastic collapse, and the floor speed that keeps a particle resting on the
// plate from colliding infinitely often.
#include <cmath>

#include "common/restitution.hpp"
#include "md/particles.hpp"

namespace shaker::md {

struct CollisionRules {
  Restitution restitution;
  /// TC model (Luding & McNamara 1998): a collision within tc of either particle's previous
  /// collision is elastic, so collision sequences cannot accumulate in finite time.
  bool tc_guard = false;
  double tc = 1e-5;

  /// Resting/grazing rule for walls: after a wall collision a particle always separates from
  /// the wall with at least this relative speed (units sqrt(g sigma)). A particle resting on
  /// the plate therefore hops with a height below floor^2 / (2 g) = 5e-9 sigma and a period of
  /// at least 2 floor / (g (1 + Gamma)); the sequence of its wall collisions cannot become
  /// infinite in finite time, and it leaves the plate on its own when the plate decelerates
  /// faster than g. The energy this adds is booked as plate work.
  static constexpr double wall_floor_speed = 1e-4;
};

struct PairCollision {
  double normal_speed = 0.0;  ///< |v_n| before the collision
  double loss = 0.0;          ///< kinetic energy lost, (1 - e^2) v_n^2 / 4
  double virial = 0.0;        ///< r_ab . (impulse on a), for the collisional pressure
  bool elastic_by_guard = false;
  bool happened = false;      ///< false if the pair was not approaching (nothing changed)
};

/// Collides a and b (both at the same time) whose centres differ by r_ab = r_a - r_b.
/// last_a and last_b: the times of their previous collisions (TC guard).
inline PairCollision collide_pair(Particle& a, Particle& b, const Vec3& r_ab, double now, double last_a,
                                  double last_b, const CollisionRules& rules) {
  PairCollision out;
  const double distance = std::sqrt(dot(r_ab, r_ab));
  const Vec3 k = (1.0 / distance) * r_ab;
  const double vn = dot(a.v - b.v, k);
  if (vn >= 0.0) return out;
  out.happened = true;
  out.normal_speed = -vn;
  double e = rules.restitution(-vn);
  if (rules.tc_guard && (now - last_a < rules.tc || now - last_b < rules.tc)) {
    e = 1.0;
    out.elastic_by_guard = true;
  }
  const double j = 0.5 * (1.0 + e) * vn;  // impulse on a along k is -j
  a.v -= j * k;
  b.v += j * k;
  out.loss = 0.25 * (1.0 - e * e) * vn * vn;
  out.virial = -j * distance;
  return out;
}

struct WallCollision {
  double work = 0.0;  ///< work done by the wall on the particle
  double loss = 0.0;  ///< energy dissipated in the wall's frame
  bool elastic_by_guard = false;
  bool changed = false;  ///< false for a graze of a particle already leaving fast enough
};

/// Collides p with a wall moving at wall_velocity along z; normal = +1 for the plate (the
/// particle is above), -1 for the ceiling.
/// last: the time of p's previous collision (TC guard).
inline WallCollision collide_wall(Particle& p, double wall_velocity, double normal, double now, double last,
                                  const CollisionRules& rules) {
  WallCollision out;
  const double w = (p.v.z - wall_velocity) * normal;  // < 0: approaching
  if (w >= CollisionRules::wall_floor_speed) return out;
  double e = rules.restitution(std::fabs(w));
  if (rules.tc_guard && now - last < rules.tc) {
    e = 1.0;
    out.elastic_by_guard = true;
  }
  const double outgoing = std::max(e * std::max(-w, 0.0), CollisionRules::wall_floor_speed);
  const double new_vz = wall_velocity + normal * outgoing;
  out.work = (new_vz - p.v.z) * wall_velocity;
  out.loss = 0.5 * (w * w - outgoing * outgoing);
  out.changed = true;
  p.v.z = new_vz;
  return out;
}

}  // namespace shaker::md
