#include "md/initial_states.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "common/errors.hpp"
#include "common/units.hpp"

namespace shaker::md {

double Random::gaussian() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u, v, s;
  do {
    u = uniform(-1.0, 1.0);
    v = uniform(-1.0, 1.0);
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * factor;
  has_spare_ = true;
  return u * factor;
}

namespace {

/// Picks n of the sites in random order (Fisher-Yates with our generator).
std::vector<std::size_t> choose_sites(std::size_t sites, std::size_t n, Random& random) {
  std::vector<std::size_t> order(sites);
  std::iota(order.begin(), order.end(), std::size_t{0});
  for (std::size_t k = sites; k > 1; --k) std::swap(order[k - 1], order[random.below(k)]);
  order.resize(n);
  std::sort(order.begin(), order.end());
  return order;
}

void set_temperature(std::vector<Particle>& particles, double T, Random& random) {
  Vec3 mean;
  for (Particle& p : particles) {
    p.v = {random.gaussian(), random.gaussian(), random.gaussian()};
    mean += p.v;
  }
  const double n = static_cast<double>(particles.size());
  mean = (1.0 / n) * mean;
  double sum = 0.0;
  for (Particle& p : particles) {
    p.v -= mean;
    sum += dot(p.v, p.v);
  }
  if (sum <= 0.0) return;
  const double scale = std::sqrt(3.0 * n * T / sum);
  for (Particle& p : particles) p.v = scale * p.v;
}

}  // namespace

namespace {
/// A seed for the column lifts that differs from the layer's own seed, so that lifting the
/// columns leaves the layer's sites and displacements as they are without it.
constexpr std::uint64_t column_lift_stream = 0x9e3779b97f4a7c15ULL;
}  // namespace

State flat_layer(const Geometry& geometry, std::size_t n, std::uint64_t seed, double column_lift) {
  constexpr double spacing = 1.05;  // leaves room for the random displacements
  if (!(geometry.width >= spacing && geometry.depth >= spacing))
    throw InputError(fmt::format("md.box_width = {} or md.box_depth = {} is narrower than one site of the "
                                 "flat layer; allowed: both >= {} (and >= 3 for the cell list)",
                                 geometry.width, geometry.depth, spacing));
  const auto per_row = static_cast<std::size_t>(std::floor(geometry.width / spacing));
  const auto rows = static_cast<std::size_t>(std::floor(geometry.depth / spacing));
  const double pitch = geometry.width / static_cast<double>(per_row);
  const double pitch_y = geometry.depth / static_cast<double>(rows);
  const std::size_t per_layer = per_row * rows;
  const std::size_t layers = (n + per_layer - 1) / per_layer;
  const double bottom = 0.5 + 0.02;
  const double top = bottom + static_cast<double>(layers - 1) * spacing + 0.02 + column_lift;
  if (geometry.periodic_z || top > geometry.height - 0.5)
    throw InputError(fmt::format(
        "layer.particles = {} does not fit: a flat layer of {} per layer reaches z = {:.4g}, above "
        "md.ceiling - 1/2 = {:.4g}; allowed: at most {} particles for this box and ceiling",
        n, per_layer, top, geometry.height - 0.5,
        per_layer * static_cast<std::size_t>(std::floor((geometry.height - 1.0 - 0.04) / spacing) + 1)));
  // The layer rests on the plate: at the plate's highest point (2A) its top must stay below
  // the ceiling, or the layer is squeezed against it (a collapse that never finishes a cycle).
  const double needed = geometry.plate_top() + top + 0.5;
  if (needed > geometry.height)
    throw InputError(fmt::format(
        "md.ceiling = {} is below the top of the initial flat layer ({} particles, {} layers) when "
        "the plate is at its highest point 2A = {:.4g}; allowed: md.ceiling at least {:.4g}",
        geometry.height, n, layers, geometry.plate_top(), needed));
  Random random(seed);
  const std::vector<std::size_t> sites = choose_sites(per_layer * layers, n, random);
  const double jitter = 0.45 * (std::min(pitch, pitch_y) - 1.0);
  // Every column of sites rises as one by its own lift in [0, column_lift): horizontal
  // neighbours stay more than a diameter apart whatever their heights, so no pair overlaps.
  std::vector<double> lift(per_layer, 0.0);
  if (column_lift > 0.0) {
    Random lifts(seed ^ column_lift_stream);
    for (double& l : lift) l = lifts.uniform(0.0, column_lift);
  }
  State state;
  state.particles.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t s = sites[k];
    Particle& p = state.particles[k];
    const double ix = static_cast<double>(s % per_row), iy = static_cast<double>((s / per_row) % rows);
    const double iz = static_cast<double>(s / per_layer);
    p.r = {(ix + 0.5) * pitch + random.uniform(-jitter, jitter),
           (iy + 0.5) * pitch_y + random.uniform(-jitter, jitter),
           bottom + iz * spacing + random.uniform(-0.02, 0.02) + lift[s % per_layer]};
  }
  return state;
}

State homogeneous_gas(const Geometry& geometry, std::size_t n, double nu, double T,
                      std::uint64_t seed) {
  Random random(seed);
  State state;
  state.particles.resize(n);
  std::vector<Vec3> sites;
  if (geometry.periodic_z) {
    const double volume = geometry.width * geometry.width * geometry.height;
    const double actual = volume_fraction(static_cast<double>(n) / volume);
    if (std::fabs(actual - nu) > 1e-9 * nu)
      throw InputError(fmt::format("gas: {} particles in this box give nu = {}, not {}", n, actual, nu));
    auto side = static_cast<std::size_t>(std::ceil(std::cbrt(static_cast<double>(n))));
    while (side * side * side < n) ++side;
    const double ax = geometry.width / static_cast<double>(side);
    const double az = geometry.height / static_cast<double>(side);
    if (ax < 1.0 || az < 1.0)
      throw InputError(fmt::format("gas: volume fraction {} is too dense for a lattice start", nu));
    for (std::size_t k = 0; k < side * side * side; ++k)
      sites.push_back({(static_cast<double>(k % side) + 0.5) * ax,
                       (static_cast<double>((k / side) % side) + 0.5) * ax,
                       (static_cast<double>(k / (side * side)) + 0.5) * az});
  } else {
    const double a = std::cbrt(pi / (6.0 * nu));
    if (a < 1.0)
      throw InputError(fmt::format(
          "md.gas_volume_fraction = {} is too dense for the lattice start; allowed: at most {:.4f}",
          nu, pi / 6.0));
    const auto per_row = std::max<std::size_t>(1, static_cast<std::size_t>(std::floor(geometry.width / a)));
    const auto rows = std::max<std::size_t>(1, static_cast<std::size_t>(std::floor(geometry.depth / a)));
    const double pitch = geometry.width / static_cast<double>(per_row);
    const double pitch_y = geometry.depth / static_cast<double>(rows);
    const std::size_t layers = (n + per_row * rows - 1) / (per_row * rows);
    const double bottom = geometry.plate_top() + 0.5 + 0.01;
    const double top = bottom + static_cast<double>(layers - 1) * a;
    if (top > geometry.height - 0.5)
      throw InputError(fmt::format(
          "layer.particles = {} does not fit: a gas at nu = {} above the plate's top reaches "
          "z = {:.4g}, above md.ceiling - 1/2 = {:.4g}", n, nu, top, geometry.height - 0.5));
    for (std::size_t k = 0; k < per_row * rows * layers; ++k)
      sites.push_back({(static_cast<double>(k % per_row) + 0.5) * pitch,
                       (static_cast<double>((k / per_row) % rows) + 0.5) * pitch_y,
                       bottom + static_cast<double>(k / (per_row * rows)) * a});
  }
  const std::vector<std::size_t> chosen = choose_sites(sites.size(), n, random);
  for (std::size_t k = 0; k < n; ++k) state.particles[k].r = sites[chosen[k]];
  set_temperature(state.particles, T, random);
  return state;
}

Geometry periodic_box(std::size_t n, double nu) {
  Geometry g;
  g.periodic_z = true;
  g.gravity = 0.0;
  g.width = g.depth = g.height = std::cbrt(static_cast<double>(n) * pi / (6.0 * nu));
  return g;
}

}  // namespace shaker::md
