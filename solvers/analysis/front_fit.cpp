#include "analysis/front_fit.hpp"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace shaker::analysis {
namespace {

// Parameters of f(z) = a + b tanh((z - z0) / w), in GSL's parameter vector.
enum Parameter : std::size_t { kA = 0, kB = 1, kZ0 = 2, kW = 3, kParameters = 4 };

/// ln cosh u without overflow: cosh u overflows a double for |u| > 710.
double log_cosh(double u) {
  const double a = std::abs(u);
  return a + std::log1p(std::exp(-2.0 * a)) - std::log(2.0);
}

/// The mean of tanh(u) over [x - d, x + d], with x and d in units of w (both change sign with
/// w, and so does the mean). The closed form (ln cosh(x + d) - ln cosh(x - d)) / (2 d) loses
/// all its digits to cancellation for bins much thinner than w; the identity
/// ln cosh(x + d) - ln cosh(x - d) = 2 atanh(tanh x tanh d) keeps them, but atanh reaches 1
/// (and infinity) in double precision for large x and d, where the difference is large and
/// exact enough.
double mean_tanh(double x, double d) {
  const double q = std::tanh(x) * std::tanh(d);
  if (std::abs(q) < 0.5) return std::atanh(q) / d;
  return (log_cosh(x + d) - log_cosh(x - d)) / (2.0 * d);
}

struct Bins {
  std::vector<double> centre, half_height, value;
};

struct Model {
  double a, b, z0, w;
  explicit Model(const gsl_vector* p)
      : a(gsl_vector_get(p, kA)), b(gsl_vector_get(p, kB)), z0(gsl_vector_get(p, kZ0)),
        w(gsl_vector_get(p, kW)) {}
};

int residuals(const gsl_vector* p, void* data, gsl_vector* r) {
  const auto& bins = *static_cast<const Bins*>(data);
  const Model m(p);
  for (std::size_t i = 0; i < bins.centre.size(); ++i) {
    const double x = (bins.centre[i] - m.z0) / m.w, d = bins.half_height[i] / m.w;
    gsl_vector_set(r, i, m.a + m.b * mean_tanh(x, d) - bins.value[i]);
  }
  return GSL_SUCCESS;
}

int jacobian(const gsl_vector* p, void* data, gsl_matrix* J) {
  const auto& bins = *static_cast<const Bins*>(data);
  const Model m(p);
  for (std::size_t i = 0; i < bins.centre.size(); ++i) {
    const double x = (bins.centre[i] - m.z0) / m.w, d = bins.half_height[i] / m.w;
    const double mean = mean_tanh(x, d);
    const double t_hi = std::tanh(x + d), t_lo = std::tanh(x - d);
    // Derivatives of the bin mean (w / h) [ln cosh(u_hi) - ln cosh(u_lo)], u = (edge - z0) / w.
    const double d_z0 = -(t_hi - t_lo) / (2.0 * d * m.w);
    const double d_w = (mean - ((x + d) * t_hi - (x - d) * t_lo) / (2.0 * d)) / m.w;
    gsl_matrix_set(J, i, kA, 1.0);
    gsl_matrix_set(J, i, kB, mean);
    gsl_matrix_set(J, i, kZ0, m.b * d_z0);
    gsl_matrix_set(J, i, kW, m.b * d_w);
  }
  return GSL_SUCCESS;
}

struct WorkspaceDeleter {
  void operator()(gsl_multifit_nlinear_workspace* w) const { gsl_multifit_nlinear_free(w); }
};
struct VectorDeleter {
  void operator()(gsl_vector* v) const { gsl_vector_free(v); }
};
struct MatrixDeleter {
  void operator()(gsl_matrix* m) const { gsl_matrix_free(m); }
};
using VectorPtr = std::unique_ptr<gsl_vector, VectorDeleter>;

/// Start values from the data: the levels of the two ends of the window, the centre at the
/// steepest change in the direction of the jump, and w from that slope (at least a quarter bin,
/// at most the window: a noisy slope must not start the fit at a front the window cannot hold).
std::array<double, kParameters> start_values(const Bins& bins) {
  const std::size_t m = bins.centre.size(), k = std::max<std::size_t>(1, m / 5);
  double low = 0.0, high = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    low += bins.value[i] / static_cast<double>(k);
    high += bins.value[m - 1 - i] / static_cast<double>(k);
  }
  const double sign = high >= low ? 1.0 : -1.0;
  std::size_t steepest = 0;
  double slope = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < m; ++i) {
    const double s =
        sign * (bins.value[i + 1] - bins.value[i]) / (bins.centre[i + 1] - bins.centre[i]);
    if (s > slope) slope = s, steepest = i;
  }
  const double span = bins.centre[m - 1] - bins.centre[0];
  const double z0 = 0.5 * (bins.centre[steepest] + bins.centre[steepest + 1]);
  const double quarter_bin = 0.5 * bins.half_height[steepest];
  double w = slope > 0.0 ? 0.5 * std::abs(high - low) / slope : span;
  w = std::clamp(w, quarter_bin, 0.5 * span);
  return {0.5 * (high + low), 0.5 * (high - low), z0, w};
}

/// The profile's bins inside [z_lo, z_hi] and their standard errors; nullopt when fewer than
/// five or any is not finite.
struct Window {
  Bins bins;
  std::vector<double> sigma;
  bool weighted = false;  ///< every bin has a finite positive standard error
};

std::optional<Window> window_of(const std::vector<double>& z, const std::vector<double>& f,
                                const std::vector<double>& se, double z_lo, double z_hi) {
  Window window;
  Bins& bins = window.bins;
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (!(z[i] >= z_lo && z[i] <= z_hi)) continue;
    // A bin reaches half-way to its neighbours; the outer bins of the profile symmetrically.
    const double below = i > 0 ? z[i] - z[i - 1] : z[i + 1] - z[i];
    const double above = i + 1 < z.size() ? z[i + 1] - z[i] : below;
    bins.centre.push_back(z[i] + 0.25 * (above - below));
    bins.half_height.push_back(0.25 * (above + below));
    bins.value.push_back(f[i]);
    if (!se.empty()) window.sigma.push_back(se[i]);
  }
  const std::size_t m = bins.centre.size();
  if (m < 5) return std::nullopt;
  for (std::size_t i = 0; i < m; ++i)
    if (!std::isfinite(bins.value[i]) || !std::isfinite(bins.centre[i])) return std::nullopt;
  window.weighted = !window.sigma.empty() && std::all_of(window.sigma.begin(), window.sigma.end(), [](double s) {
    return std::isfinite(s) && s > 0.0;
  });
  return window;
}

using Workspace = std::unique_ptr<gsl_multifit_nlinear_workspace, WorkspaceDeleter>;

/// The trust-region least-squares fit of the model to the window from start_values; nullptr if
/// it does not converge.
Workspace solve(Window& window) {
  const std::size_t m = window.bins.centre.size();
  gsl_multifit_nlinear_fdf fdf{};
  fdf.f = residuals;
  fdf.df = jacobian;
  fdf.fvv = nullptr;
  fdf.n = m;
  fdf.p = kParameters;
  fdf.params = &window.bins;
  const gsl_multifit_nlinear_parameters parameters = gsl_multifit_nlinear_default_parameters();
  Workspace workspace(gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &parameters, m, kParameters));
  const auto start = start_values(window.bins);
  gsl_vector_const_view x0 = gsl_vector_const_view_array(start.data(), kParameters);
  VectorPtr weights;
  if (window.weighted) {
    weights.reset(gsl_vector_alloc(m));
    for (std::size_t i = 0; i < m; ++i) gsl_vector_set(weights.get(), i, 1.0 / (window.sigma[i] * window.sigma[i]));
    gsl_multifit_nlinear_winit(&x0.vector, weights.get(), &fdf, workspace.get());
  } else {
    gsl_multifit_nlinear_init(&x0.vector, &fdf, workspace.get());
  }
  // Tight tolerances: a noise-free front is to be recovered to 1e-6 and the trust region
  // converges quadratically near the minimum, so they cost a few iterations at most.
  int info = 0;
  const int status = gsl_multifit_nlinear_driver(200, 1e-12, 1e-12, 0.0, nullptr, nullptr, &info, workspace.get());
  if (status != GSL_SUCCESS) workspace.reset();
  return workspace;
}

/// The front of a converged fit with its standard errors; nullopt if a parameter is not
/// determined by the data or the front lies outside [z_lo, z_hi].
std::optional<FrontFit> front_of(gsl_multifit_nlinear_workspace* workspace, const Window& window, double z_lo,
                                 double z_hi) {
  const std::size_t m = window.bins.centre.size();
  const gsl_vector* p = gsl_multifit_nlinear_position(workspace);
  const gsl_vector* r = gsl_multifit_nlinear_residual(workspace);
  double chi2 = 0.0;
  gsl_blas_ddot(r, r, &chi2);  // the residuals are weighted already when weights are given
  const double reduced_chi2 = chi2 / static_cast<double>(m - kParameters);

  std::unique_ptr<gsl_matrix, MatrixDeleter> covariance(gsl_matrix_alloc(kParameters, kParameters));
  // A parameter the data do not determine gets a zero row here rather than a huge variance;
  // it is caught below.
  gsl_multifit_nlinear_covar(gsl_multifit_nlinear_jac(workspace), 1e-12, covariance.get());
  // Given standard errors are trusted: scaling by chi^2 would hide a model that does not fit
  // (reported in reduced_chi2) and make the errors noisy themselves. Without them the scatter
  // about the fit is the only estimate of the noise.
  const double scale = window.weighted ? 1.0 : reduced_chi2;
  const double var_z0 = scale * gsl_matrix_get(covariance.get(), kZ0, kZ0);
  const double var_w = scale * gsl_matrix_get(covariance.get(), kW, kW);
  const double var_b = scale * gsl_matrix_get(covariance.get(), kB, kB);
  for (const double v : {var_z0, var_w, var_b})
    if (!(v > 0.0 && std::isfinite(v))) return std::nullopt;

  Model fitted(p);
  // The model is odd in w; report the front with w > 0, so that low is the value below.
  if (fitted.w < 0.0) fitted.w = -fitted.w, fitted.b = -fitted.b;
  if (!(fitted.z0 >= z_lo && fitted.z0 <= z_hi)) return std::nullopt;

  FrontFit fit;
  fit.location = fitted.z0;
  fit.location_error = std::sqrt(var_z0);
  fit.width = 2.0 * fitted.w;
  fit.width_error = 2.0 * std::sqrt(var_w);
  fit.low = fitted.a - fitted.b;
  fit.high = fitted.a + fitted.b;
  fit.jump_error = 2.0 * std::sqrt(var_b);
  fit.reduced_chi2 = reduced_chi2;
  fit.points = static_cast<int>(m);
  return fit;
}

}  // namespace

std::optional<FrontFit> fit_front(const std::vector<double>& z, const std::vector<double>& f,
                                  const std::vector<double>& se, double z_lo, double z_hi) {
  if (z.size() != f.size() || (!se.empty() && se.size() != z.size()))
    throw std::invalid_argument("fit_front: z, f and se differ in length");
  if (z.size() < 5) return std::nullopt;
  for (std::size_t i = 0; i + 1 < z.size(); ++i)
    if (!(z[i + 1] > z[i]) && std::isfinite(z[i]) && std::isfinite(z[i + 1]))
      throw std::invalid_argument("fit_front: z is not strictly increasing");
  std::optional<Window> window = window_of(z, f, se, z_lo, z_hi);
  if (!window) return std::nullopt;
  const Workspace workspace = solve(*window);
  if (!workspace) return std::nullopt;
  return front_of(workspace.get(), *window, z_lo, z_hi);
}

}  // namespace shaker::analysis
