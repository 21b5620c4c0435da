#pragma once
// The typed, validated view of the keys both solvers share.
#include <cstdint>
#include <string>
#include <vector>

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
  /// Cycles of the run: the transient ones, then the sampled ones or the single shock's one.
  std::int64_t cycles() const { return transient_cycles + (kind == Kind::single_shock ? 1 : sampled_cycles); }
};

struct CaseParameters {
  std::string name;
  ShakerKinematics shaker{3.0, 0.095};
  Restitution restitution;
  std::int64_t particles = 3937;
  double md_box_width = 20.0;  ///< with the depth, sets the mass per unit area of both solvers
  double md_box_depth = 20.0;  ///< md.box_depth, or md.box_width where that is 0 (a square box)
  RunProtocol run;

  double mass_per_area() const { return static_cast<double>(particles) / (md_box_width * md_box_depth); }
  static CaseParameters from(const config::Config& config);
};

/// The list `key` of phases f t as stored phases k of `phases` (run.phases_per_cycle), in
/// increasing order. A phase between stored phases, or one listed twice, is refused
/// (InputError naming the key and the allowed values).
std::vector<std::int64_t> stored_phase_indices(const config::Config& config, const std::string& key,
                                               std::int64_t phases);

/// The list `key` of cycles of `run` (from 0; negative from the end, -1 the last) as cycles
/// from 0, in increasing order. A cycle the run does not have, a fraction, or one listed twice
/// is refused (InputError naming the key and the allowed values).
std::vector<std::int64_t> cycle_indices(const config::Config& config, const std::string& key, const RunProtocol& run);

}  // namespace shaker
