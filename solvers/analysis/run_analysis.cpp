#include "analysis/run_analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>

#include "common/errors.hpp"
#include "common/granular_model.hpp"

namespace shaker::analysis {
namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

/// Height below which `fraction` of the material lies, the material spread evenly over each
/// bin; never below the plate, which a lab-frame MD bin cut by the plate reaches below.
double mass_quantile_height(const Profile& p, double fraction) {
  const double total = std::accumulate(p.n.begin(), p.n.end(), 0.0);
  if (!(total > 0.0)) return nan;
  double below = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (below + p.n[i] >= fraction * total)
      return std::max(p.plate_z, p.z[i] - 0.5 * p.bin_height +
                                     p.bin_height * (fraction * total - below) / p.n[i]);
    below += p.n[i];
  }
  return p.z.back() + 0.5 * p.bin_height;
}

double layer_temperature(const Profile& p, const std::optional<Layer>& layer) {
  if (!layer) return nan;
  double n = 0.0, nT = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.z[i] >= layer->bottom && p.z[i] <= layer->top && !std::isnan(p.T[i])) {
      n += p.n[i];
      nT += p.n[i] * p.T[i];
    }
  return n > 0.0 ? nT / n : nan;
}

/// T across the shock fitted by a tanh front, within the layer, if the fit resolves it; `p`
/// holds the bins with a defined T (with_defined_temperature).
std::optional<FrontFit> fitted_front(const Profile& p, const Shock& shock, const Layer& layer) {
  const double half = std::max(1.5 * shock.width, front_window_minimum);
  const double lo = std::max(shock.location - half, layer.bottom);
  const double hi = std::min(shock.location + half, layer.top);
  auto fit = fit_front(p.z, p.T, p.T_se, lo, hi);
  if (!fit || !(fit->width_error < fit->width) || !(fit->high < fit->low)) return std::nullopt;
  return fit;
}

/// The phases of the shock's life: the longest stretch of stored phases with a shock (the
/// first on a tie), in which phases without a shock between two with one, lasting together at
/// most max_gap (each stands for one phase spacing), are missed detections and do not end the
/// life (the shock rule's thresholds are in standard errors, so at MD noise a real shock is
/// missed at isolated phases). In a periodic run the last stored phase is followed by the
/// first. Returns the phases with a shock, in time order.
std::vector<std::size_t> longest_life(const std::vector<PhaseQuantities>& q, const AnalysisOptions& o) {
  const std::size_t m = q.size();
  std::vector<std::size_t> seen;
  for (std::size_t k = 0; k < m; ++k)
    if (q[k].shock) seen.push_back(k);
  const std::size_t d = seen.size();
  if (d == 0 || d == m) return seen;
  const double spacing = 1.0 / static_cast<double>(m);
  // Stored phases without a shock before detection i (none before a run's first phase).
  const auto missed_before = [&](std::size_t i) -> std::optional<std::size_t> {
    if (i > 0) return seen[i] - seen[i - 1] - 1;
    if (!o.periodic) return std::nullopt;
    return seen[0] + m - seen[d - 1] - 1;
  };
  const auto starts_a_life = [&](std::size_t i) {
    const auto missed = missed_before(i);
    return !missed || static_cast<double>(*missed) * spacing > o.max_gap * (1.0 + 1e-9);
  };
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < d; ++i)
    if (starts_a_life(i)) starts.push_back(i);
  // Periodic with every gap bridged: one life round the cycle, starting after any gap.
  const bool round_the_cycle = starts.empty();
  if (round_the_cycle)
    for (std::size_t i = 0; i < d; ++i)
      if (*missed_before(i) > 0) starts.push_back(i);
  std::size_t best_start = 0, best_count = 0, best_span = 0;
  for (std::size_t i : starts) {
    std::size_t count = 1;
    while (count < d && (o.periodic || i + count < d) &&
           (round_the_cycle || !starts_a_life((i + count) % d)))
      ++count;
    const std::size_t span = (seen[(i + count - 1) % d] + m - seen[i]) % m;
    if (best_count == 0 || span > best_span) best_start = i, best_count = count, best_span = span;
  }
  std::vector<std::size_t> life;
  for (std::size_t j = 0; j < best_count; ++j) life.push_back(seen[(best_start + j) % d]);
  return life;
}

/// Least-squares line y = a + b x: the slope and its standard error from the residuals.
std::pair<double, double> fitted_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  const double xm = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double ym = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    sxy += (x[k] - xm) * (y[k] - ym);
    sxx += (x[k] - xm) * (x[k] - xm);
  }
  const double slope = sxy / sxx;
  if (x.size() < 3) return {slope, nan};
  double residuals = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double r = y[k] - ym - slope * (x[k] - xm);
    residuals += r * r;
  }
  return {slope, std::sqrt(residuals / (n - 2.0) / sxx)};
}

double temperature_slope_above(const Profile& p, const std::optional<Layer>& layer) {
  if (!layer) return nan;
  std::vector<double> z, T;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.z[i] > layer->top && p.z[i] <= layer->top + gas_span_above_layer && p.n[i] > 0.0 &&
        !std::isnan(p.T[i])) {
      z.push_back(p.z[i]);
      T.push_back(p.T[i]);
    }
  return z.size() >= 3 ? fitted_slope(z, T).first : nan;
}

double median(std::vector<double> v) {
  const auto middle = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  if (v.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(v.begin(), middle));
}

/// The least-squares slope of y(x) and its standard error after dropping outliers: points
/// farther from the Theil-Sen line (median of the pairwise slopes, which a few outliers do
/// not move) than 4 robust standard deviations (1.4826 x the median absolute residual) and
/// `floor`. A shock rule that mistakes noise near the plate for the front at one phase of
/// the life gives such a point, and one is enough to bias a slope through ten phases by a
/// tenth.
std::pair<double, double> robust_slope(const std::vector<double>& x, const std::vector<double>& y,
                                       double floor) {
  if (x.size() < 4) return fitted_slope(x, y);
  std::vector<double> slopes, offsets, magnitude;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j) slopes.push_back((y[j] - y[i]) / (x[j] - x[i]));
  const double slope = median(slopes);
  for (std::size_t k = 0; k < x.size(); ++k) offsets.push_back(y[k] - slope * x[k]);
  const double offset = median(offsets);
  for (std::size_t k = 0; k < x.size(); ++k) magnitude.push_back(std::abs(offsets[k] - offset));
  const double limit = std::max(4.0 * 1.4826 * median(magnitude), floor);
  std::vector<double> xi, yi;
  for (std::size_t k = 0; k < x.size(); ++k)
    if (magnitude[k] <= limit) xi.push_back(x[k]), yi.push_back(y[k]);
  return fitted_slope(xi.size() >= 3 ? xi : x, xi.size() >= 3 ? yi : y);
}

/// 2 c of the least-squares parabola a + b x + c x^2 (through the points, if three).
double fitted_curvature(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() < 3) return nan;
  const double x0 = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
  double s[5] = {0, 0, 0, 0, 0}, r[3] = {0, 0, 0};
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double u = x[k] - x0;
    double power = 1.0;
    for (int j = 0; j < 5; ++j, power *= u) {
      s[j] += power;
      if (j < 3) r[j] += power * y[k];
    }
  }
  // Normal equations [s0 s1 s2; s1 s2 s3; s2 s3 s4] (a b c) = r, solved for c by Cramer.
  const auto det3 = [](double a, double b, double c, double d, double e, double f, double g,
                       double h, double i) { return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g); };
  const double d = det3(s[0], s[1], s[2], s[1], s[2], s[3], s[2], s[3], s[4]);
  const double dc = det3(s[0], s[1], r[0], s[1], s[2], r[1], s[2], s[3], r[2]);
  return 2.0 * dc / d;
}

/// The height above the plate from which a front is resolved (AnalysisOptions::plate_clearance).
double clear_of_plate(const AnalysisOptions& o, double bin_height) {
  return std::max(o.plate_clearance, 2.0 * bin_height);
}

double mean(const std::vector<double>& v) {
  return v.empty() ? nan : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

std::optional<ShockLife> shock_life(const std::vector<PhaseQuantities>& q,
                                    const AnalysisOptions& o, double bin_height) {
  const auto life = longest_life(q, o);
  if (life.empty()) return std::nullopt;
  ShockLife s;
  s.phases = life;
  // Phases on one axis: a life that wraps the cycle starts in the cycle before.
  std::vector<double> phase, t, height, location;
  const bool wraps = std::adjacent_find(life.begin(), life.end(), std::greater<>()) != life.end();
  double offset = wraps ? -1.0 : 0.0;
  for (std::size_t j = 0; j < life.size(); ++j) {
    const std::size_t k = life[j];
    if (j > 0 && k < life[j - 1]) offset += 1.0;
    const double p = q[k].phase + offset;
    phase.push_back(p);
    t.push_back(p / o.frequency);
    height.push_back(q[k].shock->location - q[k].plate_z);
    location.push_back(q[k].shock->location);
  }
  // The shock formed between the stored phase before its life (which has none) and the first
  // with one: the midpoint, unbiased for a formation anywhere in that interval. A life that
  // starts at the first stored phase of a non-periodic run formed before it: that phase.
  const std::size_t m = q.size();
  const double spacing = m > 1 ? 1.0 / static_cast<double>(m) : 1.0;
  const bool seen_before = o.periodic || life.front() > 0;
  s.formation_phase = phase.front() - (seen_before ? 0.5 * spacing : 0.0);
  // Exit: where the gap (layer top - shock) reaches zero, on a line through the gaps of the
  // life's last exit_window cycles (a time, so that finer sampling does not fit a line through
  // two close, noisy points), at most exit_reach after the last phase with a shock (one
  // spacing if coarser): near the layer's top the shock rule no longer sees the front, so the
  // next stored phase without a shock does not bound the exit.
  const std::size_t last = life.back();
  const double reach = std::max(spacing, o.exit_reach);
  double exit = phase.back() + reach;
  std::vector<double> late_phase, late_gap;
  for (std::size_t j = 0; j < life.size(); ++j)
    if (phase[j] >= phase.back() - o.exit_window || j + 2 >= life.size()) {
      late_phase.push_back(phase[j]);
      late_gap.push_back(q[life[j]].layer->top - q[life[j]].shock->location);
    }
  if (late_phase.size() >= 2) {
    const double closing = -fitted_slope(late_phase, late_gap).first;
    if (closing > 0.0) exit = mean(late_phase) + mean(late_gap) / closing;
  }
  s.exit_phase = std::clamp(exit, phase.back(), phase.back() + reach);
  if (!o.periodic && last + 1 == m) s.exit_phase = nan;  // the run ended with the shock inside
  s.lifetime = s.exit_phase - s.formation_phase;
  // A front near the plate sits in the lowest bins, whatever its true height: those phases
  // locate the bin, not the front, and are left out of the speed's fit and of d and d/xi.
  std::vector<double> t_resolved, height_resolved, width, width_over_mfp;
  for (std::size_t j = 0; j < t.size(); ++j)
    if (height[j] >= clear_of_plate(o, bin_height)) {
      t_resolved.push_back(t[j]), height_resolved.push_back(height[j]);
      width.push_back(q[life[j]].shock->width);
      width_over_mfp.push_back(q[life[j]].shock->width_over_mfp());
    }
  s.width_mean = mean(width);
  s.width_over_mfp_mean = mean(width_over_mfp);
  const bool resolved = t_resolved.size() >= 3;
  const auto& t_fitted = resolved ? t_resolved : t;
  const auto& height_fitted = resolved ? height_resolved : height;
  if (t_fitted.size() >= 2) std::tie(s.speed, s.speed_fit_error) = robust_slope(t_fitted, height_fitted, 2.0 * bin_height);
  else s.speed = s.speed_fit_error = nan;
  s.speed_resolution = std::abs(fitted_curvature(t_fitted, height_fitted)) * spacing / o.frequency / std::sqrt(2.0);
  s.curvature = t.size() >= 4 ? fitted_curvature(t, location) : nan;
  return s;
}

}  // namespace

RunQuantities analyze_profiles(const std::vector<Profile>& profiles, double e,
                               const AnalysisOptions& options) {
  RunQuantities r;
  for (const Profile& p : profiles) {
    PhaseQuantities q;
    q.phase = p.phase;
    q.time = p.time;
    q.plate_z = p.plate_z;
    q.center_of_mass = center_of_mass(p);
    q.max_mach = max_mach_in_layer(p, e);
    q.layer = find_layer(p);
    q.mass_bottom = mass_quantile_height(p, 0.01);
    q.layer_temperature = layer_temperature(p, q.layer);
    q.knudsen_mass_fraction = knudsen_mass_fraction(p, knudsen_numbers(p));
    q.temperature_slope_above = temperature_slope_above(p, q.layer);
    q.shock = find_shock(p, options.criteria);
    if (q.shock) {
      const Profile defined = with_defined_temperature(p);
      q.front = fitted_front(defined, *q.shock, *q.layer);
      if (q.front)
        q.front_mean_free_path = model::mean_free_path(interpolate(defined.z, defined.n, q.front->location));
    }
    r.phases.push_back(std::move(q));
  }
  if (r.phases.empty()) return r;
  double com = 0.0;
  r.center_of_mass_apex = -std::numeric_limits<double>::infinity();
  r.layer_temperature_peak = nan;
  for (const auto& q : r.phases) {
    com += q.center_of_mass;
    r.center_of_mass_apex = std::max(r.center_of_mass_apex, q.center_of_mass);
    r.max_mach_peak = std::max(r.max_mach_peak, q.max_mach);
    if (std::isfinite(q.layer_temperature) && !(q.layer_temperature <= r.layer_temperature_peak))
      r.layer_temperature_peak = q.layer_temperature;
  }
  r.center_of_mass_mean = com / static_cast<double>(r.phases.size());
  r.bin_height = profiles.front().bin_height;
  r.shock = shock_life(r.phases, options, r.bin_height);
  r.width_over_mfp_peak_phase = nan;
  if (r.shock) {
    double best = -1.0;
    for (std::size_t k : r.shock->phases)
      if (r.phases[k].shock->location - r.phases[k].plate_z >= clear_of_plate(options, r.bin_height) &&
          r.phases[k].shock->width_over_mfp() > best) {
        best = r.phases[k].shock->width_over_mfp();
        r.width_over_mfp_peak_phase = r.phases[k].phase;
      }
  }
  return r;
}

std::vector<NamedValues> phase_columns(const RunQuantities& r) {
  const auto column = [&](std::string name, std::string unit, auto get) {
    NamedValues c{std::move(name), std::move(unit), {}};
    for (const auto& q : r.phases) c.values.push_back(get(q));
    return c;
  };
  const auto layer = [](auto member) {
    return [member](const PhaseQuantities& q) { return q.layer ? (*q.layer).*member : nan; };
  };
  const auto shock = [](auto get) {
    return [get](const PhaseQuantities& q) { return q.shock ? get(*q.shock) : nan; };
  };
  const auto bin = [&](NamedValues c) {
    c.resolution.assign(r.phases.size(), r.bin_height);
    return c;
  };
  const auto bin_over_mfp = [&](NamedValues c) {
    for (const auto& q : r.phases)
      c.resolution.push_back(q.shock ? r.bin_height / q.shock->mean_free_path : nan);
    return c;
  };
  return {
      column("phase", "1", [](auto& q) { return q.phase; }),
      column("time", "sqrt(sigma/g)", [](auto& q) { return q.time; }),
      column("plate_z", "sigma", [](auto& q) { return q.plate_z; }),
      column("layer_bottom", "sigma", layer(&Layer::bottom)),
      column("layer_top", "sigma", layer(&Layer::top)),
      column("mass_bottom", "sigma", [](auto& q) { return q.mass_bottom; }),
      column("center_of_mass", "sigma", [](auto& q) { return q.center_of_mass; }),
      column("layer_temperature", "g sigma", [](auto& q) { return q.layer_temperature; }),
      column("layer_gap", "sigma",
             [](auto& q) { return q.layer ? q.layer->bottom - q.plate_z : nan; }),
      column("mass_gap", "sigma", [](auto& q) { return q.mass_bottom - q.plate_z; }),
      column("knudsen_mass_fraction", "1", [](auto& q) { return q.knudsen_mass_fraction; }),
      column("temperature_slope_above_layer", "g",
             [](auto& q) { return q.temperature_slope_above; }),
      column("max_mach", "1", [](auto& q) { return q.max_mach; }),
      column("shock_present", "1", [](auto& q) { return q.shock ? 1.0 : 0.0; }),
      column("shock_location", "sigma", shock([](const Shock& s) { return s.location; })),
      bin(column("shock_width", "sigma", shock([](const Shock& s) { return s.width; }))),
      bin_over_mfp(column("width_over_mfp", "1", shock([](const Shock& s) { return s.width_over_mfp(); }))),
      column("mean_free_path", "sigma", shock([](const Shock& s) { return s.mean_free_path; })),
      column("front_width", "sigma", [](auto& q) { return q.front ? q.front->width : nan; }),
      column("front_width_fit_error", "sigma",
             [](auto& q) { return q.front ? q.front->width_error : nan; }),
      column("front_width_over_mfp", "1",
             [](auto& q) { return q.front ? q.front->width / q.front_mean_free_path : nan; }),
      bin(column("shock_compressed_top", "sigma", shock([](const Shock& s) { return s.compressed_top; }))),
      bin(column("shock_undisturbed_bottom", "sigma",
                 shock([](const Shock& s) { return s.undisturbed_bottom; }))),
  };
}

std::vector<NamedValues> run_values(const RunQuantities& r) {
  const auto life = [&](auto member) { return r.shock ? (*r.shock).*member : nan; };
  const double spacing = r.phases.empty() ? nan : 1.0 / static_cast<double>(r.phases.size());
  return {
      {"formation_phase", "1", {life(&ShockLife::formation_phase)}, {spacing}},
      {"exit_phase", "1", {life(&ShockLife::exit_phase)}},
      {"lifetime", "1/f", {life(&ShockLife::lifetime)}, {spacing}},
      {"shock_speed", "sqrt(g sigma)", {life(&ShockLife::speed)}, {life(&ShockLife::speed_resolution)}},
      {"shock_speed_fit_error", "sqrt(g sigma)", {life(&ShockLife::speed_fit_error)}},
      {"shock_curvature", "g", {life(&ShockLife::curvature)}},
      {"shock_phases", "1", {r.shock ? static_cast<double>(r.shock->phases.size()) : 0.0}, {1.0}},
      {"shock_width_mean", "sigma", {life(&ShockLife::width_mean)}, {r.bin_height}},
      {"width_over_mfp_mean", "1", {life(&ShockLife::width_over_mfp_mean)},
       {r.bin_height * life(&ShockLife::width_over_mfp_mean) / life(&ShockLife::width_mean)}},
      {"max_mach_peak", "1", {r.max_mach_peak}},
      {"center_of_mass_mean", "sigma", {r.center_of_mass_mean}},
      {"center_of_mass_apex", "sigma", {r.center_of_mass_apex}},
      {"width_over_mfp_peak_phase", "1", {r.width_over_mfp_peak_phase}, {spacing}},
      {"layer_temperature_peak", "g sigma", {r.layer_temperature_peak}},
  };
}

std::vector<double> crossings_per_cycle(const RunRecord& run, const std::string& column) {
  if (!run.series.has(column) || !run.series.has("t") || run.profiles.empty()) return {};
  const auto& t = run.series.column("t");
  const auto& count = run.series.column(column);
  const double first = std::min_element(run.profiles.begin(), run.profiles.end(),
                                        [](auto& a, auto& b) { return a.time < b.time; })->time;
  // The sampled cycles start at the cycle boundary at or before the first stored profile.
  const double period = (run.profiles.size() > 1 && run.profiles[1].phase > run.profiles[0].phase)
                            ? (run.profiles[1].time - run.profiles[0].time) /
                                  (run.profiles[1].phase - run.profiles[0].phase)
                            : nan;
  if (!std::isfinite(period) || period <= 0.0) return {};
  const double start = std::floor(first / period + 1e-9) * period;
  const auto row_at = [&](double time) -> std::optional<std::size_t> {
    for (std::size_t i = 0; i < t.size(); ++i)
      if (std::abs(t[i] - time) < 1e-9 * std::max(1.0, time)) return i;
    return std::nullopt;
  };
  std::vector<double> per_cycle;
  for (double c = start;; c += period) {
    const auto a = row_at(c), b = row_at(c + period);
    if (!a || !b) break;
    per_cycle.push_back(count[*b] - count[*a]);
  }
  return per_cycle;
}

std::vector<Profile> profiles_without(const RunRecord& run, std::size_t left_out) {
  std::vector<Profile> profiles = run.profiles;
  std::vector<char> use(run.samples.samples(), 1);
  use.at(left_out) = 0;
  for (std::size_t k = 0; k < profiles.size(); ++k) run.samples.pool(k, profiles[k], use);
  return profiles;
}

double jackknife_error(const std::vector<double>& leave_one_out) {
  std::vector<double> v;
  for (double x : leave_one_out)
    if (std::isfinite(x)) v.push_back(x);
  if (v.size() < 2) return nan;
  const double n = static_cast<double>(v.size());
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
  double squares = 0.0;
  for (double x : v) squares += (x - mean) * (x - mean);
  return std::sqrt((n - 1.0) / n * squares);
}

double standard_error(double value, const std::vector<double>& leave_one_out, double resolution) {
  const double sampling = jackknife_error(leave_one_out);
  const double rounding = resolution / std::sqrt(12.0);
  if (!std::isfinite(rounding) || !std::isfinite(value)) return sampling;
  return std::isfinite(sampling) ? std::hypot(sampling, rounding) : rounding;
}

}  // namespace shaker::analysis
