// Exact kinematics of single events: pair collisions, the fixed and the oscillating plate,
// and no missed collisions across cells and periodic boundaries.
#include <algorithm>
#include <cmath>
#include <vector>

#include "md/initial_states.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

Geometry open_box(double width) {
  Geometry g;
  g.periodic_z = true;
  g.gravity = 0.0;
  g.width = g.depth = g.height = width;
  return g;
}

State two_particles(Vec3 r1, Vec3 v1, Vec3 r2, Vec3 v2) {
  State s;
  s.particles.resize(2);
  s.particles[0].r = r1;
  s.particles[0].v = v1;
  s.particles[1].r = r2;
  s.particles[1].v = v2;
  return s;
}

CollisionRules constant_e(double e) {
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, e};
  return rules;
}

TEST(MdKinematics, HeadOnCollisionTimeVelocitiesAndLoss) {
  const double e = 0.8;
  Simulation sim(open_box(10.0), constant_e(e),
                 two_particles({3.0, 5.0, 5.0}, {1.0, 0.0, 0.0}, {7.0, 5.0, 5.0}, {-0.5, 0.0, 0.0}));
  while (sim.tally().pair == 0) sim.step();
  EXPECT_NEAR(sim.time(), 3.0 / 1.5, 1e-14);  // gap 4 - 1 closed at relative speed 1.5
  const auto& p = sim.particles();
  const double vn = -1.5, j = 0.5 * (1.0 + e) * vn;  // normal k = -x from 1 to 0
  EXPECT_NEAR(p[0].v.x, 1.0 + j, 1e-15);
  EXPECT_NEAR(p[1].v.x, -0.5 - j, 1e-15);
  EXPECT_NEAR(p[0].v.x + p[1].v.x, 0.5, 1e-15);  // momentum
  EXPECT_NEAR(sim.tally().pair_loss, 0.25 * (1.0 - e * e) * vn * vn, 1e-15);
  const double before = 0.5 * (1.0 + 0.25), after = 0.5 * (p[0].v.x * p[0].v.x + p[1].v.x * p[1].v.x);
  EXPECT_NEAR(before - after, sim.tally().pair_loss, 1e-15);
}

TEST(MdKinematics, ObliqueCollisionKeepsTangentialVelocity) {
  const double e = 0.7, b = 0.6;  // impact parameter
  Simulation sim(open_box(10.0), constant_e(e),
                 two_particles({2.0, 5.0, 5.0}, {2.0, 0.0, 0.0}, {6.0, 5.0 + b, 5.0}, {0.0, 0.0, 0.0}));
  while (sim.tally().pair == 0) sim.step();
  const double contact_x = 6.0 - std::sqrt(1.0 - b * b);
  EXPECT_NEAR(sim.time(), (contact_x - 2.0) / 2.0, 1e-14);
  const auto& p = sim.particles();
  const Vec3 k{-std::sqrt(1.0 - b * b), -b, 0.0};  // from particle 1 to 0 at contact
  const double vn = 2.0 * k.x;
  const Vec3 v0 = p[0].v, v1 = p[1].v;
  EXPECT_NEAR(dot(v0 - v1, k), -e * vn, 1e-14);             // normal rule
  const Vec3 t{-k.y, k.x, 0.0};                              // in-plane tangent
  EXPECT_NEAR(dot(v0 - v1, t), dot(Vec3{2.0, 0.0, 0.0}, t), 1e-14);
  EXPECT_NEAR(v0.x + v1.x, 2.0, 1e-15);
  EXPECT_NEAR(v0.y + v1.y, 0.0, 1e-15);
  EXPECT_NEAR(2.0 - 0.5 * (dot(v0, v0) + dot(v1, v1)), 0.25 * (1.0 - e * e) * vn * vn, 1e-14);
}

TEST(MdKinematics, CollisionAcrossThePeriodicBoundaryAfterManyCells) {
  // 0 at x = 1 moves left, 1 at x = 7 moves right: they meet through x = 0 after crossing cells.
  Simulation sim(open_box(10.0), constant_e(1.0),
                 two_particles({1.0, 5.2, 4.9}, {-1.0, 0.0, 0.0}, {7.0, 5.0, 5.0}, {1.0, 0.0, 0.0}));
  while (sim.tally().pair == 0) sim.step();
  const double gap_x = 10.0 - 6.0, dy = 0.2, dz = -0.1;  // separation through the boundary
  const double contact_dx = std::sqrt(1.0 - dy * dy - dz * dz);
  EXPECT_NEAR(sim.time(), (gap_x - contact_dx) / 2.0, 1e-13);
  EXPECT_GE(sim.tally().cell, 2u);
}

/// Independent reference: the earliest contact of any pair, all 27 images, no cells or queue.
double brute_force_next_contact(const std::vector<Vec3>& r, const std::vector<Vec3>& v, double L) {
  double best = never;
  for (std::size_t i = 0; i < r.size(); ++i)
    for (std::size_t j = i + 1; j < r.size(); ++j)
      for (int sx = -1; sx <= 1; ++sx)
        for (int sy = -1; sy <= 1; ++sy)
          for (int sz = -1; sz <= 1; ++sz) {
            const Vec3 shift{sx * L, sy * L, sz * L};
            best = std::min(best, pair_contact_delay(r[i] - r[j] - shift, v[i] - v[j]));
          }
  return best;
}

TEST(MdKinematics, NoMissedCollisionsAgainstAllPairsReference) {
  // Gas chaos forbids comparing whole trajectories, so after every collision the all-pairs
  // search predicts the next one from the solver's own state.
  const std::size_t n = 40;
  const Geometry g = periodic_box(n, 0.15);
  Simulation sim(g, constant_e(1.0), homogeneous_gas(g, n, 0.15, 1.0, 7));
  std::vector<Vec3> r, v;
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    sim.positions_at(sim.time(), r, v);
    const double expected = sim.time() + brute_force_next_contact(r, v, g.width);
    const auto before = sim.tally().pair;
    while (sim.tally().pair == before) sim.step();
    worst = std::max(worst, std::fabs(sim.time() - expected));
  }
  EXPECT_LT(worst, 1e-10) << "largest difference over 2000 collisions";
  EXPECT_GT(sim.tally().cell, 1000u);
}

Geometry plate_box(double amplitude, double omega) {
  Geometry g;
  g.width = g.depth = 5.0;
  g.height = 400.0;
  g.gravity = 1.0;
  g.plate = ShakerKinematics::of_amplitude(amplitude, omega);
  return g;
}

TEST(MdKinematics, BallOnFixedPlateHeightsShrinkByESquared) {
  const double e = 0.9, h0 = 3.0;
  State s;
  s.particles.resize(1);
  s.particles[0].r = {2.5, 2.5, 0.5 + h0};
  Simulation sim(plate_box(0.0, 1.0), constant_e(e), s);
  std::vector<double> impacts, speeds;
  while (impacts.size() < 12) {
    const auto before = sim.tally().plate;
    sim.step();
    if (sim.tally().plate > before) {
      impacts.push_back(sim.time());
      speeds.push_back(sim.particles()[0].v.z);
    }
  }
  double expected = std::sqrt(2.0 * h0), v = std::sqrt(2.0 * h0), worst_time = 0.0, worst_ratio = 0.0;
  for (std::size_t k = 0; k < impacts.size(); ++k) {
    worst_time = std::max(worst_time, std::fabs(impacts[k] - expected));
    v *= e;
    expected += 2.0 * v;
    if (k > 0) {
      const double ratio = (speeds[k] * speeds[k]) / (speeds[k - 1] * speeds[k - 1]);  // apex ratio
      worst_ratio = std::max(worst_ratio, std::fabs(ratio - e * e));
    }
  }
  EXPECT_LT(worst_time, 1e-12);
  EXPECT_LT(worst_ratio, 1e-12);
}

TEST(MdKinematics, UpwardCrossingsOfABallThrownUpFromAFixedPlate) {
  // Thrown up at v0 from the plate: after k bounces it rises e^(2k) v0^2 / 2 above the contact
  // height 1/2, so it crosses h upwards once in each flight with e^(2k) v0^2 / 2 >= h - 1/2.
  // The heights are chosen away from every apex; one is never reached, one only in flight 0.
  const double e = 0.9, v0 = 6.0;
  const std::vector<double> heights = {0.6, 5.0, 12.0, 18.0, 19.0};
  State s;
  s.particles.resize(1);
  s.particles[0].r = {2.5, 2.5, 0.5 + 1e-12};
  s.particles[0].v = {0.0, 0.0, v0};
  Simulation sim(plate_box(0.0, 1.0), constant_e(e), s);
  sim.start_height_counts(heights, 1.0);
  std::vector<std::uint64_t> expected(heights.size(), 0);
  std::vector<std::uint64_t> previous(heights.size(), 0);
  bool monotone = true;
  for (int flight = 0; flight < 60; ++flight) {  // flights 0..59, all complete by the end
    const double rise = std::pow(e, 2.0 * flight) * v0 * v0 / 2.0;
    for (std::size_t k = 0; k < heights.size(); ++k) expected[k] += rise >= heights[k] - 0.5 ? 1 : 0;
  }
  const double total_time = 2.0 * v0 * (1.0 - std::pow(e, 60.0)) / (1.0 - e);
  for (int sample = 1; sample <= 400; ++sample) {  // counts between events too
    sim.advance_to(total_time * sample / 400.0 - 1e-6);
    const std::vector<std::uint64_t> now = sim.crossings_at(sim.time());
    for (std::size_t k = 0; k < heights.size(); ++k) monotone = monotone && now[k] >= previous[k];
    previous = now;
  }
  const std::vector<std::uint64_t> counted = sim.crossings_at(sim.time());
  for (std::size_t k = 0; k < heights.size(); ++k) {
    std::printf("measured: h = %g: %llu upward crossings (analytic %llu)\n", heights[k],
                static_cast<unsigned long long>(counted[k]), static_cast<unsigned long long>(expected[k]));
    EXPECT_EQ(counted[k], expected[k]) << "h = " << heights[k];
  }
  EXPECT_EQ(expected[4], 0u);  // 19 is above the first apex 18.5
  EXPECT_EQ(expected[3], 1u);
  EXPECT_TRUE(monotone);
}

TEST(MdKinematics, CrossingsCountOnlyFlightsAfterCountingStarts) {
  // A ball rising through h = 3 before counting starts is not counted; the next flight is.
  State s;
  s.particles.resize(1);
  s.particles[0].r = {2.5, 2.5, 0.5 + 1e-12};
  s.particles[0].v = {0.0, 0.0, 4.0};  // apex 8.5, first landing at t = 8
  Simulation sim(plate_box(0.0, 1.0), constant_e(1.0), s);
  sim.advance_to(2.0);  // at z = 6.5: h = 3 already crossed in this flight
  sim.start_height_counts({3.0}, 1.0);
  EXPECT_EQ(sim.crossings_at(2.0)[0], 0u);
  sim.advance_to(7.9);
  EXPECT_EQ(sim.crossings_at(7.9)[0], 0u);
  sim.advance_to(9.0);  // bounced at t = 8, at z = 0.5 + 4 - 0.5 = 4 > 3 again
  EXPECT_EQ(sim.crossings_at(9.0)[0], 1u);
  sim.advance_to(17.0);
  EXPECT_EQ(sim.crossings_at(17.0)[0], 2u);
}

/// A ball of plate_box at (x, y, z) moving straight up or down at vz (it never meets a ball at
/// another (x, y) at least one diameter away).
Particle vertical_ball(double x, double y, double z, double vz) {
  Particle p;
  p.r = {x, y, z};
  p.v = {0.0, 0.0, vz};
  return p;
}

/// The per-cycle counts from running counts read at consecutive cycle boundaries.
std::vector<std::uint64_t> per_cycle(const std::vector<std::vector<std::uint64_t>>& readings, std::size_t k) {
  std::vector<std::uint64_t> counts;
  for (std::size_t c = 1; c < readings.size(); ++c) counts.push_back(readings[c][k] - readings[c - 1][k]);
  return counts;
}

TEST(MdKinematics, DistinctParticlesPerCycleOfElasticBallsOnAFixedPlate) {
  // Five balls bounce elastically straight up and down on the fixed plate (contact at z = 1/2),
  // in cycles of length 8 (f = 1/8). A starts at rest at its apex 6.5; B, C, E, F leave the
  // plate at speeds 2.4, 1, 3.2 and 7 (apexes 3.38, 1, 5.62, 25; bounce periods 4.8, 2, 6.4,
  // 14; A's is 2 sqrt(12)). A ball is at or above h within (apex time) +- sqrt(2 (apex - h)):
  //   h = 2.5: A in [0, 2.83], [4.10, 9.76], [11.03, 16.68], [17.96, 23.61], [24.88, 30.54],
  //            [31.81, ...]; B in [1.07, 3.73] + 4.8 k; E in [0.70, 5.70] + 6.4 k;
  //            F in [0.29, 13.71] + 14 k; C never.
  //   h = 4.5: A in [0, 2], [4.93, 8.93], [11.86, 15.86], [18.79, 22.79], [25.71, 29.71];
  //            E in [1.70, 4.70] + 6.4 k; F in [0.60, 13.40] + 14 k; B and C never.
  //   h = 22:  F only, in [4.55, 9.45] and [18.55, 23.45]: not in the last cycle.
  // A is above every h but 22 when counting starts. Flights across t = 8 or 16 (A, B, E, F at
  // 2.5; A and F at t = 8, E and F at t = 16 at 4.5; F at t = 8 at 22) count in both cycles,
  // once per ball, while B rises through 2.5 twice in cycles 0, 1 and 3 and E through 4.5
  // twice in cycle 1.
  const double f = 0.125;
  const std::vector<double> heights = {2.5, 4.5, 22.0};
  State s;
  s.particles = {vertical_ball(1.0, 1.0, 6.5, 0.0), vertical_ball(1.0, 3.5, 0.5 + 1e-12, 2.4),
                 vertical_ball(3.5, 1.0, 0.5 + 1e-12, 1.0), vertical_ball(3.5, 3.5, 0.5 + 1e-12, 3.2),
                 vertical_ball(2.25, 2.25, 0.5 + 1e-12, 7.0)};
  Simulation sim(plate_box(0.0, 1.0), constant_e(1.0), s);
  sim.start_height_counts(heights, f);
  std::vector<std::vector<std::uint64_t>> distinct{sim.distinct_particles_at(0.0)}, crossings{sim.crossings_at(0.0)};
  bool monotone = true;
  for (int cycle = 0; cycle < 4; ++cycle) {
    std::vector<std::uint64_t> previous = distinct.back();
    for (int step = 1; step <= 40; ++step) {  // readings between events too
      const double t = (cycle + step / 40.0) / f;
      sim.advance_to(t);
      const std::vector<std::uint64_t> now = sim.distinct_particles_at(t);
      for (std::size_t k = 0; k < heights.size(); ++k)
        monotone = monotone && now[k] >= previous[k] && now[k] <= distinct.back()[k] + s.particles.size();
      previous = now;
    }
    distinct.push_back(sim.distinct_particles_at(sim.time()));
    crossings.push_back(sim.crossings_at(sim.time()));
  }
  using Counts = std::vector<std::uint64_t>;
  EXPECT_EQ(distinct.front(), Counts(3, 0));
  EXPECT_EQ(per_cycle(distinct, 0), Counts({4, 4, 4, 4}));
  EXPECT_EQ(per_cycle(crossings, 0), Counts({6, 5, 3, 6}));
  EXPECT_EQ(per_cycle(distinct, 1), Counts({3, 3, 3, 3}));
  EXPECT_EQ(per_cycle(crossings, 1), Counts({3, 4, 2, 3}));
  EXPECT_EQ(per_cycle(distinct, 2), Counts({1, 1, 1, 0}));
  EXPECT_EQ(per_cycle(crossings, 2), Counts({1, 0, 1, 0}));
  EXPECT_TRUE(monotone);
  EXPECT_EQ(sim.tally().pair, 0u);
}

TEST(MdKinematics, DistinctParticlesCountOnlyFromWhenCountingStarts) {
  // Thrown up at 4 from the plate: at or above h = 7.9 in [2.90, 5.10] and, after the bounce
  // at t = 8, in [10.90, 13.10]. Counting starts at t = 5.5 in cycle 0 = [0, 8): the flight
  // under way (no cell crossing above z = 3 updates it) reached h before, so cycle 0 counts
  // nothing and cycle 1 one particle.
  State s;
  s.particles = {vertical_ball(2.5, 2.5, 0.5 + 1e-12, 4.0)};
  Simulation sim(plate_box(0.0, 1.0), constant_e(1.0), s);
  sim.advance_to(5.5);
  sim.start_height_counts({7.9}, 0.125);
  EXPECT_EQ(sim.distinct_particles_at(5.5)[0], 0u);
  sim.advance_to(8.0);
  EXPECT_EQ(sim.distinct_particles_at(8.0)[0], 0u);
  sim.advance_to(16.0);
  EXPECT_EQ(sim.distinct_particles_at(16.0)[0], 1u);
  EXPECT_EQ(sim.crossings_at(16.0)[0], 1u);
}

/// Independent reference for the oscillating plate: dense scan + long double bisection.
long double reference_impact(long double t0, long double z0, long double v0, long double A,
                             long double w) {
  auto gap = [&](long double t) {
    const long double s = t - t0;
    return z0 + v0 * s - 0.5L * s * s - 0.5L - A * (1.0L - std::cos(w * t));
  };
  const long double step = 1e-4L;
  long double a = t0 + 1e-9L;
  while (gap(a + step) > 0.0L) a += step;
  long double b = a + step;
  for (int k = 0; k < 200; ++k) {
    const long double m = 0.5L * (a + b);
    (gap(m) > 0.0L ? a : b) = m;
  }
  return 0.5L * (a + b);
}

TEST(MdKinematics, BallOnOscillatingPlateMatchesIndependentRootFinder) {
  const ShakerKinematics shaker{3.0, 0.095};
  const double e = 0.9;
  State s;
  s.particles.resize(1);
  s.particles[0].r = {2.5, 2.5, 6.0};
  // The reference has no ceiling: put it out of reach (the ball gains energy from the plate;
  // at 400 a rounding-level different path reached it within 40 impacts).
  Geometry g = plate_box(shaker.amplitude(), shaker.omega());
  g.height = 1e5;
  Simulation sim(g, constant_e(e), s);
  // The bouncing ball is chaotic, so each impact is compared from the state the solver had
  // after the previous one: the difference measures the root finding alone.
  long double t = 0.0L, z = 6.0L, v = 0.0L;
  double worst = 0.0;
  int impacts = 0;
  while (impacts < 40) {
    const auto before = sim.tally().plate;
    sim.step();
    if (sim.tally().plate == before) continue;
    ++impacts;
    const long double tr = reference_impact(t, z, v, shaker.amplitude(), shaker.omega());
    worst = std::max(worst, static_cast<double>(std::fabs(tr - sim.time())));
    t = sim.time();
    z = sim.particles()[0].r.z;
    v = sim.particles()[0].v.z;
  }
  EXPECT_LT(worst, 1e-11) << "largest impact-time difference over 40 impacts";
  EXPECT_EQ(sim.tally().ceiling, 0u);
}

}  // namespace
}  // namespace shaker::md
