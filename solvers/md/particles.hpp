#pragma once
// Particle state of the event-driven MD: free flight under gravity between events, each
// particle carrying its own local time (it is only updated when it takes part in an event).
#include <cstdint>
#include <vector>

namespace shaker::md {

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
  Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
};
inline Vec3 operator+(Vec3 a, const Vec3& b) { return a += b; }
inline Vec3 operator-(Vec3 a, const Vec3& b) { return a -= b; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/// One cache line per particle: what every prediction reads. The collision counter is here
/// (not in an array of its own) because a prediction reads the counter of the partner it finds,
/// whose state it has just read: one cache line instead of two, and at large N the second was
/// a DRAM miss in every prediction.
struct alignas(64) Particle {
  Vec3 r, v;
  double t = 0.0;              ///< local time at which r and v are valid
  std::uint32_t counter = 0;   ///< collisions so far (a pair event remembers its partner's)
  std::uint32_t streak = 0;    ///< consecutive very short collision intervals (collapse detector)
};
static_assert(sizeof(Particle) == 64);

/// Time of a particle's last collision before any (the TC guard never applies).
inline constexpr double no_collision_yet = -1e300;

/// Position and velocity at time t >= p.t, without modifying p (gravity g along -z).
inline void state_at(const Particle& p, double t, double g, Vec3& r, Vec3& v) {
  const double dt = t - p.t;
  r = {p.r.x + p.v.x * dt, p.r.y + p.v.y * dt, p.r.z + (p.v.z - 0.5 * g * dt) * dt};
  v = {p.v.x, p.v.y, p.v.z - g * dt};
}

/// Brings p to time t.
inline void advance(Particle& p, double t, double g) {
  state_at(p, t, g, p.r, p.v);
  p.t = t;
}

/// Height of p at time t >= p.t in its free flight.
inline double height_at(const Particle& p, double t, double g) {
  const double dt = t - p.t;
  return p.r.z + (p.v.z - 0.5 * g * dt) * dt;
}

/// Highest point of the free flight of p over [from, to] (p.t <= from <= to): the start if it
/// is already falling there, the end if it is still rising there, else the apex.
inline double flight_peak(const Particle& p, double from, double to, double g) {
  if (p.v.z - g * (from - p.t) <= 0.0) return height_at(p, from, g);
  if (p.v.z - g * (to - p.t) >= 0.0) return height_at(p, to, g);
  return p.r.z + p.v.z * p.v.z / (2.0 * g);
}

/// Whether the free flight of p from its local time to t rises through the lab-frame height h:
/// it starts below h and reaches h. A free flight is one parabola, so it rises through h at
/// most once.
inline bool rises_through(const Particle& p, double t, double g, double h) {
  return p.r.z < h && flight_peak(p, p.t, t, g) >= h;
}

/// Everything needed to start or continue a run: positions, velocities and local times.
/// The event-queue and cell-list parts are optional (a checkpoint stores them so that a
/// restart continues bit for bit; a fresh state leaves them empty).
struct State {
  double time = 0.0;
  std::vector<Particle> particles;
  /// Time of each particle's last pair or wall collision (TC guard and collapse detector);
  /// empty: none yet.
  std::vector<double> last_collision;
};

}  // namespace shaker::md
