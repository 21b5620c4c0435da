#include "analysis/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "common/granular_model.hpp"

namespace shaker::analysis {
namespace {

/// Height where a field crosses `level` between bins i and j, linearly interpolated.
double crossing(const Profile& p, std::size_t i, std::size_t j, double level) {
  const double a = p.nu[i], b = p.nu[j];
  const double s = (level - a) / (b - a);
  return p.z[i] + s * (p.z[j] - p.z[i]);
}

bool in_layer(const Profile& p, std::size_t i) { return p.nu[i] > layer_volume_fraction; }

/// A standard error not stored, or undefined (NaN: fewer than two samples), counts as 0:
/// then only the relative criteria apply.
double standard_error(const std::vector<double>& se, std::size_t i) {
  return se.empty() || !std::isfinite(se[i]) ? 0.0 : se[i];
}

/// The smallest change of T between bins i and j that is not noise.
double significant_change(const Profile& p, std::size_t i, std::size_t j, double fraction,
                          double peak_temperature, const ShockCriteria& c) {
  const double combined = std::hypot(standard_error(p.T_se, i), standard_error(p.T_se, j));
  return std::max(fraction * peak_temperature, c.standard_errors * combined);
}

/// The lowest bin with material whose upper edge is above the plate: while a shock forms, its
/// compressed region can be thinner than one bin and sit there even if that bin, cut by the
/// plate, falls below the layer threshold (physics.md).
std::optional<std::size_t> lowest_bin_above_plate(const Profile& p) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.n[i] > 0.0 && p.z[i] + 0.5 * p.bin_height > p.plate_z) return i;
  return std::nullopt;
}

/// Where T falls steepest, to a fraction of a bin: the vertex of the parabola through the
/// drops T_j - T_{j+1} at the faces k - 1, k, k + 1, k being the face of the largest drop.
/// The face itself would quantise the location to the bin grid, so a grid study would see it
/// stand still between resolutions (or jump by a bin); the vertex converges as the shock's
/// width is resolved (tanh shocks: within 0.17, 0.08, 0.03 bins for widths 0.5, 1, 2 bins).
/// At the ends of the profile, or where the neighbouring drops do not bracket a maximum,
/// the face is kept.
double steepest_descent_height(const Profile& p, std::size_t k) {
  const double face = 0.5 * (p.z[k] + p.z[k + 1]);
  if (k == 0 || k + 2 >= p.size()) return face;
  const auto drop = [&p](std::size_t j) { return p.T[j] - p.T[j + 1]; };
  const double below = drop(k - 1), at = drop(k), above = drop(k + 1);
  const double curvature = below - 2.0 * at + above;
  if (!(curvature < 0.0)) return face;
  const double offset = std::clamp(0.5 * (below - above) / curvature, -0.5, 0.5);
  return face + offset * (p.z[k + 1] - p.z[k]);
}

}  // namespace

double interpolate(const std::vector<double>& z, const std::vector<double>& f, double at) {
  const auto upper = std::upper_bound(z.begin(), z.end(), at);
  if (upper == z.begin()) return f.front();
  if (upper == z.end()) return f.back();
  const auto j = static_cast<std::size_t>(upper - z.begin());
  const double s = (at - z[j - 1]) / (z[j] - z[j - 1]);
  return f[j - 1] + s * (f[j] - f[j - 1]);
}

Profile with_defined_temperature(const Profile& p) {
  Profile q = p;
  for (auto field : {&Profile::z, &Profile::n, &Profile::nu, &Profile::uz, &Profile::T,
                     &Profile::samples, &Profile::n_se, &Profile::uz_se, &Profile::T_se}) {
    if ((p.*field).empty()) continue;
    (q.*field).clear();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.n[i] > 0.0 && !std::isnan(p.T[i])) (q.*field).push_back((p.*field)[i]);
  }
  return q;
}

std::optional<Layer> find_layer(const Profile& p) {
  std::optional<std::size_t> first, last;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (in_layer(p, i)) {
      if (!first) first = i;
      last = i;
    }
  if (!first) return std::nullopt;
  Layer layer;
  layer.bottom = *first == 0 ? p.z[0] - 0.5 * p.bin_height
                             : crossing(p, *first - 1, *first, layer_volume_fraction);
  layer.top = *last + 1 == p.size() ? p.z[*last] + 0.5 * p.bin_height
                                     : crossing(p, *last, *last + 1, layer_volume_fraction);
  // MD bins are fixed in the lab frame: one cut by the raised plate has its material above the
  // plate, though the interpolation spreads it over the whole bin.
  layer.bottom = std::max(layer.bottom, p.plate_z);
  layer.top = std::max(layer.top, p.plate_z);
  return layer;
}

double center_of_mass(const Profile& p) {
  double mass = 0.0, moment = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    mass += p.n[i];
    moment += p.n[i] * p.z[i];
  }
  return mass > 0.0 ? moment / mass : std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> mach_number(const Profile& p, double e) {
  std::vector<double> ma(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p.nu[i] > 0.0) || std::isnan(p.T[i]) || std::isnan(p.uz[i])) {
      ma[i] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    if (!(p.T[i] > 0.0)) continue;
    // An MD bin can be packed beyond nu_max; c diverges as nu -> nu_max, so Ma -> 0 there.
    if (p.nu[i] >= nu_max) continue;
    ma[i] = std::abs(p.uz[i] - p.plate_v) / model::sound_speed(p.nu[i], p.T[i], e);
  }
  return ma;
}

double max_mach_in_layer(const Profile& p, double e) {
  const auto ma = mach_number(p, e);
  double best = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (in_layer(p, i) && !std::isnan(ma[i])) best = std::max(best, ma[i]);
  return best;
}

std::optional<Shock> find_shock(const Profile& profile, const ShockCriteria& c) {
  const Profile p = with_defined_temperature(profile);
  // Walk up from the plate: the running temperature maximum inside the layer becomes the top
  // of the compressed region once T has fallen significantly below it; the running minimum
  // after it becomes the bottom of the undisturbed region once T has risen again.
  std::optional<std::size_t> peak, trough;
  std::size_t i = 0;
  const std::optional<std::size_t> lowest = lowest_bin_above_plate(p);
  for (; i < p.size(); ++i) {
    const bool candidate = in_layer(p, i) || (lowest && i == *lowest);
    if (candidate && (!peak || p.T[i] > p.T[*peak])) peak = i;
    if (peak && p.T[*peak] - p.T[i] > significant_change(p, *peak, i, c.relative_drop,
                                                         p.T[*peak], c))
      break;
  }
  if (!peak || i == p.size()) return std::nullopt;
  trough = i;
  for (; i < p.size(); ++i) {
    if (p.T[i] < p.T[*trough]) trough = i;
    if (p.T[i] - p.T[*trough] >
        significant_change(p, *trough, i, c.relative_rise, p.T[*peak], c))
      break;
  }
  if (i == p.size()) return std::nullopt;  // no undisturbed region above: no shock in the layer
  // The shock has stopped the material falling into it: across the region the velocity
  // relative to the plate must lose a large part of its incoming value. This rejects the hot,
  // dilute lower edge of a layer that is still falling freely (hot, but not decelerated).
  const double incoming = p.plate_v - p.uz[*trough];
  const double deceleration = p.uz[*peak] - p.uz[*trough];
  const double velocity_noise =
      c.standard_errors * std::hypot(standard_error(p.uz_se, *peak), standard_error(p.uz_se, *trough));
  if (!(incoming > 0.0 && deceleration > std::max(c.deceleration * incoming, velocity_noise)))
    return std::nullopt;

  std::size_t steepest = *peak;
  for (std::size_t k = *peak; k < *trough; ++k)
    if (p.T[k] - p.T[k + 1] > p.T[steepest] - p.T[steepest + 1]) steepest = k;
  // The shock of physics.md is a shock in the layer: the front where the falling layer's
  // material is stopped. So the material where T falls steepest must be layer material
  // (nu above the layer threshold). This rejects the dilute gas that a continuum keeps in the
  // gap under a falling layer: squeezed against the plate, it is hot and T falls from it into
  // the cold layer, but that drop lies in gas (nu 0.015-0.022 in the base case at
  // f t = 0.92-0.96), not in the layer, and no layer material has been stopped yet. A shock
  // compresses what it decelerates, so a real one has layer material on both sides.
  const double nu_at_shock = 0.5 * (p.nu[steepest] + p.nu[steepest + 1]);
  if (!(nu_at_shock > layer_volume_fraction)) return std::nullopt;
  Shock shock;
  shock.location = steepest_descent_height(p, steepest);
  // Once the steepest drop is above the layer's top the shock has left the layer.
  const auto layer = find_layer(profile);
  if (!layer || shock.location > layer->top) return std::nullopt;
  shock.compressed_top = p.z[*peak];
  shock.undisturbed_bottom = p.z[*trough];
  shock.width = shock.undisturbed_bottom - shock.compressed_top;
  // n between the bins the shock was found on: an empty bin between them (skipped) would give
  // a density of 0 at its centre.
  shock.mean_free_path = model::mean_free_path(interpolate(p.z, p.n, shock.location));
  return shock;
}

PhaseSummary summarize(const Profile& p, double e) {
  PhaseSummary s;
  s.phase = p.phase;
  s.plate_z = p.plate_z;
  s.center_of_mass = center_of_mass(p);
  s.max_mach = max_mach_in_layer(p, e);
  s.layer = find_layer(p);
  s.shock = find_shock(p);
  return s;
}

SeriesDifference series_difference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) throw std::invalid_argument("series_difference: lengths differ");
  SeriesDifference d;
  double squared = 0.0, reference = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (std::isnan(a[k]) || std::isnan(b[k])) continue;
    squared += (a[k] - b[k]) * (a[k] - b[k]);
    reference += b[k] * b[k];
    ++d.count;
  }
  if (d.count == 0) return d;
  const double n = static_cast<double>(d.count);
  d.absolute_rms = std::sqrt(squared / n);
  d.fractional_rms = reference > 0.0 ? d.absolute_rms / std::sqrt(reference / n)
                                     : std::numeric_limits<double>::quiet_NaN();
  return d;
}

ProfileNorms profile_difference(const Profile& a, const Profile& b, const std::string& field) {
  const auto member = field == "nu"  ? &Profile::nu
                      : field == "T" ? &Profile::T
                                     : throw std::invalid_argument("unknown field " + field);
  ProfileNorms norms;
  if (a.size() == 0 || b.size() == 0) return norms;
  double sum = 0.0, squares = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.z[i] < b.z.front() || a.z[i] > b.z.back()) continue;
    const double d = std::abs((a.*member)[i] - interpolate(b.z, b.*member, a.z[i]));
    if (std::isnan(d)) continue;  // undefined in either run (an MD bin without particles)
    sum += d;
    squares += d * d;
    norms.linf = std::max(norms.linf, d);
    ++norms.count;
  }
  if (norms.count) {
    norms.l1 = sum / static_cast<double>(norms.count);
    norms.l2 = std::sqrt(squares / static_cast<double>(norms.count));
  }
  return norms;
}

RunComparison compare_runs(const RunRecord& a, const RunRecord& b) {
  if (a.profiles.size() != b.profiles.size())
    throw std::invalid_argument("compare: the runs store different numbers of phases");
  RunComparison r;
  std::vector<double> shock_a, shock_b, com_a, com_b;
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < a.profiles.size(); ++k) {
    const Profile& pa = a.profiles[k];
    const Profile& pb = b.profiles[k];
    if (std::abs(pa.phase - pb.phase) > 1e-9)
      throw std::invalid_argument("compare: the runs store different phases");
    r.phases.push_back(pa.phase);
    const auto sa = find_shock(pa), sb = find_shock(pb);
    shock_a.push_back(sa ? sa->location : nan);
    shock_b.push_back(sb ? sb->location : nan);
    com_a.push_back(center_of_mass(pa));
    com_b.push_back(center_of_mass(pb));
    r.nu_norms.push_back(profile_difference(pa, pb, "nu"));
    r.T_norms.push_back(profile_difference(pa, pb, "T"));
  }
  r.shock_location = series_difference(shock_a, shock_b);
  r.center_of_mass = series_difference(com_a, com_b);
  return r;
}

namespace {
/// |df/dz| / f at bin i from the neighbours with material, NaN without one.
double relative_gradient(const Profile& p, const std::vector<double>& f, std::size_t i) {
  const auto usable = [&](std::size_t k) { return p.n[k] > 0.0 && f[k] > 0.0; };
  if (!usable(i)) return std::numeric_limits<double>::quiet_NaN();
  const bool below = i > 0 && usable(i - 1), above = i + 1 < p.size() && usable(i + 1);
  const std::size_t lo = below ? i - 1 : i, hi = above ? i + 1 : i;
  if (lo == hi) return std::numeric_limits<double>::quiet_NaN();
  return std::abs(f[hi] - f[lo]) / (p.z[hi] - p.z[lo]) / f[i];
}
}  // namespace

KnudsenNumbers knudsen_numbers(const Profile& p) {
  KnudsenNumbers kn;
  kn.density.assign(p.size(), std::numeric_limits<double>::quiet_NaN());
  kn.temperature = kn.density;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p.n[i] > 0.0)) continue;
    const double xi = model::mean_free_path(p.n[i]);
    kn.density[i] = xi * relative_gradient(p, p.n, i);
    kn.temperature[i] = xi * relative_gradient(p, p.T, i);
  }
  return kn;
}

double knudsen_mass_fraction(const Profile& p, const KnudsenNumbers& kn, double limit) {
  double above = 0.0, total = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p.n[i] > 0.0)) continue;
    total += p.n[i];
    if (kn.density[i] > limit || kn.temperature[i] > limit) above += p.n[i];
  }
  return total > 0.0 ? above / total : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace shaker::analysis
