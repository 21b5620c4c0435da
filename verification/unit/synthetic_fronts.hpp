#pragma once
// Exact bin averages of tanh fronts, and synthetic MD runs of a base-case-like layer with a
// shock of known life built from them, shared by the synthetic-truth tests (test_front_fit.cpp,
// test_estimator_truth.cpp, test_sampling_invariance.cpp). Written independently of the
// library's front model, so that a test does not check the library against itself.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "analysis/analysis.hpp"
#include "analysis/run_analysis.hpp"
#include "common/cycle_samples.hpp"
#include "common/profile.hpp"
#include "common/shaker_kinematics.hpp"
#include "common/units.hpp"

namespace shaker::testing {

/// ln cosh u; cosh overflows for |u| > 710, so it is written through |u|.
inline double log_cosh(double u) {
  const double a = std::abs(u);
  return a + std::log1p(std::exp(-2.0 * a)) - std::log(2.0);
}

/// The mean of a + b tanh((z - z0) / w) over the bin [zc - h/2, zc + h/2].
inline double bin_mean(double zc, double h, double a, double b, double z0, double w) {
  return a + b * (w / h) * (log_cosh((zc + 0.5 * h - z0) / w) - log_cosh((zc - 0.5 * h - z0) / w));
}

/// The mean over [lo, hi] of a step of height `jump` centred at z0 with half-width w,
/// jump (1 + tanh((z - z0) / w)) / 2: 0 far below z0, `jump` far above.
inline double step_mean(double lo, double hi, double jump, double z0, double w) {
  return bin_mean(0.5 * (lo + hi), hi - lo, 0.5 * jump, 0.5 * jump, z0, w);
}

namespace synthetic {

using shaker::BinSums;
using shaker::CycleSamples;
using shaker::Profile;
using shaker::RunRecord;
namespace an = shaker::analysis;

// ---- The base case's grid (validation/cases/base.toml, `shaker config` defaults) -----------

constexpr double kGamma = 3.0, kFrequency = 0.095, kRestitution = 0.9;
constexpr std::size_t kSamples = 10;   // run.sampled_cycles: one sample per cycle
constexpr std::size_t kBins = 80;      // 1-sigma bins up to z = 80 (MD bins go to the ceiling)
constexpr double kBinHeight = 1.0;     // md.bin_height
constexpr double kBoxWidth = 20.0;     // md.box_width: 3937 particles, H = 9
constexpr double kBinVolume = kBoxWidth * kBoxWidth * kBinHeight;
inline const shaker::ShakerKinematics kPlate{kGamma, kFrequency};

inline double real(std::size_t i) { return static_cast<double>(i); }
inline double bin_bottom(std::size_t j) { return real(j) * kBinHeight; }

// ---- Noise: the per-bin standard errors the MD shows --------------------------------------
//
// Per cycle, a bin expecting N particles gets relative noise c_n / sqrt(N) in its count,
// c_T / sqrt(N) in its temperature and c_u sqrt(T / N) in its mean u_z (c = 1, 0.82, 1 for
// independent Poisson counts of a Maxwellian gas). The c were measured on
// `shaker md validation/cases/base.toml --set run.transient_cycles=5 --set run.sampled_cycles=10`
// (seed 1, 50 phases x 200 bins, 400 sigma^3 per bin) as c = (se / value) sqrt(10 N), medians
// over bins (quartiles in brackets):
//   layer, nu > 0.2 (495 bins, N ~ 243, n_se/n 0.012, T_se/T 0.033, uz_se 0.013):
//     c_n 0.56 [0.43, 0.73], c_T 1.67 [1.36, 1.99], c_u 1.68 [1.14, 2.47]
//   gas, 0.001 < nu < 0.02 (2654 bins, N ~ 3.2, n_se/n 0.17, T_se/T 0.12, uz_se 0.56):
//     c_n 0.93 [0.78, 1.09], c_T 0.79 [0.61, 0.98], c_u 1.00 [0.78, 1.28]
// The generator uses the layer's c where nu >= 0.1 and the gas's below. What it leaves out:
// in the MD the shock itself moves from cycle to cycle, so the bins on the front have c_T of
// 2.5-8.6 (phases 0.16-0.28), and that noise is correlated between neighbouring bins.
struct NoiseLevels {
  double n = 0, uz = 0, T = 0;
};
constexpr NoiseLevels kMdLayerNoise{0.56, 1.68, 1.67}, kMdGasNoise{0.93, 1.00, 0.79};
constexpr double kDenseBelow = 0.1;  ///< nu from which a bin has the layer's noise

// ---- The truth -------------------------------------------------------------------------

/// A layer like the base case's. During the shock's life (formation <= phase < exit) the
/// layer sits on the plate: compressed, hot material at rest relative to the plate below the
/// shock (nu 0.5), cold material falling at fall_speed relative to the plate above it (nu 0.3),
/// then a dilute, warmer gas above the layer's top; the shock (a tanh front in nu, T and u_z of
/// half-width front_half_width) moves up at `speed` in the plate frame from the plate at
/// formation until it reaches the layer's top at exit. At the other phases the layer is in
/// flight: a uniform cold layer, gap above the plate, with no front in T.
struct Truth {
  double formation_phase = 0.107;
  double speed = 6.0;              ///< plate frame at formation, sqrt(g sigma)
  double deceleration = 0.0;       ///< of the shock in the plate frame, g (0: a straight path)
  double top_height = 14.0;        ///< layer top (nu = layer threshold) above the plate
  double front_half_width = 1.0;   ///< w of the shock's tanh fronts
  double edge_half_width = 0.5;    ///< w of the layer's top and bottom edges
  double nu_compressed = 0.5, nu_falling = 0.3, nu_gas = 0.005, nu_flight = 0.4;
  // The MD base case at phase 0.22: T 15.6 at the compressed top, 1.1-1.5 above the shock,
  // 2-4 in the gas above the layer; the material above the shock falls at 8.5-10 relative to
  // the plate (the MD's undisturbed layer is more dilute than here, nu 0.06-0.09).
  double T_hot = 15.0, T_cold = 1.3, T_gas = 3.0;
  double fall_speed = 8.0;         ///< of the undisturbed material, relative to the plate
  double flight_gap = 1.5, flight_depth = 12.0;

  /// In cycles: the time at which the shock's height reaches top_height (which a decelerating
  /// shock must reach before it stops: speed^2 > 2 deceleration top_height).
  double lifetime() const {
    if (deceleration == 0.0) return top_height / speed * kFrequency;
    const double time = (speed - std::sqrt(speed * speed - 2.0 * deceleration * top_height)) / deceleration;
    return time * kFrequency;
  }
  double exit_phase() const { return formation_phase + lifetime(); }
  bool has_shock(double phase) const { return phase >= formation_phase && phase < exit_phase(); }
  /// Shock height above the plate.
  double shock_height(double phase) const {
    const double time = (phase - formation_phase) / kFrequency;
    return speed * time - 0.5 * deceleration * time * time;
  }
  double shock_location(double phase) const { return kPlate.position(phase / kFrequency) + shock_height(phase); }
  /// Centre of the nu step at the layer's top, placed so that nu crosses the layer threshold
  /// (find_layer) exactly at top_height.
  double top_edge() const {
    const double q = (nu_falling - an::layer_volume_fraction) / (nu_falling - nu_gas);
    return top_height - edge_half_width * std::atanh(2.0 * q - 1.0);
  }
};

struct BinTruth {
  double n = 0, uz = 0, T = 0;
};

/// Exact bin averages of the truth at one phase (lab-frame bin [lo, hi]); material only above
/// the plate, so the bin the plate cuts holds the fraction of it above the plate.
inline BinTruth bin_truth(const Truth& tr, double phase, double lo, double hi) {
  const double t = phase / kFrequency;
  const double plate = kPlate.position(t), plate_v = kPlate.velocity(t);
  const double a = std::max(lo - plate, 0.0), b = hi - plate;
  if (b <= a) return {};
  const double w = tr.front_half_width, we = tr.edge_half_width;
  double nu = 0, T = 0, uz = 0;
  if (tr.has_shock(phase)) {
    const double s = tr.shock_height(phase), top = tr.top_edge();
    nu = tr.nu_compressed + step_mean(a, b, tr.nu_falling - tr.nu_compressed, s, w) +
         step_mean(a, b, tr.nu_gas - tr.nu_falling, top, we);
    T = tr.T_hot + step_mean(a, b, tr.T_cold - tr.T_hot, s, w) +
        step_mean(a, b, tr.T_gas - tr.T_cold, top, we);
    uz = plate_v + step_mean(a, b, -tr.fall_speed, s, w);
  } else {
    const double bottom = tr.flight_gap, top = tr.flight_gap + tr.flight_depth;
    nu = step_mean(a, b, tr.nu_flight, bottom, we) + step_mean(a, b, tr.nu_gas - tr.nu_flight, top, we);
    T = tr.T_cold + step_mean(a, b, tr.T_gas - tr.T_cold, top, we);
    uz = plate_v - tr.fall_speed;
  }
  return {shaker::number_density(nu) * (b - a) / (hi - lo), uz, T};
}

/// A synthetic MD run stored at `phases` phases per cycle: kSamples cycles of per-bin sums at
/// every phase, each the truth plus Gaussian noise of the MD's size (above) times `scale`. The
/// noise of a phase does not depend on `phases`: the MD takes one snapshot per stored phase
/// and sampled cycle, however many phases it stores.
inline RunRecord synthetic_run(const Truth& tr, double scale, std::uint64_t seed,
                               std::size_t phases) {
  const auto phase_of = [phases](std::size_t k) { return real(k) / real(phases); };
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  RunRecord run;
  run.solver = "synthetic";
  run.e = kRestitution;
  run.samples = CycleSamples(phases, kBins, kBinVolume);
  std::vector<std::vector<BinTruth>> truth(phases);
  for (std::size_t k = 0; k < phases; ++k)
    for (std::size_t j = 0; j < kBins; ++j)
      truth[k].push_back(bin_truth(tr, phase_of(k), bin_bottom(j), bin_bottom(j + 1)));
  std::vector<BinSums> snapshot(kBins);
  for (std::size_t s = 0; s < kSamples; ++s)
    for (std::size_t k = 0; k < phases; ++k) {
      for (std::size_t j = 0; j < kBins; ++j) {
        const BinTruth& b = truth[k][j];
        const double expected = b.n * kBinVolume;
        BinSums& sums = snapshot[j];
        sums = {};
        if (!(expected > 0.0)) continue;
        const double root = std::sqrt(expected);
        const NoiseLevels& noise =
            shaker::volume_fraction(b.n) >= kDenseBelow ? kMdLayerNoise : kMdGasNoise;
        const double count = std::max(0.0, expected * (1.0 + scale * noise.n / root * gauss(rng)));
        const double uz = b.uz + scale * noise.uz * std::sqrt(b.T) / root * gauss(rng);
        const double T = std::max(0.0, b.T * (1.0 + scale * noise.T / root * gauss(rng)));
        sums.count = count;
        sums.vz = count * uz;
        sums.v2 = count * (3.0 * T + uz * uz);
      }
      run.samples.add_cycle(k, snapshot);
    }
  for (std::size_t k = 0; k < phases; ++k) {
    Profile p;
    p.phase = phase_of(k);
    p.time = p.phase / kFrequency;
    p.plate_z = kPlate.position(p.time);
    p.plate_v = kPlate.velocity(p.time);
    p.bin_height = kBinHeight;
    for (std::size_t j = 0; j < kBins; ++j) p.z.push_back(bin_bottom(j) + 0.5 * kBinHeight);
    run.samples.pool(k, p);
    run.profiles.push_back(std::move(p));
  }
  return run;
}

/// The options `shaker analyze` applies to a periodic run of the synthetic shaker.
inline an::AnalysisOptions options() {
  an::AnalysisOptions o;
  o.periodic = true;
  o.frequency = kFrequency;
  return o;
}

}  // namespace synthetic
}  // namespace shaker::testing
