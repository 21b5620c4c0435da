// The vibrated layer: the base-case smoke test, energy budget, heights reached per cycle,
// checkpoint restart, the collapse detector and guard, the single-shock protocol, the time
// series of an ensemble's replicas (md.replicas), and the hydrostatic elastic gas.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <numeric>
#include <sstream>
#include <string>

#include "analysis/analysis.hpp"
#include "common/config.hpp"
#include "common/granular_model.hpp"
#include "common/run_file.hpp"
#include "md/checkpoint.hpp"
#include "md/initial_states.hpp"
#include "md/run_md.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

config::Config base_case(const std::filesystem::path& output) {
  config::Config c;  // defaults are the paper's base case
  c.set("run.output=" + output.string());
  return c;
}

TEST(MdVibrated, BaseCaseSmoke) {
  const auto dir = testing::test_directory();
  config::Config c = base_case(dir / "base.h5");
  ASSERT_EQ(run(c), 0);
  const RunRecord record = read_run_file(dir / "base.h5");
  EXPECT_EQ(record.solver, "md");
  EXPECT_EQ(record.configuration, c.to_toml());
  ASSERT_EQ(record.profiles.size(), 50u);

  // The layer leaves the plate in every cycle and lands on it in every cycle.
  const auto& t = record.series.column("t");
  const auto& near = record.series.column("near_plate");
  const double period = 1.0 / 0.095;
  int cycles_with_flight = 0, cycles_with_contact = 0;
  for (int cycle = 0; cycle < 20; ++cycle) {
    double fewest = 1e9, most = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k)
      if (t[k] >= cycle * period - 1e-9 && t[k] < (cycle + 1) * period - 1e-9) {
        fewest = std::min(fewest, near[k]);
        most = std::max(most, near[k]);
      }
    cycles_with_flight += fewest <= 0.01 * 3937 ? 1 : 0;
    cycles_with_contact += most >= 0.05 * 3937 ? 1 : 0;
  }
  // A shock between f t = 0.1 and 0.4.
  int phases_with_shock = 0;
  double first_shock = 1.0;
  for (const Profile& p : record.profiles)
    if (p.phase >= 0.1 && p.phase <= 0.4 && analysis::find_shock(p)) {
      ++phases_with_shock;
      first_shock = std::min(first_shock, p.phase);
    }
  const double closure = record.series.column("energy_budget_relative_residual").back();
  const double overlaps = record.series.column("overlaps").back();
  std::printf("measured: %d/20 cycles in flight, %d/20 with contact, shock at %d phases in "
              "[0.1, 0.4] from f t = %.2f, closure %.3g, overlaps %g\n", cycles_with_flight,
              cycles_with_contact, phases_with_shock, first_shock, closure, overlaps);
  EXPECT_EQ(cycles_with_flight, 20);
  EXPECT_EQ(cycles_with_contact, 20);
  EXPECT_GE(phases_with_shock, 3);
  EXPECT_LT(closure, 1e-9);
  EXPECT_EQ(overlaps, 0.0);
}

TEST(MdVibrated, EnergyBudgetClosesWithVelocityDependentRestitution) {
  const auto dir = testing::test_directory();
  config::Config c = base_case(dir / "vd.h5");
  c.set("material.restitution=velocity_dependent");
  c.set("run.transient_cycles=2");
  c.set("run.sampled_cycles=1");
  ASSERT_EQ(run(c), 0);
  const RunRecord record = read_run_file(dir / "vd.h5");
  double worst = 0.0;
  for (double x : record.series.column("energy_budget_relative_residual")) worst = std::max(worst, x);
  const double work = record.series.column("accumulated_drive_work").back();
  std::printf("measured: largest relative closure %.3g (plate work %.6g)\n", worst, work);
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(work, 1e4);  // the plate did work
}

TEST(MdVibrated, CrossingAndCollisionColumnsAreCumulative) {
  const auto dir = testing::test_directory();
  config::Config c = base_case(dir / "crossings.h5");
  c.set("run.transient_cycles=1");
  c.set("run.sampled_cycles=1");
  c.set("md.crossing_heights=[12.5, 80]");
  ASSERT_EQ(run(c), 0);
  const RunRecord record = read_run_file(dir / "crossings.h5");
  const auto& low = record.series.column("crossings_z12.5");
  const auto& high = record.series.column("crossings_z80");
  const auto& low_particles = record.series.column("particles_z12.5");
  const auto& high_particles = record.series.column("particles_z80");
  const auto& collisions = record.series.column("collisions");
  const auto& pair = record.series.column("pair_collisions");
  bool monotone = true;
  for (std::size_t k = 1; k < low.size(); ++k)
    monotone = monotone && low[k] >= low[k - 1] && high[k] >= high[k - 1] &&
               low_particles[k] >= low_particles[k - 1] && high_particles[k] >= high_particles[k - 1] &&
               collisions[k] >= collisions[k - 1];
  std::printf("measured: %g crossings of z = 12.5, %g of z = 80, %g pair collisions; %g and %g "
              "distinct particles per cycle summed\n", low.back(), high.back(), collisions.back(),
              low_particles.back(), high_particles.back());
  EXPECT_TRUE(monotone);
  EXPECT_GT(low.back(), 1000.0);  // the layer is thrown above 12.5 every cycle
  EXPECT_LE(high.back(), low.back());
  EXPECT_EQ(low_particles.front(), 0.0);
  EXPECT_GT(low_particles.back(), 1000.0);
  EXPECT_LE(low_particles.back(), 2.0 * 3937);  // at most every particle in each of 2 cycles
  EXPECT_LE(high_particles.back(), low_particles.back());
  EXPECT_EQ(collisions.back() - collisions.front(), pair.back() - pair.front());
  EXPECT_EQ(collisions.front(), 0.0);  // the first row is the start of the run
  EXPECT_GT(collisions.back(), 1e5);
}

constexpr double base_frequency = 0.095;  // the base case's shaker.frequency

/// A plate of the base case's frequency shaken at peak acceleration gamma g, width x width.
Geometry shaken_plate(double gamma, double width) {
  Geometry g;
  g.width = g.depth = width;
  g.plate = ShakerKinematics{gamma, base_frequency};
  return g;
}

CollisionRules constant_restitution(double e) {
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, e};
  return rules;
}

/// Per height and cycle: upward crossings, distinct particles, and particles at or above the
/// height at the cycle's start.
struct CycleCounts {
  std::vector<std::vector<std::uint64_t>> crossings, distinct, above_at_start;
};

/// Counts `cycles` cycles of the shaker frequency f from sim's time (a cycle boundary): the
/// running counts read at consecutive boundaries, and the positions at each.
CycleCounts count_cycles(Simulation& sim, const std::vector<double>& heights, double f, int cycles) {
  const double first = std::round(sim.time() * f);
  sim.start_height_counts(heights, f);
  CycleCounts out;
  out.crossings.resize(heights.size());
  out.distinct.resize(heights.size());
  out.above_at_start.resize(heights.size());
  std::vector<std::uint64_t> crossings = sim.crossings_at(sim.time()), distinct = sim.distinct_particles_at(sim.time());
  std::vector<Vec3> r, v;
  for (int c = 0; c < cycles; ++c) {
    sim.positions_at(sim.time(), r, v);
    for (std::size_t k = 0; k < heights.size(); ++k)
      out.above_at_start[k].push_back(static_cast<std::uint64_t>(
          std::count_if(r.begin(), r.end(), [&](const Vec3& x) { return x.z >= heights[k]; })));
    sim.advance_to((first + c + 1) / f);
    const std::vector<std::uint64_t> x = sim.crossings_at(sim.time()), d = sim.distinct_particles_at(sim.time());
    for (std::size_t k = 0; k < heights.size(); ++k) {
      out.crossings[k].push_back(x[k] - crossings[k]);
      out.distinct[k].push_back(d[k] - distinct[k]);  // wraps around (fails below) if it fell
    }
    crossings = x;
    distinct = d;
  }
  return out;
}

TEST(MdVibrated, DistinctParticlesPerCycleAreBoundedByCrossingsAndParticlesAbove) {
  // A small vibrated layer with pair collisions (the base case's plate and depth on a 6 x 6
  // plate). A particle counted in a cycle was at or above h at its start or rose through h in
  // it, and every particle above h at the start counts.
  const Geometry g = shaken_plate(3.0, 6.0);
  const std::size_t n = 354;  // the base case's 3937 per 20 x 20
  Simulation sim(g, constant_restitution(0.9), flat_layer(g, n, 17));
  sim.advance_to(2.0 / base_frequency);
  const std::vector<double> heights = {12.5, 20.5, 30.5, 45.5};
  const CycleCounts counts = count_cycles(sim, heights, base_frequency, 4);
  bool bounded = true;
  int differ = 0;  // cycles with fewer distinct particles than crossings plus particles above
  for (std::size_t k = 0; k < heights.size(); ++k) {
    for (std::size_t c = 0; c < counts.distinct[k].size(); ++c) {
      const std::uint64_t d = counts.distinct[k][c], x = counts.crossings[k][c], a = counts.above_at_start[k][c];
      bounded = bounded && a <= d && d <= x + a && d <= n;
      differ += d < x + a ? 1 : 0;
      std::printf("measured: h = %g, cycle %zu: %llu distinct, %llu crossings, %llu above at the start\n",
                  heights[k], c, static_cast<unsigned long long>(d), static_cast<unsigned long long>(x),
                  static_cast<unsigned long long>(a));
    }
  }
  EXPECT_TRUE(bounded);
  EXPECT_GT(differ, 0);  // particles crossing twice in a cycle, or above at its start and crossing
  const std::vector<std::uint64_t>& highest = counts.distinct.back();
  EXPECT_GT(std::accumulate(highest.begin(), highest.end(), std::uint64_t{0}), 0u);
  EXPECT_GT(sim.tally().pair, 10000u);
}

/// Per particle and cycle, from the particles' free flights one by one (independently of the
/// solver's counting): upward crossings of h, at the rising root of z(t) = h, and whether the
/// particle is at or above h at the cycle's start. It reaches h in a cycle exactly if it is
/// above at the start or crosses during it.
class FlightReference {
 public:
  FlightReference(double h, double f, double first_cycle, int cycles, std::size_t n)
      : h_(h), f_(f), first_(first_cycle), cycles_(cycles),
        crossings_(n, std::vector<int>(static_cast<std::size_t>(cycles), 0)),
        above_(n, std::vector<bool>(static_cast<std::size_t>(cycles), false)) {}

  /// The free flight of particle i (state p) over [p.t, end] (gravity 1).
  void add(std::size_t i, const Particle& p, double end) {
    if (p.r.z < h_ && p.v.z > 0.0) {
      const double discriminant = p.v.z * p.v.z - 2.0 * (h_ - p.r.z);
      if (discriminant >= 0.0) {
        const double at = p.t + 2.0 * (h_ - p.r.z) / (p.v.z + std::sqrt(discriminant));
        const double c = std::floor(at * f_) - first_;
        if (at <= end && c >= 0 && c < cycles_) ++crossings_[i][static_cast<std::size_t>(c)];
      }
    }
    for (int c = 0; c < cycles_; ++c) {
      const double start = (first_ + c) / f_, dt = start - p.t;
      if (dt >= 0.0 && start < end && p.r.z + p.v.z * dt - 0.5 * dt * dt >= h_) above_[i][static_cast<std::size_t>(c)] = true;
    }
  }
  std::uint64_t crossings(int c) const {
    std::uint64_t sum = 0;
    for (const auto& particle : crossings_) sum += static_cast<std::uint64_t>(particle[static_cast<std::size_t>(c)]);
    return sum;
  }
  std::uint64_t distinct(int c) const {
    std::uint64_t sum = 0;
    for (std::size_t i = 0; i < crossings_.size(); ++i)
      sum += crossings_[i][static_cast<std::size_t>(c)] > 0 || above_[i][static_cast<std::size_t>(c)] ? 1 : 0;
    return sum;
  }
  /// Particles crossing more than once in a cycle, and particles above h at a cycle's start.
  int repeats() const { return tally([](int crossed, bool) { return crossed > 1; }); }
  int above_at_starts() const { return tally([](int, bool above) { return above; }); }

 private:
  template <class Test> int tally(Test test) const {
    int count = 0;
    for (std::size_t i = 0; i < crossings_.size(); ++i)
      for (std::size_t c = 0; c < crossings_[i].size(); ++c) count += test(crossings_[i][c], above_[i][c]) ? 1 : 0;
    return count;
  }
  double h_, f_, first_;
  int cycles_;
  std::vector<std::vector<int>> crossings_;
  std::vector<std::vector<bool>> above_;
};

bool same_state(const Particle& p, const Particle& q) {
  const double x[] = {p.r.x, p.r.y, p.r.z, p.v.x, p.v.y, p.v.z, p.t};
  const double y[] = {q.r.x, q.r.y, q.r.z, q.v.x, q.v.y, q.v.z, q.t};
  return std::memcmp(x, y, sizeof x) == 0;
}

TEST(MdVibrated, DistinctParticlesEqualCrossingsWhenEachBallCrossesAtMostOnce) {
  // Nine balls on a plate shaken at Gamma = 1.5, inelastic (e = 0.5), straight up and down,
  // too far apart to meet. A twin of the run is stepped event by event to follow every free
  // flight of every ball (FlightReference). Just above the plate's lowest contact height balls
  // chatter, crossing several times in a cycle, and start cycles above it; the two upper
  // heights each ball crosses at most once per cycle and never starts a cycle above them, so
  // there the distinct particles of a cycle are its crossings. The heights are off the cell
  // boundaries (integers), where a flight is cut exactly at h and the reference's root is a
  // rounding away from the cut.
  const Geometry g = shaken_plate(1.5, 18.0);
  const CollisionRules rules = constant_restitution(0.5);
  Random random(23);
  State s;
  for (int k = 0; k < 9; ++k) {
    Particle p;
    p.r = {3.0 + 6.0 * (k % 3), 3.0 + 6.0 * (k / 3), random.uniform(1.5, 6.0)};
    s.particles.push_back(p);
  }
  const std::vector<double> heights = {0.95, 5.3, 9.8};
  const double f = base_frequency;
  const int transient = 2, cycles = 10;
  Simulation counted(g, rules, s), stepped(g, rules, s);
  counted.advance_to(transient / f);
  const CycleCounts counts = count_cycles(counted, heights, f, cycles);

  const double end = (transient + cycles) / f;
  std::vector<FlightReference> reference;
  for (double h : heights) reference.emplace_back(h, f, transient, cycles, s.particles.size());
  std::vector<Particle> last = stepped.particles();
  auto follow = [&](std::size_t i, double until) {
    for (FlightReference& r : reference) r.add(i, last[i], until);
  };
  while (stepped.time() < end) {
    stepped.step();
    for (std::size_t i = 0; i < last.size(); ++i)
      if (!same_state(stepped.particles()[i], last[i])) {
        follow(i, stepped.particles()[i].t);
        last[i] = stepped.particles()[i];
      }
  }
  for (std::size_t i = 0; i < last.size(); ++i) follow(i, end);  // flights under way

  for (std::size_t k = 0; k < reference.size(); ++k)
    for (int c = 0; c < cycles; ++c) {
      const auto at = static_cast<std::size_t>(c);
      EXPECT_EQ(counts.crossings[k][at], reference[k].crossings(c)) << "height " << k << ", cycle " << c;
      EXPECT_EQ(counts.distinct[k][at], reference[k].distinct(c)) << "height " << k << ", cycle " << c;
    }
  std::printf("measured: h = %g: %d repeated crossings, %d cycle starts above\n", heights[0],
              reference[0].repeats(), reference[0].above_at_starts());
  EXPECT_GT(reference[0].repeats(), 0);
  EXPECT_GT(reference[0].above_at_starts(), 0);
  for (std::size_t k = 1; k < heights.size(); ++k) {
    EXPECT_EQ(reference[k].repeats(), 0) << heights[k];  // the construction
    EXPECT_EQ(reference[k].above_at_starts(), 0) << heights[k];
    std::uint64_t crossed = 0;
    for (std::size_t c = 0; c < counts.crossings[k].size(); ++c) {
      EXPECT_EQ(counts.distinct[k][c], counts.crossings[k][c]) << "h = " << heights[k] << ", cycle " << c;
      crossed += counts.crossings[k][c];
    }
    std::printf("measured: h = %g: %llu crossings\n", heights[k], static_cast<unsigned long long>(crossed));
    EXPECT_GT(crossed, 0u) << heights[k];
  }
  EXPECT_EQ(counted.tally().pair, 0u);
}

bool same_bits(const SimulationData& a, const SimulationData& b) {
  if (a.particles.size() != b.particles.size() || a.time != b.time) return false;
  for (std::size_t i = 0; i < a.particles.size(); ++i) {
    const Particle &p = a.particles[i], &q = b.particles[i];
    const double x[] = {p.r.x, p.r.y, p.r.z, p.v.x, p.v.y, p.v.z, p.t, a.last_collision[i]};
    const double y[] = {q.r.x, q.r.y, q.r.z, q.v.x, q.v.y, q.v.z, q.t, b.last_collision[i]};
    if (std::memcmp(x, y, sizeof x) != 0) return false;
    if (a.events[i].time != b.events[i].time || p.counter != q.counter || p.streak != q.streak) return false;
  }
  return a.cell_of == b.cell_of && a.tally.pair == b.tally.pair &&
         a.tally.plate_work == b.tally.plate_work;
}

TEST(MdVibrated, RestartFromCheckpointContinuesBitForBit) {
  const auto dir = testing::test_directory();
  const ShakerKinematics shaker{3.0, 0.095};
  Geometry g;
  g.plate = shaker;
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, 0.9};
  Simulation straight(g, rules, flat_layer(g, 3937, 3));
  straight.advance_to(1.3 / shaker.frequency());
  write_checkpoint(dir / "stop.h5", straight.save(), g, SchedulePosition{}, "test");
  straight.advance_to(2.0 / shaker.frequency());
  Checkpoint saved = read_checkpoint(dir / "stop.h5");
  validate_state(g, saved.data);
  Simulation restarted(g, rules, std::move(saved.data));
  restarted.advance_to(2.0 / shaker.frequency());
  std::printf("measured: %llu collisions after the restart point\n",
              static_cast<unsigned long long>(restarted.tally().pair));
  EXPECT_GT(straight.tally().pair, 100000u);
  EXPECT_TRUE(same_bits(straight.save(), restarted.save()));
}

/// A line of the summary `shaker md` prints: collisions over a span, their parts and the
/// collapse guard's activations over the same span.
struct CollisionLine {
  unsigned long long total = 0, pair = 0, plate = 0, ceiling = 0, guard = 0;
};

/// The summary's collision lines by their span ("" for a run that continues nothing), from
/// the text the run printed.
std::map<std::string, CollisionLine> collision_lines(const std::string& printed) {
  std::map<std::string, CollisionLine> out;
  std::istringstream lines(printed);
  const std::string start = "  collisions";
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(start, 0) != 0) continue;
    const std::string guard_label = "collapse guard activations ";
    const std::size_t colon = line.find(": "), guard_at = line.rfind(guard_label);
    CollisionLine c;
    const bool parsed =
        colon != std::string::npos && guard_at != std::string::npos &&
        std::sscanf(line.c_str() + colon + 2, "%llu (pair %llu, plate %llu, ceiling %llu)", &c.total,
                    &c.pair, &c.plate, &c.ceiling) == 4 &&
        std::sscanf(line.c_str() + guard_at + guard_label.size(), "%llu", &c.guard) == 1;
    EXPECT_TRUE(parsed) << line;
    out[line.substr(start.size(), colon - start.size())] = c;
  }
  return out;
}

/// `run(config)` with what it prints to stdout.
std::string printed_by_run(const config::Config& config) {
  ::testing::internal::CaptureStdout();
  const int status = run(config);
  std::string printed = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(status, 0) << printed;
  return printed;
}

TEST(MdVibrated, RestartThroughTheRunDriverMatchesAStraightRun) {
  // shaker md for 2 cycles with run.checkpoint, then the 3-cycle run continued from it with
  // run.restart_from, against the 3-cycle run straight through.
  const auto dir = testing::test_directory();
  config::Config first = base_case(dir / "a.h5");
  first.set("md.crossing_heights=[12.5]");
  first.set("run.transient_cycles=1");
  first.set("run.sampled_cycles=1");
  first.set("run.checkpoint=" + (dir / "a-end.h5").string());
  const auto first_lines = collision_lines(printed_by_run(first));
  config::Config second = base_case(dir / "b.h5");
  second.set("md.crossing_heights=[12.5]");
  second.set("run.transient_cycles=1");
  second.set("run.sampled_cycles=2");
  second.set("run.restart_from=" + (dir / "a-end.h5").string());
  second.set("run.checkpoint=" + (dir / "b-end.h5").string());
  const auto continued_lines = collision_lines(printed_by_run(second));
  config::Config straight = base_case(dir / "c.h5");
  straight.set("md.crossing_heights=[12.5]");
  straight.set("run.transient_cycles=1");
  straight.set("run.sampled_cycles=2");
  straight.set("run.checkpoint=" + (dir / "c-end.h5").string());
  const auto straight_lines = collision_lines(printed_by_run(straight));
  const Checkpoint b = read_checkpoint(dir / "b-end.h5"), c = read_checkpoint(dir / "c-end.h5");
  EXPECT_NEAR(b.data.time, 3.0 / 0.095, 1e-12);
  EXPECT_TRUE(same_bits(b.data, c.data));
  // The counts restart with the run (they are not in checkpoints); the restarted run's last
  // cycle has the straight run's counts.
  const RunRecord restarted = read_run_file(dir / "b.h5"), whole = read_run_file(dir / "c.h5");
  const auto& t = whole.series.column("t");
  const auto cycle_start = static_cast<std::size_t>(std::find(t.begin(), t.end(), 2.0 / 0.095) - t.begin());
  ASSERT_LT(cycle_start, t.size());
  for (const char* name : {"crossings_z12.5", "particles_z12.5"}) {
    const auto& part = restarted.series.column(name);
    const auto& all = whole.series.column(name);
    EXPECT_EQ(part.front(), 0.0) << name;
    EXPECT_EQ(part.back(), all.back() - all[cycle_start]) << name;
    EXPECT_GT(part.back(), 0.0) << name;
  }

  // The summary: a straight run prints one collision line, a continuation two, one over
  // itself and one since the first run's start; every total is the sum of its parts.
  ASSERT_EQ(first_lines.size(), 1u);
  ASSERT_EQ(straight_lines.size(), 1u);
  ASSERT_EQ(continued_lines.size(), 2u);
  const CollisionLine &before = first_lines.at(""), &whole_run = straight_lines.at("");
  const CollisionLine& here = continued_lines.at(" in this continuation");
  const CollisionLine& since = continued_lines.at(" since the start of the run that wrote the first checkpoint");
  for (const CollisionLine* line : {&before, &whole_run, &here, &since})
    EXPECT_EQ(line->total, line->pair + line->plate + line->ceiling);
  // Since the first start: the straight run's counts; in the continuation: the straight run's
  // less the first run's.
  for (auto member : {&CollisionLine::total, &CollisionLine::pair, &CollisionLine::plate,
                      &CollisionLine::ceiling, &CollisionLine::guard}) {
    EXPECT_EQ(since.*member, whole_run.*member);
    EXPECT_EQ(here.*member, whole_run.*member - before.*member);
  }
  EXPECT_GT(here.pair, 0u);
  EXPECT_GT(before.pair, 0u);
  // The time series count as docs/output-schema.md says: pair_collisions a running total
  // continued across the checkpoint, collisions the pair collisions of this run alone.
  EXPECT_EQ(restarted.series.column("pair_collisions").back(), static_cast<double>(since.pair));
  EXPECT_EQ(whole.series.column("pair_collisions").back(), static_cast<double>(whole_run.pair));
  EXPECT_EQ(restarted.series.column("collisions").back(), static_cast<double>(here.pair));
  EXPECT_EQ(whole.series.column("collisions").back(), static_cast<double>(whole_run.pair));
  std::printf("measured: collisions %llu straight = %llu before the checkpoint + %llu in the continuation\n",
              whole_run.total, before.total, here.total);
}

TEST(MdVibrated, CollapseIsDetectedAndReportedForLowE) {
  const auto dir = testing::test_directory();
  config::Config c = base_case(dir / "collapse.h5");
  c.set("material.e=0.7");  // paper: collapse below about e = 0.8
  c.set("run.transient_cycles=3");
  c.set("run.sampled_cycles=1");
  std::string message;
  try {
    run(c);
  } catch (const CollapseError& error) {
    message = error.what();
  }
  std::printf("measured: %s\n", message.c_str());
  EXPECT_NE(message.find("inelastic collapse at t = "), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "collapse.h5"));
}

TEST(MdVibrated, TcGuardLetsLowERunAndCountsActivations) {
  const auto dir = testing::test_directory();
  config::Config c = base_case(dir / "guarded.h5");
  c.set("material.e=0.7");
  c.set("md.collapse_guard=tc");
  c.set("md.tc=1e-3");
  c.set("run.transient_cycles=1");
  c.set("run.sampled_cycles=1");
  ASSERT_EQ(run(c), 0);
  const RunRecord record = read_run_file(dir / "guarded.h5");
  const double activations = record.series.column("guard_activations").back();
  std::printf("measured: %g guard activations\n", activations);
  EXPECT_GT(activations, 0.0);
  EXPECT_NE(record.model_variant.find("TC guard"), std::string::npos);
}

TEST(MdVibrated, SingleShockSwitchesRestitutionAtTheGivenPhase) {
  const auto dir = testing::test_directory();
  config::Config c = base_case(dir / "shock.h5");
  c.set("run.protocol=single_shock");
  c.set("run.transient_cycles=2");
  c.set("run.switch_e=1.0");
  ASSERT_EQ(run(c), 0);
  const RunRecord record = read_run_file(dir / "shock.h5");
  EXPECT_EQ(record.profiles.size(), 50u);
  EXPECT_EQ(record.e, 1.0);
  const auto& t = record.series.column("t");
  const auto& loss = record.series.column("accumulated_collisional_loss");
  const double switch_time = (2.0 - 0.33) / 0.095;
  // Before the switch the layer dissipates; after it only wall-rule rounding remains.
  double before = 0.0, after = 0.0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    const double d = std::fabs(loss[k] - loss[k - 1]);
    if (t[k] <= switch_time) before = std::max(before, d);
    if (t[k - 1] >= switch_time) after = std::max(after, d);
  }
  std::printf("measured: largest loss per interval before %.4g, after %.3g\n", before, after);
  EXPECT_GT(before, 100.0);
  EXPECT_LT(after, 1e-6);
}

// ---- MD ensembles (md.replicas, docs/parallel.md) ----

/// The tiny case of verification/mpi/check_md_ensemble.py: 40 particles, 1 + 2 cycles of 5 phases.
config::Config tiny_case(const std::filesystem::path& output, const std::string& protocol) {
  config::Config c;
  for (const char* assignment : {"layer.particles=40", "md.box_width=4.0", "md.ceiling=60.0",
                                 "run.transient_cycles=1", "run.sampled_cycles=2",
                                 "run.phases_per_cycle=5", "run.seed=7"})
    c.set(assignment);
  c.set("run.protocol=" + protocol);
  c.set("run.output=" + output.string());
  return c;
}

void expect_same_series(const TimeSeries& a, const TimeSeries& b, const std::string& what) {
  ASSERT_EQ(a.names, b.names) << what;
  for (std::size_t i = 0; i < a.names.size(); ++i) {
    ASSERT_EQ(a.columns[i].size(), b.columns[i].size()) << what << " " << a.names[i];
    for (std::size_t k = 0; k < a.columns[i].size(); ++k)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(a.columns[i][k]), std::bit_cast<std::uint64_t>(b.columns[i][k]))
          << what << " " << a.names[i] << "[" << k << "]: " << a.columns[i][k] << " vs " << b.columns[i][k];
  }
}

TEST(MdEnsemble, EveryReplicasTimeSeriesIsThatOfItsSingleRun) {
  // md.replicas = 3 in one process: replica r's series in the run file (replica 0's in
  // /timeseries, the others' in /replica_timeseries) equals, bit for bit, the series of a
  // single run of seed run.seed + r (periodic) or of run.transient_cycles + r (single shock).
  const auto dir = testing::test_directory();
  constexpr std::size_t replicas = 3, phases = 5;
  for (const std::string protocol : {"periodic", "single_shock"}) {
    config::Config ensemble = tiny_case(dir / (protocol + "-ensemble.h5"), protocol);
    ensemble.set("md.replicas=" + std::to_string(replicas));
    ASSERT_EQ(run(ensemble), 0);
    const RunRecord pooled = read_run_file(dir / (protocol + "-ensemble.h5"));
    ASSERT_EQ(pooled.replica_series.size(), replicas - 1) << protocol;
    const std::string varied = protocol == "periodic" ? "run.seed" : "run.transient_cycles";
    for (std::size_t r = 0; r < replicas; ++r) {
      const std::string name = protocol + "-single" + std::to_string(r) + ".h5";
      config::Config single = tiny_case(dir / name, protocol);
      single.set(varied + "=" + std::to_string(single.integer(varied) + static_cast<std::int64_t>(r)));
      ASSERT_EQ(run(single), 0);
      const RunRecord alone = read_run_file(dir / name);
      EXPECT_TRUE(alone.replica_series.empty()) << name;
      const TimeSeries& series = r == 0 ? pooled.series : pooled.replica_series[r - 1];
      // A row at every stored phase of every cycle, transient included, and one at the end;
      // the single shock's replica r runs r more transient cycles, then the recorded one.
      const std::size_t cycles = protocol == "periodic" ? 1 + 2 : 1 + r + 1;
      const std::string what = protocol + " replica " + std::to_string(r);
      EXPECT_EQ(series.column("com_z").size(), cycles * phases + 1) << what;
      expect_same_series(series, alone.series, what);
    }
  }
}

TEST(MdRectangularBox, ElasticGasConservesEnergyAndStaysInsideTheBox) {
  // A box 6 wide and 14 deep: the y extent is its own in the cell list, the minimum image and
  // the wrapping. Elastic gas above a fixed plate: kinetic plus potential energy is conserved,
  // and every particle stays in [0, 6) x [0, 14), reaching beyond y = 6.
  Geometry g;
  g.width = 6.0;
  g.depth = 14.0;
  g.height = 60.0;
  g.plate = ShakerKinematics::fixed_plate();
  const std::size_t n = 400;
  Simulation sim(g, constant_restitution(1.0), homogeneous_gas(g, n, 0.2, 3.0, 5));
  const double e0 = sim.kinetic_energy(sim.time()) + sim.potential_energy(sim.time());
  std::vector<Vec3> r, v;
  bool inside = true;
  std::size_t beyond_width = 0;
  for (int s = 1; s <= 50; ++s) {
    sim.advance_to(1.0 * s);
    sim.positions_at(sim.time(), r, v);
    for (const Vec3& x : r) {
      inside = inside && x.x >= 0.0 && x.x < g.width && x.y >= 0.0 && x.y < g.depth && x.z >= 0.5 && x.z <= 59.5;
      beyond_width += x.y > g.width ? 1 : 0;
    }
  }
  const double drift = std::fabs(sim.kinetic_energy(sim.time()) + sim.potential_energy(sim.time()) - e0) / e0;
  std::printf("measured: relative energy drift %.3g after %llu pair collisions; %zu positions beyond y = 6\n",
              drift, static_cast<unsigned long long>(sim.tally().pair), beyond_width);
  EXPECT_GT(sim.tally().pair, 10000u);
  EXPECT_LT(drift, 1e-10);
  EXPECT_TRUE(inside);
  EXPECT_GT(beyond_width, 50u * n / 4);  // more than half the box's area lies beyond y = 6
  EXPECT_EQ(sim.count_overlaps(sim.time(), 1e-9), 0u);
  EXPECT_TRUE(sim.queue_consistent());
}

TEST(MdInitialPerturbation, LiftsEachColumnByASeededHeightBelowTheAmplitude) {
  Geometry g;
  g.width = 8.0;
  g.depth = 12.0;
  g.plate = ShakerKinematics{3.0, base_frequency};
  const std::size_t n = 500;
  const State flat = flat_layer(g, n, 7), lifted = flat_layer(g, n, 7, 0.5);
  const State again = flat_layer(g, n, 7, 0.5), other = flat_layer(g, n, 8, 0.5);
  double largest = 0.0, smallest = 1.0;
  bool same_xy = true, reproducible = true, differs = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 a = flat.particles[i].r, b = lifted.particles[i].r;
    same_xy = same_xy && a.x == b.x && a.y == b.y;
    largest = std::max(largest, b.z - a.z);
    smallest = std::min(smallest, b.z - a.z);
    reproducible = reproducible && b.z == again.particles[i].r.z;
    differs = differs || b.z != other.particles[i].r.z;
  }
  std::printf("measured: lifts from %.4f to %.4f (amplitude 0.5)\n", smallest, largest);
  EXPECT_TRUE(same_xy);   // the lift moves the layer's sites only up
  EXPECT_GE(smallest, 0.0);
  EXPECT_LT(largest, 0.5);
  EXPECT_GT(largest, 0.45);  // 80 columns: the largest of 80 uniform lifts is this close to 0.5
  EXPECT_TRUE(reproducible);
  EXPECT_TRUE(differs);
  Simulation sim(g, constant_restitution(0.9), lifted);
  EXPECT_EQ(sim.count_overlaps(sim.time(), 1e-9), 0u);
  const State unlifted = flat_layer(g, n, 7, 0.0);
  bool identical = true;
  for (std::size_t i = 0; i < n; ++i) identical = identical && unlifted.particles[i].r.z == flat.particles[i].r.z;
  EXPECT_TRUE(identical);  // amplitude 0 is the flat layer bit for bit
}

TEST(MdHydrostatic, ElasticGasUnderGravityIsIsothermalAndHydrostatic) {
  Geometry g;
  g.width = g.depth = 10.0;
  g.height = 100.0;  // the gas never reaches the ceiling
  g.plate = ShakerKinematics::fixed_plate();
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, 1.0};
  const std::size_t n = 1500;
  Simulation sim(g, rules, homogeneous_gas(g, n, 0.2, 3.0, 21));
  sim.advance_to(100.0);  // relax
  const int bins = 100;
  const double dz = 1.0;
  std::vector<double> count(bins, 0.0), v2(bins, 0.0);
  std::vector<Vec3> r, v;
  const int snapshots = 400;
  for (int s = 0; s < snapshots; ++s) {
    sim.advance_to(100.0 + 1.0 * (s + 1));
    sim.positions_at(sim.time(), r, v);
    for (std::size_t i = 0; i < n; ++i) {
      const auto b = static_cast<int>(std::floor(r[i].z / dz));
      if (b < bins) {
        count[b] += 1.0;
        v2[b] += dot(v[i], v[i]);
      }
    }
  }
  // Temperature in the well-populated bins (mean velocity is zero at rest).
  double T_mean = 0.0, weight = 0.0;
  for (int b = 1; b < 20; ++b) {
    T_mean += v2[b] / 3.0;
    weight += count[b];
  }
  T_mean /= weight;
  double worst_T = 0.0;
  for (int b = 1; b < 20; ++b) worst_T = std::max(worst_T, std::fabs(v2[b] / (3.0 * count[b]) / T_mean - 1.0));
  // Hydrostatics: the Carnahan-Starling pressure at the measured density must equal the
  // weight per unit area of the material above (the ceiling is out of reach). The local
  // equation of state does not hold in the layered fluid within a few diameters of the plate,
  // so the check starts at z = 4.
  std::vector<double> density(bins);
  for (int b = 0; b < bins; ++b) density[b] = count[b] / (snapshots * g.width * g.width * dz);
  double worst_p = 0.0;
  for (int b = 4; b <= 30; b += 2) {
    double above = 0.5 * density[b] * dz;
    for (int k = b + 1; k < bins; ++k) above += density[k] * dz;
    const double p = density[b] * T_mean * model::compressibility_carnahan_starling(volume_fraction(density[b]));
    worst_p = std::max(worst_p, std::fabs(p / above - 1.0));
  }
  std::printf("measured: T uniform to %.4f, hydrostatic balance to %.4f (T = %.4f)\n", worst_T,
              worst_p, T_mean);
  EXPECT_LT(worst_T, 0.03);
  EXPECT_LT(worst_p, 0.03);
}

}  // namespace
}  // namespace shaker::md
