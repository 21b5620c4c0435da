#pragma once
// One restitution model serves MD pair and wall collisions and the continuum's e.
#include <cmath>
#include <string>

namespace shaker {

struct Restitution {
  enum class Kind { constant, velocity_dependent };
  Kind kind = Kind::constant;
  double e = 0.9;  ///< the constant value; for velocity_dependent, the value the continuum uses

  /// e as a function of the normal impact velocity v_n (either sign) (units sqrt(g sigma)):
  /// velocity_dependent is e = 1 - 0.1 |v_n|^(3/4) below |v_n| = 1 and 0.9 above (docs/models.md).
  double operator()(double normal_velocity) const {
    if (kind == Kind::constant) return e;
    const double speed = std::abs(normal_velocity);
    return speed < 1.0 ? 1.0 - 0.1 * std::pow(speed, 0.75) : 0.9;
  }
};

std::string to_string(Restitution::Kind kind);
Restitution::Kind restitution_kind_from_string(const std::string& name);  ///< throws InputError

}  // namespace shaker
