#pragma once
// The typed, validated view of the keys both solvers share.
#include <cstdint>
#include <string>

#include "common/config.hpp"
#include "common/restitution.hpp"
#include "common/shaker_kinematics.hpp"

namespace shaker {

struct RunProtocol {
  enum class Kind { periodic, single_shock };
  Kind kind = Kind::periodic;
  std::int64_t transient_cycles = 10;
  std::int64_t sampled_cycles = 10;
  std::int64_t phases_per_cycle = 50;
  double switch_phase = -0.33;   ///< single_shock: relative to the recorded cycle
  Restitution after_switch;      ///< single_shock: restitution after the switch
  std::uint64_t seed = 1;
  std::string output = "run.h5";
  bool log = true;  ///< keep OUTPUT.log (common/terminal_log.hpp)
};

struct CaseParameters {
  std::string name;
  ShakerKinematics shaker{3.0, 0.095};
  Restitution restitution;
  std::int64_t particles = 3937;
  double md_box_width = 20.0;  ///< sets the mass per unit area of both solvers
  RunProtocol run;

  double mass_per_area() const { return static_cast<double>(particles) / (md_box_width * md_box_width); }
  static CaseParameters from(const config::Config& config);
};

}  // namespace shaker
