// Fuzz target: the continuum checkpoint reader shaker::continuum::read_checkpoint, with the
// restart rule `shaker continuum` applies first (the stored configuration, read by
// checkpoint_configuration). Contract: a damaged checkpoint or one of another grid throws
// shaker::InputError and leaves the solver unchanged; anything else escaping (another
// exception, a crash, a sanitizer report, a hang) is a finding.
// Input: a recipe (hdf5_recipe.hpp) of the checkpoint; the solver is small_case.toml's 1D
// column, built once, whose checkpoints make_corpus.sh writes as seeds.
#include <cstdint>

#include "common/config.hpp"
#include "common/errors.hpp"
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
    shaker::config::require_same_keys(small.config, shaker::continuum::checkpoint_configuration(path),
                                      {"material.restitution", "material.e", "layer.particles",
                                       "md.box_width", "shaker.frequency"},
                                      "the fuzz input");
    shaker::continuum::read_checkpoint(path, small.solver);
  } catch (const shaker::InputError&) {
  }
  small.restore();
  return 0;
}
