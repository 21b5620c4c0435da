#include "support/convergence.hpp"

#include <gsl/gsl_fit.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace shaker::convergence {

namespace {
constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();

void require_positive(double value, const char* what) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument(std::string(what) + " must be positive and finite, got " +
                                std::to_string(value));
}
}  // namespace

double observed_order(double error_coarse, double error_fine, double refinement_ratio) {
  require_positive(error_coarse, "coarse error");
  require_positive(error_fine, "fine error");
  if (!(refinement_ratio > 1.0)) throw std::invalid_argument("refinement ratio must exceed 1");
  return std::log(error_coarse / error_fine) / std::log(refinement_ratio);
}

OrderFit fit_order(std::span<const double> h, std::span<const double> error, std::size_t finest) {
  if (h.size() != error.size()) throw std::invalid_argument("fit_order: h and error sizes differ");
  const std::size_t count = finest == 0 ? h.size() : std::min(finest, h.size());
  if (count < 2) throw std::invalid_argument("fit_order: needs at least two levels");

  // The finest levels are the ones with the smallest h, whatever order the caller used.
  std::vector<std::size_t> order(h.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return h[a] < h[b]; });

  std::vector<double> log_h(count), log_e(count);
  for (std::size_t k = 0; k < count; ++k) {
    require_positive(h[order[k]], "h");
    require_positive(error[order[k]], "error");
    log_h[k] = std::log(h[order[k]]);
    log_e[k] = std::log(error[order[k]]);
  }
  double c0 = 0.0, c1 = 0.0, cov00 = 0.0, cov01 = 0.0, cov11 = 0.0, sumsq = 0.0;
  gsl_fit_linear(log_h.data(), 1, log_e.data(), 1, count, &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
  // GSL estimates the covariance from the scatter with n - 2 degrees of freedom: undefined
  // for two points, where the line passes through both exactly.
  const double std_error = count > 2 ? std::sqrt(cov11) : not_a_number;
  return OrderFit{c1, std_error, c0, count};
}

double richardson_extrapolate(double phi_fine, double phi_coarse, double refinement_ratio,
                              double order) {
  const double rp = std::pow(refinement_ratio, order);
  return (rp * phi_fine - phi_coarse) / (rp - 1.0);
}

std::string to_string(ConvergenceKind kind) {
  switch (kind) {
    case ConvergenceKind::monotonic: return "monotonic";
    case ConvergenceKind::oscillatory: return "oscillatory";
    case ConvergenceKind::stagnant: return "stagnant";
    case ConvergenceKind::two_grids: return "two-grids";
  }
  return "unknown";
}

namespace {
// Celik et al. (2008), eqs. (5a-c): p = |ln|eps32/eps21| + q(p)| / ln r21,
// q(p) = ln((r21^p - s) / (r32^p - s)), s = sign(eps32 / eps21). Solved by fixed-point
// iteration from q = 0 (exact in one step when r21 == r32). Equal monotonic changes give
// p = 0, where q takes its limit ln(ln r21 / ln r32).
struct ApparentOrder {
  double p;
  bool converged;
  int iterations;
};
ApparentOrder apparent_order(double r21, double r32, double eps21, double eps32) {
  const double s = std::copysign(1.0, eps32 / eps21);
  const double log_ratio = std::log(std::abs(eps32 / eps21));
  const auto q = [&](double p) {
    if (p == 0.0 && s > 0.0) return std::log(std::log(r21) / std::log(r32));
    return std::log((std::pow(r21, p) - s) / (std::pow(r32, p) - s));
  };
  double p = std::abs(log_ratio) / std::log(r21);
  constexpr int max_iterations = 500;
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    const double next = std::abs(log_ratio + q(p)) / std::log(r21);
    if (!std::isfinite(next)) return {not_a_number, false, iteration};
    const bool done = std::abs(next - p) <= 1e-14 * std::max(1.0, std::abs(next));
    p = next;
    if (done) return {p, true, iteration};
  }
  return {p, false, max_iterations};
}
}  // namespace

GciResult three_grid_gci(double h1, double h2, double h3, double phi1, double phi2, double phi3,
                         double safety_factor) {
  require_positive(h1, "h1");
  if (!(h1 < h2 && h2 < h3))
    throw std::invalid_argument("three_grid_gci: needs h1 < h2 < h3 (fine to coarse)");
  GciResult result;
  result.r21 = h2 / h1;
  result.r32 = h3 / h2;
  const double eps21 = phi2 - phi1;
  const double eps32 = phi3 - phi2;
  result.relative_difference21 = std::abs(eps21 / phi1);
  result.relative_difference32 = std::abs(eps32 / phi2);
  const double scale = std::max({std::abs(phi1), std::abs(phi2), std::abs(phi3)});
  const auto no_change = [&](double eps) { return std::abs(eps) <= round_off_change * scale; };
  if (no_change(eps21) || no_change(eps32)) {
    result.kind = ConvergenceKind::stagnant;
    result.order = result.phi_extrapolated = result.extrapolated_error21 = not_a_number;
    result.gci21 = result.gci32 = result.asymptotic_ratio = not_a_number;
    return result;
  }
  result.kind = eps32 / eps21 > 0.0 ? ConvergenceKind::monotonic : ConvergenceKind::oscillatory;
  const ApparentOrder p = apparent_order(result.r21, result.r32, eps21, eps32);
  result.order = p.p;
  result.order_converged = p.converged;
  result.iterations = p.iterations;
  if (result.order == 0.0) {  // the changes do not shrink: no extrapolation, no finite bound
    result.phi_extrapolated = result.extrapolated_error21 = result.asymptotic_ratio = not_a_number;
    result.gci21 = result.gci32 = std::numeric_limits<double>::infinity();
    return result;
  }
  result.phi_extrapolated = richardson_extrapolate(phi1, phi2, result.r21, result.order);
  result.extrapolated_error21 =
      std::abs((result.phi_extrapolated - phi1) / result.phi_extrapolated);
  const double r21p = std::pow(result.r21, result.order);
  const double r32p = std::pow(result.r32, result.order);
  result.gci21 = safety_factor * result.relative_difference21 / (r21p - 1.0);
  result.gci32 = safety_factor * result.relative_difference32 / (r32p - 1.0);
  result.asymptotic_ratio = result.gci32 / (r21p * result.gci21);
  return result;
}

TwoGridGci two_grid_gci(double h1, double h2, double phi1, double phi2, double assumed_order,
                        double safety_factor) {
  require_positive(h1, "h1");
  if (!(h1 < h2)) throw std::invalid_argument("two_grid_gci: needs h1 < h2 (fine, coarse)");
  require_positive(assumed_order, "assumed order");
  TwoGridGci result;
  result.r21 = h2 / h1;
  result.order = assumed_order;
  result.phi_extrapolated = richardson_extrapolate(phi1, phi2, result.r21, assumed_order);
  result.relative_difference21 = std::abs((phi1 - phi2) / phi1);
  result.gci21 =
      safety_factor * result.relative_difference21 / (std::pow(result.r21, assumed_order) - 1.0);
  return result;
}

ErrorNorms error_norms(std::span<const double> numeric, std::span<const double> exact) {
  if (numeric.size() != exact.size() || numeric.empty())
    throw std::invalid_argument("error_norms: fields must be non-empty and of equal size");
  ErrorNorms norms;
  for (std::size_t k = 0; k < numeric.size(); ++k) {
    const double e = std::abs(numeric[k] - exact[k]);
    norms.l1 += e;
    norms.l2 += e * e;
    norms.linf = std::max(norms.linf, e);
  }
  const double count = static_cast<double>(numeric.size());
  norms.l1 /= count;
  norms.l2 = std::sqrt(norms.l2 / count);
  return norms;
}

}  // namespace shaker::convergence
