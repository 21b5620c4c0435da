#pragma once
// The constitutive functions of the Jenkins–Richman / Goldshtein model (docs/models.md,
// "The continuum model") and the hard-sphere kinetic-theory results used to check the MD solver.
//
// Written once, as templates over the scalar type, so that double, long double and
// automatic-differentiation scalars (Eigen::AutoDiffScalar) share one definition: the
// manufactured-solution sources are derived from exactly these functions.
// Every function checks its domain on the value part of its arguments and throws
// DomainError instead of returning NaN.
#include <cmath>
#include <string>
#include <type_traits>

#include "common/errors.hpp"
#include "common/units.hpp"

namespace shaker::model {

enum class Transport { paper, full };  ///< paper: 1/G terms of mu and kappa dropped

/// The plain number behind a scalar (the value part of an AD scalar).
template <class S> double value_of(const S& x) {
  if constexpr (std::is_arithmetic_v<S>) {
    return static_cast<double>(x);
  } else {
    return value_of(x.value());
  }
}

namespace detail {
[[noreturn]] void domain_failure(const char* function, const char* what, double value,
                                 const char* allowed);
template <class S> void require_volume_fraction(const S& nu, const char* function) {
  const double v = value_of(nu);
  if (!(v > 0.0 && v < nu_max)) domain_failure(function, "nu", v, "0 < nu < nu_max = 0.65");
}
template <class S> void require_temperature(const S& T, const char* function) {
  const double v = value_of(T);
  if (!(v >= 0.0)) domain_failure(function, "T", v, "T >= 0");
}
inline void require_restitution(double e, const char* function) {
  if (!(e >= 0.0 && e <= 1.0)) domain_failure(function, "e", e, "0 <= e <= 1");
}
template <class S> void require_density(const S& n, const char* function) {
  const double v = value_of(n);
  if (!(v > 0.0)) domain_failure(function, "n", v, "n > 0");
}
inline constexpr double g0_exponent = 4.0 / 3.0 * nu_max;
}  // namespace detail

/// Radial distribution at contact, g0 = [1 - (nu/nu_max)^(4 nu_max / 3)]^(-1).
template <class S> S g0(const S& nu) {
  using std::pow;
  detail::require_volume_fraction(nu, "g0");
  return 1.0 / (1.0 - pow(nu / nu_max, detail::g0_exponent));
}

/// G = nu g0(nu).
template <class S> S G(const S& nu) { return nu * g0(nu); }

/// dG/dnu, exact: g0 + nu g0' with nu g0' = g0^2 a (nu/nu_max)^a, a = 4 nu_max / 3.
template <class S> S dG_dnu(const S& nu) {
  using std::pow;
  const S g = g0(nu);
  return g + g * g * detail::g0_exponent * pow(nu / nu_max, detail::g0_exponent);
}

/// chi = 1 + 2 (1 + e) G: the factor of the pressure over the ideal-gas pressure n T.
template <class S> S chi(const S& nu, double e) {
  detail::require_restitution(e, "chi");
  return 1.0 + 2.0 * (1.0 + e) * G(nu);
}
template <class S> S dchi_dnu(const S& nu, double e) {
  detail::require_restitution(e, "dchi_dnu");
  return 2.0 * (1.0 + e) * dG_dnu(nu);
}

/// Pressure p = n T [1 + 2 (1 + e) G].
template <class S> S pressure(const S& n, const S& T, double e) {
  detail::require_temperature(T, "pressure");
  return n * T * chi(volume_fraction(n), e);
}

/// Collisional energy loss rate per unit volume, gamma = 12/sqrt(pi) (1 - e^2) n T^(3/2) G / sigma.
template <class S> S collisional_loss(const S& n, const S& T, double e) {
  using std::sqrt;
  detail::require_temperature(T, "collisional_loss");
  detail::require_restitution(e, "collisional_loss");
  return 12.0 / sqrt(pi) * (1.0 - e * e) * n * T * sqrt(T) * G(volume_fraction(n)) / sigma;
}

/// Bulk viscosity lambda = 8/(3 sqrt(pi)) n sigma T^(1/2) G.
template <class S> S bulk_viscosity(const S& n, const S& T) {
  using std::sqrt;
  detail::require_temperature(T, "bulk_viscosity");
  return 8.0 / (3.0 * sqrt(pi)) * n * sigma * sqrt(T) * G(volume_fraction(n));
}

/// Shear viscosity mu = sqrt(pi)/6 n sigma T^(1/2) [5/(16 G) + 1 + (4/5)(1 + 12/pi) G];
/// the paper variant drops 5/(16 G).
template <class S> S shear_viscosity(const S& n, const S& T, Transport transport) {
  using std::sqrt;
  detail::require_temperature(T, "shear_viscosity");
  const S g = G(volume_fraction(n));
  S bracket = 1.0 + 0.8 * (1.0 + 12.0 / pi) * g;
  if (transport == Transport::full) bracket += 5.0 / (16.0 * g);
  return sqrt(pi) / 6.0 * n * sigma * sqrt(T) * bracket;
}

/// Thermal conductivity kappa = 15 sqrt(pi)/16 n sigma T^(1/2) [5/(24 G) + 1 + (6/5)(1 + 32/(9 pi)) G];
/// the paper variant drops 5/(24 G).
template <class S> S thermal_conductivity(const S& n, const S& T, Transport transport) {
  using std::sqrt;
  detail::require_temperature(T, "thermal_conductivity");
  const S g = G(volume_fraction(n));
  S bracket = 1.0 + 1.2 * (1.0 + 32.0 / (9.0 * pi)) * g;
  if (transport == Transport::full) bracket += 5.0 / (24.0 * g);
  return 15.0 * sqrt(pi) / 16.0 * n * sigma * sqrt(T) * bracket;
}

/// Speed of sound c = sqrt(T chi (1 + (2/3) chi + (nu/chi) dchi/dnu)).
template <class S> S sound_speed(const S& nu, const S& T, double e) {
  using std::sqrt;
  detail::require_temperature(T, "sound_speed");
  const S x = chi(nu, e);
  return sqrt(T * x * (1.0 + 2.0 / 3.0 * x + nu / x * dchi_dnu(nu, e)));
}

/// Every constitutive quantity of one state (n, T) at once: the same formulas as the
/// functions above, with (nu/nu_max)^a, and so G, evaluated once instead of once per function
/// (the pow dominates a finite-volume closure otherwise).
template <class S> struct ConstitutiveValues {
  S G, chi, pressure, sound_speed, collisional_loss, bulk_viscosity, shear_viscosity,
      thermal_conductivity;
};
/// x^a for x = nu / nu_max, a = detail::g0_exponent: pow. A caller may pass its own (the
/// continuum's closure remembers the values per cell, continuum/transport.cpp).
struct G0Power {
  template <class S> S operator()(const S& x) const {
    using std::pow;
    return pow(x, detail::g0_exponent);
  }
};
template <class S, class Power = G0Power>
ConstitutiveValues<S> constitutive_values(const S& n, const S& T, double e, Transport transport,
                                          const Power& g0_power = {}) {
  using std::sqrt;
  const S nu = volume_fraction(n);
  detail::require_volume_fraction(nu, "constitutive_values");
  detail::require_temperature(T, "constitutive_values");
  detail::require_restitution(e, "constitutive_values");
  const S power = g0_power(nu / nu_max);
  const S g = 1.0 / (1.0 - power);
  ConstitutiveValues<S> r;
  r.G = nu * g;
  const S dG = g + g * g * detail::g0_exponent * power;
  r.chi = 1.0 + 2.0 * (1.0 + e) * r.G;
  const S dchi = 2.0 * (1.0 + e) * dG;
  r.pressure = n * T * r.chi;
  r.sound_speed = sqrt(T * r.chi * (1.0 + 2.0 / 3.0 * r.chi + nu / r.chi * dchi));
  const S root_T = sqrt(T);
  r.collisional_loss = 12.0 / sqrt(pi) * (1.0 - e * e) * n * T * root_T * r.G / sigma;
  r.bulk_viscosity = 8.0 / (3.0 * sqrt(pi)) * n * sigma * root_T * r.G;
  S shear = 1.0 + 0.8 * (1.0 + 12.0 / pi) * r.G;
  S heat = 1.0 + 1.2 * (1.0 + 32.0 / (9.0 * pi)) * r.G;
  if (transport == Transport::full) {
    shear += 5.0 / (16.0 * r.G);
    heat += 5.0 / (24.0 * r.G);
  }
  r.shear_viscosity = sqrt(pi) / 6.0 * n * sigma * root_T * shear;
  r.thermal_conductivity = 15.0 * sqrt(pi) / 16.0 * n * sigma * root_T * heat;
  return r;
}

/// The paper's mean free path estimate xi = sqrt(pi/8) / (n pi sigma^2).
template <class S> S mean_free_path(const S& n) {
  using std::sqrt;
  detail::require_density(n, "mean_free_path");
  return sqrt(pi / 8.0) / (n * pi * sigma * sigma);
}

// ---- Hard-sphere kinetic theory (checks of the MD solver) -----------------------------

/// Carnahan–Starling contact value g0_CS = (1 - nu/2) / (1 - nu)^3.
template <class S> S g0_carnahan_starling(const S& nu) {
  const double v = value_of(nu);
  if (!(v > 0.0 && v < 1.0)) detail::domain_failure("g0_carnahan_starling", "nu", v, "0 < nu < 1");
  const S q = 1.0 - nu;
  return (1.0 - 0.5 * nu) / (q * q * q);
}

/// Carnahan–Starling compressibility p / (n T) = (1 + nu + nu^2 - nu^3) / (1 - nu)^3.
template <class S> S compressibility_carnahan_starling(const S& nu) {
  const double v = value_of(nu);
  if (!(v > 0.0 && v < 1.0))
    detail::domain_failure("compressibility_carnahan_starling", "nu", v, "0 < nu < 1");
  const S q = 1.0 - nu;
  return (1.0 + nu + nu * nu - nu * nu * nu) / (q * q * q);
}

/// Enskog collision frequency per particle, 4 sqrt(pi) n sigma^2 g0_CS(nu) sqrt(T).
template <class S> S enskog_collision_frequency(const S& n, const S& T) {
  using std::sqrt;
  detail::require_temperature(T, "enskog_collision_frequency");
  return 4.0 * sqrt(pi) * n * sigma * sigma * g0_carnahan_starling(volume_fraction(n)) * sqrt(T);
}

/// Haff's law T(t) = T0 / (1 + t/t0)^2 for a homogeneously cooling gas with contact value
/// G = nu g0 (the model's g0 for the continuum, g0_CS for hard spheres):
/// 1/t0 = (4/sqrt(pi)) (1 - e^2) G sqrt(T0) / sigma.
template <class S> S haff_temperature(const S& t, const S& T0, const S& G_value, double e) {
  using std::sqrt;
  detail::require_temperature(T0, "haff_temperature");
  detail::require_restitution(e, "haff_temperature");
  const S inverse_t0 = 4.0 / sqrt(pi) * (1.0 - e * e) * G_value * sqrt(T0) / sigma;
  const S s = 1.0 + t * inverse_t0;
  return T0 / (s * s);
}

std::string to_string(Transport transport);
Transport transport_from_string(const std::string& name);  ///< throws InputError

}  // namespace shaker::model
