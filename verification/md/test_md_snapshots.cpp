// Particle snapshots (md.snapshot_phases x md.snapshot_cycles, docs/output-schema.md "Particle
// files"): every particle of a frame at the frame's time (a free flight from the checkpoint
// written at that phase, and the run file's centre of mass and kinetic energy there), the
// frames in time order, a run with snapshots the same trajectory as one without, no particle
// file by default, an ensemble's frames those of replica 0, and a run started from a frame
// (md.initial_state = "file").
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "md/checkpoint.hpp"
#include "md/particle_file.hpp"
#include "md/run_md.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

constexpr int phases = 10;

config::Config small_case(const std::filesystem::path& output, const std::vector<std::string>& settings = {}) {
  config::Config c;
  for (const std::string& s : {std::string("layer.particles=200"), std::string("md.box_width=6.0"),
                               std::string("md.ceiling=60.0"), std::string("run.transient_cycles=1"),
                               std::string("run.sampled_cycles=1"), fmt::format("run.phases_per_cycle={}", phases),
                               "run.output=" + output.string()})
    c.set(s);
  for (const std::string& s : settings) c.set(s);
  return c;
}

const std::vector<std::string> two_by_two{"md.snapshot_phases=[0.5, 0.0]", "md.snapshot_cycles=[-1, 0]"};

/// What the H5MD file holds, read through the HDF5 wrapper.
struct Frames {
  std::vector<std::int64_t> step, cycle;
  std::vector<double> time, phase, plate_z, r, v;
  std::size_t particles = 0;
};

Frames read_frames(const std::filesystem::path& path) {
  const h5::Handle file = h5::open_file(path);
  Frames f;
  f.step = h5::read_integers(file.id(), "particles/all/position/step");
  f.time = h5::read_doubles(file.id(), "particles/all/position/time");
  f.r = h5::read_doubles(file.id(), "particles/all/position/value");
  f.v = h5::read_doubles(file.id(), "particles/all/velocity/value");
  f.particles = h5::shape(file.id(), "particles/all/position/value").at(1);
  f.cycle = h5::read_integers(file.id(), "observables/cycle/value");
  f.phase = h5::read_doubles(file.id(), "observables/phase/value");
  f.plate_z = h5::read_doubles(file.id(), "observables/plate_position/value");
  return f;
}

/// The mean of component `axis` of frame `k`'s vectors, summed in particle order as the run's
/// time series sums them.
double frame_mean(const std::vector<double>& values, std::size_t particles, std::size_t k, int axis) {
  double sum = 0.0;
  for (std::size_t i = 0; i < particles; ++i) sum += values[(k * particles + i) * 3 + static_cast<std::size_t>(axis)];
  return sum / static_cast<double>(particles);
}

/// Frame k's kinetic energy, summed as the run's time series sums it.
double frame_kinetic(const Frames& f, std::size_t k) {
  double sum = 0.0;
  for (std::size_t i = 0; i < f.particles; ++i) {
    const double* u = &f.v[(k * f.particles + i) * 3];
    sum += 0.5 * dot(Vec3{u[0], u[1], u[2]}, Vec3{u[0], u[1], u[2]});
  }
  return sum;
}

TEST(MdSnapshots, TwoPhasesTimesTwoCyclesGiveFourFramesAtTheRunFilesInstants) {
  const auto dir = testing::test_directory();
  ASSERT_EQ(run(small_case(dir / "run.h5", two_by_two)), 0);
  const Frames f = read_frames(dir / "run.particles.h5");
  const RunRecord record = read_run_file(dir / "run.h5");
  ASSERT_EQ(f.time.size(), 4u);
  EXPECT_EQ(f.particles, 200u);
  EXPECT_EQ(f.step, (std::vector<std::int64_t>{0, 5, phases, phases + 5}));
  EXPECT_EQ(f.cycle, (std::vector<std::int64_t>{0, 0, 1, 1}));
  EXPECT_EQ(f.phase, (std::vector<double>{0.0, 0.5, 0.0, 0.5}));
  const auto& t = record.series.column("t");
  const auto& com = record.series.column("com_z");
  const auto& kinetic = record.series.column("kinetic_energy");
  const auto& plate = record.series.column("plate_z");
  double worst_com = 0.0, worst_kinetic = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    // Row m K + k of the series is stored phase k of cycle m.
    const auto row = static_cast<std::size_t>(f.step[k]);
    EXPECT_EQ(f.time[k], t[row]) << "frame " << k;
    EXPECT_EQ(f.plate_z[k], plate[row]) << "frame " << k;
    if (k > 0) {
      EXPECT_LT(f.time[k - 1], f.time[k]);
    }
    worst_com = std::max(worst_com, std::fabs(frame_mean(f.r, f.particles, k, 2) - com[row]));
    worst_kinetic = std::max(worst_kinetic, std::fabs(frame_kinetic(f, k) - kinetic[row]) / kinetic[row]);
  }
  std::printf("measured: 4 frames at t = %.6g .. %.6g; largest |com_z - series| %.3g, relative kinetic "
              "difference %.3g\n", f.time.front(), f.time.back(), worst_com, worst_kinetic);
  EXPECT_LE(worst_com, 1e-12);
  EXPECT_LE(worst_kinetic, 1e-12);

  // The XYZ file: one frame per H5MD frame, each N + 2 lines, with the frame's time.
  std::ifstream xyz(dir / "run.particles.xyz");
  std::vector<std::string> lines;
  for (std::string line; std::getline(xyz, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 4u * (200u + 2u));
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(lines[k * 202], "200");
    EXPECT_NE(lines[k * 202 + 1].find(fmt::format(" Time={} ", f.time[k])), std::string::npos) << lines[k * 202 + 1];
  }
}

TEST(MdSnapshots, EveryParticleIsAtTheFramesTimeAFreeFlightFromTheCheckpoint) {
  const auto dir = testing::test_directory();
  // One cycle, a checkpoint at its end (its last stored phase), and a frame there.
  ASSERT_EQ(run(small_case(dir / "run.h5", {"run.transient_cycles=0", "run.checkpoint_every=1",
                                            "run.checkpoint=" + (dir / "c.h5").string(),
                                            fmt::format("md.snapshot_phases=[{}]", (phases - 1.0) / phases),
                                            "md.snapshot_cycles=[0]"})),
            0);
  const Frames f = read_frames(dir / "run.particles.h5");
  ASSERT_EQ(f.time.size(), 1u);
  // The periodic checkpoint at the frame's time is the newest or the one before it.
  std::vector<std::filesystem::path> files{dir / "c.h5", dir / "c.previous.h5"};
  files.erase(std::remove_if(files.begin(), files.end(),
                             [&](const auto& p) { return !std::filesystem::exists(p) || read_checkpoint(p).data.time != f.time[0]; }),
              files.end());
  ASSERT_EQ(files.size(), 1u) << "no checkpoint at the frame's time t = " << f.time[0];
  const Checkpoint saved = read_checkpoint(files.front());
  ASSERT_EQ(saved.data.particles.size(), f.particles);
  std::size_t in_flight = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < f.particles; ++i) {
    const Particle& p = saved.data.particles[i];
    in_flight += p.t < f.time[0] ? 1 : 0;
    Vec3 r, v;
    state_at(p, f.time[0], 1.0, r, v);
    r.x -= 6.0 * std::floor(r.x / 6.0);
    r.y -= 6.0 * std::floor(r.y / 6.0);
    const double expected[6] = {r.x, r.y, r.z, v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) {
      worst = std::max(worst, std::fabs(f.r[3 * i + static_cast<std::size_t>(a)] - expected[a]));
      worst = std::max(worst, std::fabs(f.v[3 * i + static_cast<std::size_t>(a)] - expected[3 + a]));
    }
  }
  std::printf("measured: %zu of %zu particles last updated before the frame's time; largest difference "
              "from their free flight %.3g\n", in_flight, f.particles, worst);
  EXPECT_GT(in_flight, f.particles / 2);  // the free flight is not trivial
  EXPECT_EQ(worst, 0.0);
}

TEST(MdSnapshots, SnapshotsLeaveTheRunUnchangedAndTheDefaultWritesNoParticleFile) {
  const auto dir = testing::test_directory();
  ASSERT_EQ(run(small_case(dir / "plain.h5")), 0);
  ASSERT_EQ(run(small_case(dir / "with.h5", two_by_two)), 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "plain.particles.h5"));
  EXPECT_FALSE(std::filesystem::exists(dir / "plain.particles.xyz"));
  EXPECT_TRUE(std::filesystem::exists(dir / "with.particles.xyz"));
  const RunRecord plain = read_run_file(dir / "plain.h5"), with = read_run_file(dir / "with.h5");
  ASSERT_EQ(plain.series.names, with.series.names);
  for (std::size_t c = 0; c < plain.series.names.size(); ++c)
    EXPECT_EQ(plain.series.columns[c], with.series.columns[c]) << plain.series.names[c];
  ASSERT_EQ(plain.profiles.size(), with.profiles.size());
  for (std::size_t k = 0; k < plain.profiles.size(); ++k) {
    EXPECT_TRUE(testing::bitwise_equal(plain.profiles[k].n, with.profiles[k].n)) << "phase " << k;
    EXPECT_TRUE(testing::bitwise_equal(plain.profiles[k].T, with.profiles[k].T)) << "phase " << k;
  }
}

TEST(MdSnapshots, AnEnsembleWritesTheFramesOfReplicaZero) {
  const auto dir = testing::test_directory();
  ASSERT_EQ(run(small_case(dir / "single.h5", two_by_two)), 0);
  ASSERT_EQ(run(small_case(dir / "ensemble.h5", [] {
              auto settings = two_by_two;
              settings.push_back("md.replicas=2");
              return settings;
            }())),
            0);
  const Frames single = read_frames(dir / "single.particles.h5"), ensemble = read_frames(dir / "ensemble.particles.h5");
  EXPECT_EQ(ensemble.time, single.time);
  EXPECT_EQ(ensemble.r, single.r);
  EXPECT_EQ(ensemble.v, single.v);
}

TEST(MdSnapshots, ARunStartsFromAFrameAtItsTime) {
  const auto dir = testing::test_directory();
  ASSERT_EQ(run(small_case(dir / "first.h5", two_by_two)), 0);
  const Frames f = read_frames(dir / "first.particles.h5");
  const RunRecord first = read_run_file(dir / "first.h5");
  // Frame 2 is phase 0 of cycle 1: the continued run's first stored phase is its time.
  ASSERT_EQ(run(small_case(dir / "second.h5", {"md.initial_state=file", "md.initial_file=" +
                                                (dir / "first.particles.h5").string(), "md.initial_frame=2"})),
            0);
  const RunRecord second = read_run_file(dir / "second.h5");
  const double com = frame_mean(f.r, f.particles, 2, 2);
  std::printf("measured: frame 2 at t = %.10g, com_z %.12g; the new run's first row t = %.10g, com_z %.12g, "
              "kinetic %.12g (frame %.12g)\n", f.time[2], com, second.series.column("t")[0],
              second.series.column("com_z")[0], second.series.column("kinetic_energy")[0], frame_kinetic(f, 2));
  EXPECT_EQ(second.series.column("t")[0], f.time[2]);
  EXPECT_EQ(second.series.column("com_z")[0], com);
  EXPECT_EQ(second.series.column("com_z")[0], first.series.column("com_z")[phases]);
  EXPECT_EQ(second.series.column("kinetic_energy")[0], frame_kinetic(f, 2));
  // The last frame (the default) lies mid-cycle: the run goes on to the next whole cycle first.
  ASSERT_EQ(run(small_case(dir / "third.h5", {"md.initial_state=file", "md.initial_file=" +
                                               (dir / "first.particles.h5").string()})),
            0);
  const RunRecord third = read_run_file(dir / "third.h5");
  EXPECT_NEAR(third.series.column("t")[0] * 0.095, 2.0, 1e-12);
  EXPECT_EQ(third.series.column("overlaps").back(), 0.0);
}

}  // namespace
}  // namespace shaker::md
