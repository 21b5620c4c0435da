// Kinetic-theory checks of the elastic and the homogeneously cooling hard-sphere gas.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "common/granular_model.hpp"
#include "md/initial_states.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

CollisionRules elastic() {
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, 1.0};
  return rules;
}

void run_collisions(Simulation& sim, std::uint64_t pair_collisions) {
  const std::uint64_t target = sim.tally().pair + pair_collisions;
  while (sim.tally().pair < target) sim.step();
}

TEST(MdElasticGas, EnergyAndMomentumConservedOverMillionCollisions) {
  const std::size_t n = 2000;
  const Geometry g = periodic_box(n, 0.3);
  Simulation sim(g, elastic(), homogeneous_gas(g, n, 0.3, 1.0, 11));
  const double e0 = sim.kinetic_energy(sim.time());
  run_collisions(sim, 1000000);
  const double drift = std::fabs(sim.kinetic_energy(sim.time()) - e0) / e0;
  const Vec3 p = testing::total_momentum(sim);
  std::printf("measured: relative energy drift %.3g, |P| = %.3g after %llu collisions\n", drift,
              std::sqrt(dot(p, p)), static_cast<unsigned long long>(sim.tally().pair));
  EXPECT_LT(drift, 1e-10);
  EXPECT_LT(std::sqrt(dot(p, p)), 1e-10);
  EXPECT_TRUE(sim.queue_consistent());
  EXPECT_EQ(sim.count_overlaps(sim.time(), 1e-9), 0u);
}

/// Maxwell speed distribution function at temperature T (mass 1).
double maxwell_cdf(double s, double T) {
  const double x = s / std::sqrt(2.0 * T);
  return std::erf(x) - 2.0 / std::sqrt(pi) * x * std::exp(-x * x);
}

TEST(MdElasticGas, SpeedsRelaxToMaxwellian) {
  // Start far from equilibrium: every particle with the same speed in a random direction.
  const std::size_t n = 2000;
  const Geometry g = periodic_box(n, 0.2);
  State start = homogeneous_gas(g, n, 0.2, 1.0, 5);
  for (Particle& p : start.particles) p.v = (std::sqrt(3.0) / std::sqrt(dot(p.v, p.v))) * p.v;
  Simulation sim(g, elastic(), start);
  run_collisions(sim, 20 * n);  // 40 collisions per particle
  const int bins = 20;
  std::vector<double> observed(bins, 0.0);
  std::vector<Vec3> r, v;
  const double T = 2.0 * sim.kinetic_energy(sim.time()) / (3.0 * static_cast<double>(n));
  // Equiprobable bins of the Maxwell distribution, by bisection of its CDF.
  std::vector<double> edges(bins + 1, 0.0);
  edges[bins] = 1e300;
  for (int b = 1; b < bins; ++b) {
    double lo = 0.0, hi = 20.0;
    for (int k = 0; k < 100; ++k) {
      const double mid = 0.5 * (lo + hi);
      (maxwell_cdf(mid, T) < static_cast<double>(b) / bins ? lo : hi) = mid;
    }
    edges[b] = lo;
  }
  const int snapshots = 10;
  for (int s = 0; s < snapshots; ++s) {
    run_collisions(sim, 5 * n);  // ten collisions per particle between snapshots
    sim.positions_at(sim.time(), r, v);
    for (const Vec3& u : v) {
      const double speed = std::sqrt(dot(u, u));
      const auto b = std::upper_bound(edges.begin(), edges.end(), speed) - edges.begin() - 1;
      observed[static_cast<std::size_t>(b)] += 1.0;
    }
  }
  const double expected = static_cast<double>(n) * snapshots / bins;
  double chi2 = 0.0;
  for (double o : observed) chi2 += (o - expected) * (o - expected) / expected;
  std::printf("measured: chi^2 = %.2f with %d degrees of freedom\n", chi2, bins - 1);
  EXPECT_LT(chi2, 43.82);  // chi^2 critical value, 19 degrees of freedom, p = 0.001
}

struct BulkMeasurement {
  double compressibility;    ///< p / (n T) from the collisional virial
  double frequency_ratio;    ///< collision frequency per particle / Enskog
};

BulkMeasurement measure_bulk(double nu, std::size_t n, std::uint64_t per_particle) {
  const Geometry g = periodic_box(n, nu);
  Simulation sim(g, elastic(), homogeneous_gas(g, n, nu, 1.0, 3));
  run_collisions(sim, 20 * n);  // forget the lattice
  const Tally start = sim.tally();
  const double t0 = sim.time();
  run_collisions(sim, per_particle * n / 2);
  const double duration = sim.time() - t0;
  const double N = static_cast<double>(n);
  const double T = 2.0 * sim.kinetic_energy(sim.time()) / (3.0 * N);
  const double density = N / (g.width * g.width * g.height);
  const double collisions = static_cast<double>(sim.tally().pair - start.pair);
  BulkMeasurement m;
  m.compressibility = 1.0 + (sim.tally().virial - start.virial) / (3.0 * N * T * duration);
  m.frequency_ratio = 2.0 * collisions / (N * duration) / model::enskog_collision_frequency(density, T);
  return m;
}

class MdCarnahanStarling : public ::testing::TestWithParam<double> {};

TEST_P(MdCarnahanStarling, VirialPressureAndEnskogFrequency) {
  const double nu = GetParam();
  const BulkMeasurement m = measure_bulk(nu, 4000, 200);
  const double cs = model::compressibility_carnahan_starling(nu);
  std::printf("measured: nu = %.2f  p/(nT) = %.5f  CS = %.5f  (%.3f%%)  frequency/Enskog = %.5f\n",
              nu, m.compressibility, cs, 100.0 * (m.compressibility / cs - 1.0), m.frequency_ratio);
  EXPECT_NEAR(m.compressibility / cs, 1.0, 0.01);
  if (nu <= 0.3) {
    EXPECT_NEAR(m.frequency_ratio, 1.0, 0.02);
  }
}

INSTANTIATE_TEST_SUITE_P(VolumeFractions, MdCarnahanStarling,
                         ::testing::Values(0.1, 0.2, 0.3, 0.4, 0.45));

TEST(MdCoolingGas, HaffLaw) {
  const std::size_t n = 8000;  // T fluctuates by about 1/sqrt(n)
  const double nu = 0.1, e = 0.95;
  const Geometry g = periodic_box(n, nu);
  Simulation sim(g, elastic(), homogeneous_gas(g, n, nu, 1.0, 17));
  run_collisions(sim, 20 * n);  // equilibrate elastically, then switch dissipation on
  sim.set_restitution(Restitution{Restitution::Kind::constant, e});
  const double N = static_cast<double>(n);
  const double t0 = sim.time(), T0 = 2.0 * sim.kinetic_energy(t0) / (3.0 * N);
  const double G = nu * model::g0_carnahan_starling(nu);
  const double haff_time = 1.0 / (4.0 / std::sqrt(pi) * (1.0 - e * e) * G * std::sqrt(T0));
  double worst = 0.0, last_ratio = 1.0;
  for (int k = 1; k <= 20; ++k) {
    const double t = t0 + 0.1 * k * haff_time;  // to T0 / 9
    sim.advance_to(t);
    const double T = 2.0 * sim.kinetic_energy(t) / (3.0 * N);
    const double expected = model::haff_temperature(t - t0, T0, G, e);
    worst = std::max(worst, std::fabs(T / expected - 1.0));
    last_ratio = T / T0;
  }
  std::printf("measured: largest |T/T_Haff - 1| = %.4f, final T/T0 = %.4f\n", worst, last_ratio);
  EXPECT_LT(worst, 0.03);
  EXPECT_LT(last_ratio, 0.15);  // the test did cool the gas substantially
}

}  // namespace
}  // namespace shaker::md
