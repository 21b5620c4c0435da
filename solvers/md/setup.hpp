#pragma once
// The typed, validated MD configuration of a case (md.* keys, the shared case keys and the
// checkpoint keys), as the continuum's setup builds its own. Every inconsistency is an
// InputError naming the key and the allowed range, raised before any work or allocation.
#include <cstdint>
#include <string>
#include <vector>

#include "common/case_parameters.hpp"
#include "common/checkpoints.hpp"
#include "common/config.hpp"
#include "common/output_paths.hpp"
#include "md/collision_rules.hpp"
#include "md/geometry.hpp"
#include "md/protocol.hpp"

namespace shaker::md {

struct MdCase {
  CaseParameters parameters;
  MdSettings settings;
  Geometry geometry;
  CheckpointSettings checkpoints;
  CollisionRules rules;
  std::int64_t replicas = 1;  ///< md.replicas
  std::string configuration;  ///< the effective configuration as TOML, for the outputs
};

/// The case of `config`, checked: the box, the memory, every output path against `inputs` (files
/// read besides those the configuration names) and the replicas against the checkpoint keys.
MdCase md_case(const config::Config& config, const std::vector<NamedPath>& inputs);

/// Replica r of the case (md.replicas): the periodic protocol takes seed run.seed + r, the
/// single shock starts r cycles later from run.seed, as repeats of one single shock are pooled.
config::Config replica_configuration(const config::Config& config, std::int64_t r);

}  // namespace shaker::md
