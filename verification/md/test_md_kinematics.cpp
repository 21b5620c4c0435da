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
  g.width = g.height = width;
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
  g.width = 5.0;
  g.height = 400.0;
  g.gravity = 1.0;
  g.plate = PlateMotion{amplitude, omega};
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
  sim.count_crossings(heights);
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
  sim.count_crossings({3.0});
  EXPECT_EQ(sim.crossings_at(2.0)[0], 0u);
  sim.advance_to(7.9);
  EXPECT_EQ(sim.crossings_at(7.9)[0], 0u);
  sim.advance_to(9.0);  // bounced at t = 8, at z = 0.5 + 4 - 0.5 = 4 > 3 again
  EXPECT_EQ(sim.crossings_at(9.0)[0], 1u);
  sim.advance_to(17.0);
  EXPECT_EQ(sim.crossings_at(17.0)[0], 2u);
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
