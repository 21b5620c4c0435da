#pragma once
// Dimensionless units (docs/units.md): particle diameter, particle mass and gravity are 1.
#include <numbers>

namespace shaker {
inline constexpr double sigma = 1.0;    ///< particle diameter
inline constexpr double mass = 1.0;     ///< particle mass
inline constexpr double gravity = 1.0;  ///< g
inline constexpr double nu_max = 0.65;  ///< random close packing
inline constexpr double pi = std::numbers::pi;

/// Volume fraction of a number density (and back), sigma = 1.
template <class S> S volume_fraction(const S& n) { return (pi / 6.0) * n; }
template <class S> S number_density(const S& nu) { return (6.0 / pi) * nu; }
}  // namespace shaker
