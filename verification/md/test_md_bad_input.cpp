// Bad input through the `shaker` program: exit code 2, a message naming the value and the
// allowed range, and nothing written under the output name.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "common/config.hpp"
#include "md/checkpoint.hpp"
#include "md/initial_states.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

struct Outcome {
  int exit_code;
  std::string errors;
};

Outcome run_shaker(const std::filesystem::path& dir, const std::string& arguments) {
  const auto err = dir / "stderr.txt";
  std::ofstream(dir / "case.toml") << "[case]\nname = \"bad-input\"\n";
  const std::string command = std::string(SHAKER_BINARY) + " md " + (dir / "case.toml").string() +
                              " --set run.output=" + (dir / "out.h5").string() + " " + arguments +
                              " > /dev/null 2> " + err.string();
  const int status = std::system(command.c_str());
  std::stringstream text;
  text << std::ifstream(err).rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text.str()};
}

void expect_rejected(const std::string& arguments, const std::string& names) {
  const auto dir = testing::test_directory();
  const Outcome outcome = run_shaker(dir, arguments);
  EXPECT_EQ(outcome.exit_code, 2) << arguments << ": " << outcome.errors;
  EXPECT_NE(outcome.errors.find(names), std::string::npos) << outcome.errors;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.h5"));
  for (const auto& entry : std::filesystem::directory_iterator(dir))  // no temporary left either
    EXPECT_EQ(entry.path().string().find("out.h5"), std::string::npos) << entry.path();
}

TEST(MdBadInput, RestitutionOutsideZeroOne) { expect_rejected("--set material.e=1.5", "material.e"); }
TEST(MdBadInput, NegativeRestitution) { expect_rejected("--set material.e=-0.1", "material.e"); }
TEST(MdBadInput, GammaNotPositive) { expect_rejected("--set shaker.gamma=0", "shaker.gamma"); }
TEST(MdBadInput, FrequencyNotPositive) { expect_rejected("--set shaker.frequency=-1", "shaker.frequency"); }
TEST(MdBadInput, CeilingBelowPlateTop) { expect_rejected("--set md.ceiling=15", "md.ceiling = 15"); }
TEST(MdBadInput, TooManyParticlesForTheBox) {
  expect_rejected("--set layer.particles=100000", "layer.particles = 100000 does not fit");
}
TEST(MdBadInput, BoxNarrowerThanThreeCells) { expect_rejected("--set md.box_width=2.5 --set layer.particles=10", "md.box_width"); }
TEST(MdBadInput, CrossingHeightNotPositive) {
  expect_rejected("--set md.crossing_heights=[80,0]", "md.crossing_heights");
}
TEST(MdBadInput, CrossingHeightTwice) {
  expect_rejected("--set md.crossing_heights=[80,80.0]", "md.crossing_heights");
}
TEST(MdBadInput, MissingCheckpoint) {
  expect_rejected("--set run.restart_from=/nonexistent.h5", "run.restart_from = \"/nonexistent.h5\": no such file");
}

/// A checkpoint of the base case after a few events, changed by `damage`.
template <class Damage> std::string checkpoint_with(const std::filesystem::path& dir, Damage damage) {
  Geometry g;
  g.plate = ShakerKinematics{3.0, 0.095};
  CollisionRules rules;
  Simulation sim(g, rules, flat_layer(g, 3937, 1));
  for (int k = 0; k < 20000; ++k) sim.step();
  SimulationData data = sim.save();
  damage(data);
  const auto path = dir / "bad-checkpoint.h5";
  // The few events end between stored phases 1 and 2 of cycle 0 (f t = 0.038 of 50 phases): the
  // checkpoint continues at phase 2, as one written by a stop signal at phase 1 would.
  write_checkpoint(path, data, g, SchedulePosition{0.0, 0, 2, 50}, config::Config().to_toml());
  return "--set run.restart_from=" + path.string();
}

/// A damaged checkpoint is refused with a message containing `names`.
template <class Damage> void expect_checkpoint_rejected(Damage damage, const std::string& names) {
  const auto dir = testing::test_directory();
  const Outcome outcome = run_shaker(dir, checkpoint_with(dir, damage));
  EXPECT_EQ(outcome.exit_code, 2) << outcome.errors;
  EXPECT_NE(outcome.errors.find(names), std::string::npos) << outcome.errors;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.h5"));
}

TEST(MdBadInput, UndamagedCheckpointIsAccepted) {  // the checks below refuse only the damage
  const auto dir = testing::test_directory();
  const Outcome outcome =
      run_shaker(dir, checkpoint_with(dir, [](SimulationData&) {}) + " --set run.transient_cycles=1 --set run.sampled_cycles=1");
  EXPECT_EQ(outcome.exit_code, 0) << outcome.errors;
  EXPECT_TRUE(std::filesystem::exists(dir / "out.h5"));
}
TEST(MdBadInput, CellListLinkOutOfRangeInCheckpoint) {
  expect_checkpoint_rejected([](SimulationData& d) { d.cell_head[d.cell_of[7]] = 5000; },
                             "checkpoint cell lists: cell");
}
TEST(MdBadInput, CellListCycleInCheckpoint) {
  expect_checkpoint_rejected([](SimulationData& d) {
    const std::int32_t first = d.cell_head[d.cell_of[7]];
    d.cell_next[first] = first;
  }, "listed twice");
}
TEST(MdBadInput, ParticleInTheWrongCellInCheckpoint) {
  // Moved high above the layer (no overlap, inside the box) but still listed in its old cell:
  // the run would never test it against its new neighbours.
  expect_checkpoint_rejected([](SimulationData& d) {
    d.particles[5].r.z += 40.0;
    d.particles[5].t = d.time;
  }, "which does not contain it");
}
TEST(MdBadInput, EventPartnerOutOfRangeInCheckpoint) {
  expect_checkpoint_rejected([](SimulationData& d) { d.events[3].partner = 3937; }, "partner 3937");
}
TEST(MdBadInput, EventBeforeTheCheckpointTime) {
  expect_checkpoint_rejected([](SimulationData& d) { d.events[3].time = d.time - 1.0; }, "not before the checkpoint time");
}

TEST(MdBadInput, OverlappingParticlesInCheckpoint) {
  expect_checkpoint_rejected([](SimulationData& d) {
    Vec3 r, v;
    state_at(d.particles[6], d.time, Geometry{}.gravity, r, v);
    r.x += 0.3;  // 0.3 from particle 6's centre
    d.particles[5].r = r;
    d.particles[5].t = d.time;
  }, "overlap");
}

TEST(MdBadInput, ParticleOutsideTheBoxInCheckpoint) {
  expect_checkpoint_rejected([](SimulationData& d) {
    d.particles[5].r = {5.0, 5.0, 250.0};  // above the ceiling
    d.particles[5].t = d.time;
  }, "particle 5 at (5, 5, 250) is outside the box");
}

}  // namespace
}  // namespace shaker::md
