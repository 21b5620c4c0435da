#pragma once
// Plate motion z_p(t) = A (1 - cos(omega t)), lowest at phase f t = 0 (docs/models.md, "The shaker").
// The one description of the plate for both solvers: the MD's event prediction evaluates it at
// every plate contact, so omega and A are computed once, here, not at each call.
#include <cmath>

#include "common/units.hpp"

namespace shaker {

class ShakerKinematics {
 public:
  /// The shaker of a case: peak acceleration Gamma (units of g) at frequency f.
  ShakerKinematics(double Gamma, double f)
      : Gamma_(Gamma), f_(f), omega_(2.0 * pi * f), amplitude_(Gamma * gravity / (omega_ * omega_)) {}
  /// A plate at rest at z = 0.
  static ShakerKinematics fixed_plate() { return of_amplitude(0.0, 1.0); }
  /// The motion of amplitude A at angular frequency omega, both kept exactly as given.
  static ShakerKinematics of_amplitude(double A, double omega) {
    ShakerKinematics k(A * omega * omega / gravity, omega / (2.0 * pi));
    k.omega_ = omega;
    k.amplitude_ = A;
    return k;
  }

  double gamma() const { return Gamma_; }   ///< peak plate acceleration in units of g
  double frequency() const { return f_; }   ///< f
  double omega() const { return omega_; }
  double amplitude() const { return amplitude_; }
  double period() const { return 1.0 / f_; }
  double position(double t) const { return amplitude_ * (1.0 - std::cos(omega_ * t)); }
  double velocity(double t) const { return amplitude_ * omega_ * std::sin(omega_ * t); }
  double acceleration(double t) const { return amplitude_ * omega_ * omega_ * std::cos(omega_ * t); }
  /// Phase f t reduced to [0, 1).
  double phase(double t) const {
    const double x = f_ * t;
    return x - std::floor(x);
  }
  /// Body force per unit mass in the container frame: -g - a_p(t).
  double frame_gravity(double t) const { return -gravity - acceleration(t); }

 private:
  double Gamma_, f_, omega_, amplitude_;
};

}  // namespace shaker
