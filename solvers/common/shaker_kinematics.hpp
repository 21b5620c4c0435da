#pragma once
// Plate motion z_p(t) = A (1 - cos(omega t)), lowest at phase f t = 0 (docs/models.md, "The shaker").
#include <cmath>

#include "common/units.hpp"

namespace shaker {

struct ShakerKinematics {
  double Gamma;  ///< peak plate acceleration in units of g
  double f;      ///< frequency

  double omega() const { return 2.0 * pi * f; }
  double amplitude() const { return Gamma * gravity / (omega() * omega()); }
  double period() const { return 1.0 / f; }
  double position(double t) const { return amplitude() * (1.0 - std::cos(omega() * t)); }
  double velocity(double t) const { return amplitude() * omega() * std::sin(omega() * t); }
  double acceleration(double t) const {
    return amplitude() * omega() * omega() * std::cos(omega() * t);
  }
  /// Phase f t reduced to [0, 1).
  double phase(double t) const {
    const double x = f * t;
    return x - std::floor(x);
  }
  /// Body force per unit mass in the container frame: -g - a_p(t).
  double frame_gravity(double t) const { return -gravity - acceleration(t); }
};

}  // namespace shaker
