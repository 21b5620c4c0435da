#include "md/event_prediction.hpp"

#include <gsl/gsl_errno.h>

#include <cmath>
#include <stdexcept>

namespace shaker::md {
namespace {

/// The gap h(s) = z(s) - 1/2 - z_p(s) and its derivative, s measured from the particle's time.
struct PlateGap {
  double z, vz, t0, g;
  ShakerKinematics plate;
  double value(double s) const {
    return z + (vz - 0.5 * g * s) * s - 0.5 - plate.position(t0 + s);
  }
  double slope(double s) const { return vz - g * s - plate.velocity(t0 + s); }
};

double gap_for_gsl(double s, void* params) { return static_cast<PlateGap*>(params)->value(s); }

/// Brent's method on a bracket [a, b] with h(a) > 0 > h(b), to rounding of the time.
double polish(gsl_root_fsolver* solver, PlateGap& gap, double a, double b) {
  gsl_function function{&gap_for_gsl, &gap};
  if (gsl_root_fsolver_set(solver, &function, a, b) != GSL_SUCCESS) return b;
  for (int iteration = 0; iteration < 200; ++iteration) {
    if (gsl_root_fsolver_iterate(solver) != GSL_SUCCESS) break;
    const double lo = gsl_root_fsolver_x_lower(solver), hi = gsl_root_fsolver_x_upper(solver);
    if (gsl_root_test_interval(lo, hi, 1e-15, 1e-15) == GSL_SUCCESS) break;
  }
  return gsl_root_fsolver_root(solver);
}

}  // namespace

PlateContactFinder::PlateContactFinder() : solver_(gsl_root_fsolver_alloc(gsl_root_fsolver_brent)) {
  gsl_set_error_handler_off();  // failures are reported through return codes below
}
PlateContactFinder::~PlateContactFinder() {
  if (solver_) gsl_root_fsolver_free(solver_);
}

// Conservative advancement: with |h''| <= M, h(s + tau) >= h + h' tau - M tau^2 / 2, so no
// contact can occur before the positive root tau of that bound. Stepping by tau approaches the
// first contact from the safe side, and converges quadratically for a transversal contact.
// Once the gap is tiny, the root is bracketed a little ahead and polished with Brent.
double PlateContactFinder::first_contact(double z, double vz, double now, double horizon,
                                         const Geometry& geometry) {
  PlateGap gap{z, vz, now, geometry.gravity, geometry.plate};
  const double M = geometry.gap_curvature_bound();
  const double s_max = horizon - now;
  double s = 0.0, h = gap.value(0.0), hp = gap.slope(0.0);
  if (h <= contact_gap && hp < 0.0) return now;  // touching and approaching: contact now
  if (M <= 0.0) return hp < 0.0 && now + h / -hp <= horizon ? now + h / -hp : never;
  for (int iteration = 0; iteration < 100000; ++iteration) {
    const double hb = std::max(h, 0.0);
    const double tau = (hp + std::sqrt(hp * hp + 2.0 * M * hb)) / M;
    if (!(tau > 0.0)) return now + s;  // resting exactly on the plate: contact
    const double s_next = s + tau;
    if (s_next > s_max) return never;
    const double h_next = gap.value(s_next), hp_next = gap.slope(s_next);
    if (h_next <= contact_gap) {
      // Within rounding of the bound: the contact is here (a graze if h' >= 0).
      if (h_next >= 0.0 || hp_next >= 0.0) return now + s_next;
      // The bound says h >= 0 up to s_next, so [s, s_next] brackets the first root.
      return now + polish(solver_, gap, s, s_next);
    }
    if (h_next < 1e-6 && hp_next < 0.0) {
      // Nearly there: try to bracket the root just ahead (h is almost linear on this scale).
      const double probe = s_next + 2.0 * h_next / -hp_next;
      if (probe <= s_max && gap.value(probe) < 0.0) return now + polish(solver_, gap, s_next, probe);
    }
    s = s_next;
    h = h_next;
    hp = hp_next;
  }
  throw std::runtime_error("plate contact search did not converge");
}

}  // namespace shaker::md
