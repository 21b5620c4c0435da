// Fuzz target: the continuum checkpoint reader shaker::continuum::read_checkpoint, with the
// restart rule `shaker continuum` applies first (the stored configuration, read by
// checkpoint_configuration) and the schedule it continues after (resume_at, check_switch). Contract: a damaged checkpoint or one of another grid throws
// shaker::InputError and leaves the solver unchanged; anything else escaping (another
// exception, a crash, a sanitizer report, a hang) is a finding.
// Input: a recipe (hdf5_recipe.hpp) of the checkpoint; the solver is small_case.toml's 1D
// column, built once, whose checkpoints make_corpus.sh writes as seeds.
#include <cstdint>
#include <string>

#include "common/config.hpp"
#include "common/case_parameters.hpp"
#include "common/errors.hpp"
#include "common/run_loop.hpp"
#include "continuum/checkpoint.hpp"
#include "continuum/setup.hpp"
#include "hdf5_recipe.hpp"

namespace {

struct SmallCase {
  shaker::config::Config config = shaker::config::Config::load(SHAKER_FUZZ_CASE, {});
  shaker::continuum::ContinuumCase setup = shaker::continuum::continuum_case(config);
  shaker::continuum::TimeIntegrator solver = shaker::continuum::make_solver(setup);
  // What a successful read replaces, restored after each input (the solver cannot be copied).
  shaker::continuum::State initial_state = solver.state();
  double initial_e = solver.op().settings().e;

  void restore() {
    solver.state() = initial_state;
    solver.set_time(0.0);
    solver.op().settings().e = initial_e;
    solver.budget() = {};
    solver.counters() = {};
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static SmallCase small;
  static const auto path = shaker::fuzz::private_input_file("continuum-checkpoint");
  shaker::fuzz::write_hdf5_recipe(path, data, size);
  try {
    const std::string saved = shaker::continuum::checkpoint_configuration(path);
    shaker::config::require_same_keys(small.config, saved,
                                      {"material.restitution", "material.e", "layer.particles",
                                       "md.box_width", "shaker.frequency"},
                                      "the fuzz input");
    const shaker::SchedulePosition position = shaker::continuum::read_checkpoint(path, small.solver);
    // The schedule the checkpoint continues: its position and time, and the single-shock
    // switch against the stored protocol.
    const shaker::RunProtocol& run = small.setup.parameters.run;
    shaker::PhaseSchedule schedule =
        shaker::PhaseSchedule::from_start(run, small.setup.parameters.shaker, position.start_time);
    schedule.resume_at(position, small.solver.time(), "the fuzz input");
    schedule.check_switch(shaker::CaseParameters::from(shaker::config::Config::from_toml(saved, "the fuzz input")).run,
                          small.solver.time(), "the fuzz input");
  } catch (const shaker::InputError&) {
  }
  small.restore();
  return 0;
}
