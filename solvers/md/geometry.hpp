#pragma once
// The container: periodic in x and y; in z either an oscillating plate below and a fixed
// ceiling above (the shaker), or periodic (the bulk-gas checks, without gravity).
#include "common/shaker_kinematics.hpp"

namespace shaker::md {

struct Geometry {
  double width = 20.0;     ///< periodic box edge in x
  double depth = 20.0;     ///< periodic box edge in y
  double height = 200.0;   ///< ceiling (walls) or periodic length (periodic_z)
  bool periodic_z = false; ///< true: no plate and no ceiling, z periodic
  double gravity = 1.0;    ///< acceleration -gravity along z
  ShakerKinematics plate = ShakerKinematics::fixed_plate();

  /// Largest |h''| of the plate gap h(t) = z(t) - 1/2 - z_p(t): g + A omega^2.
  double gap_curvature_bound() const {
    return gravity + plate.amplitude() * plate.omega() * plate.omega();
  }
  double plate_top() const { return 2.0 * plate.amplitude(); }
};

}  // namespace shaker::md
