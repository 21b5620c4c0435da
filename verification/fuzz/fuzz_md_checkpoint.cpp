// Fuzz target: the MD checkpoint reader shaker::md::read_checkpoint, followed by what
// `shaker md` does with run.restart_from (run_md.cpp, make_simulation): the
// restart rule against the stored configuration, the state check, the schedule continued from
// the checkpoint's position (resume_at, check_switch against the stored protocol), the sums of
// its sampled cycles taken up (take_up_samples), and the Simulation built from the saved cells
// and events (same box) or from the particles alone (another box).
// Contract: a damaged checkpoint throws shaker::InputError; anything else escaping (another
// exception, a crash, a sanitizer report, a hang) is a finding.
// Input: a recipe (hdf5_recipe.hpp) of the checkpoint; the case is small_case.toml, whose
// checkpoints make_corpus.sh writes as seeds.
#include <cstdint>
#include <utility>

#include "common/case_parameters.hpp"
#include "common/config.hpp"
#include "common/errors.hpp"
#include "common/run_loop.hpp"
#include "common/units.hpp"
#include "hdf5_recipe.hpp"
#include "md/checkpoint.hpp"
#include "md/protocol.hpp"
#include "md/sampling.hpp"
#include "md/simulation.hpp"

namespace {

struct SmallCase {
  shaker::config::Config config = shaker::config::Config::load(SHAKER_FUZZ_CASE, {});
  shaker::CaseParameters parameters = shaker::CaseParameters::from(config);
  shaker::md::MdSettings settings = shaker::md::MdSettings::from(config);
  shaker::md::Geometry geometry;
  shaker::md::CollisionRules rules;
  SmallCase() {
    geometry.width = parameters.md_box_width;
    geometry.depth = parameters.md_box_depth;
    geometry.height = settings.ceiling;
    geometry.gravity = shaker::gravity;
    geometry.plate = parameters.shaker;
    rules.restitution = parameters.restitution;
    rules.tc_guard = settings.tc_guard;
    rules.tc = settings.tc;
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const SmallCase small;
  static const auto path = shaker::fuzz::private_input_file("md-checkpoint");
  shaker::fuzz::write_hdf5_recipe(path, data, size);
  try {
    shaker::md::Checkpoint saved = shaker::md::read_checkpoint(path);
    shaker::config::require_same_keys(small.config, saved.configuration,
                                      {"material.restitution", "material.e", "shaker.frequency"},
                                      "the fuzz input");
    shaker::md::validate_state(small.geometry, saved.data);
    // The schedule the checkpoint continues (its position, time and single-shock switch
    // against the stored protocol) and the sums of its sampled cycles.
    const shaker::RunProtocol written_by =
        shaker::CaseParameters::from(shaker::config::Config::from_toml(saved.configuration, "the fuzz input")).run;
    shaker::PhaseSchedule schedule =
        shaker::PhaseSchedule::whole_cycles(small.parameters.run, small.parameters.shaker, saved.position.start_time);
    schedule.resume_at(saved.position, saved.data.time, "the fuzz input");
    schedule.check_switch(written_by, saved.data.time, "the fuzz input");
    shaker::md::PhaseSampler sampler(static_cast<int>(schedule.phases()), small.settings.bin_height,
                                     small.settings.ceiling, small.geometry.width);
    shaker::md::take_up_samples(sampler, saved.sampled, saved.position, schedule, "the fuzz input");
    if (saved.width == small.geometry.width && saved.height == small.geometry.height) {
      shaker::md::Simulation(small.geometry, small.rules, std::move(saved.data), small.settings.queue);
    } else {
      shaker::md::State state{saved.data.time, std::move(saved.data.particles),
                              std::move(saved.data.last_collision)};
      shaker::md::Simulation(small.geometry, small.rules, state, small.settings.queue);
    }
  } catch (const shaker::InputError&) {
  }
  return 0;
}
