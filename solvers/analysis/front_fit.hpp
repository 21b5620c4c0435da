#pragma once
// A shock width that does not depend on the bin: a smooth front fitted
// across the shock. The paper's width (T maximum to T minimum, find_shock) is a whole number
// of bins and cannot resolve a front about one mean free path wide; the fitted one can, and
// comes with an error.
#include <optional>
#include <vector>

namespace shaker::analysis {

struct FrontFit {
  double location = 0, location_error = 0;  ///< centre z0 of the front
  /// maximum-slope thickness: |jump| / max|df/dz| (= 2 w for a tanh of half-width w)
  double width = 0, width_error = 0;
  double low = 0, high = 0;  ///< asymptotic values below/above (f(z0 -/+ inf))
  /// error of the jump high - low: whether there is a front at all is |jump| against it
  double jump_error = 0;
  double reduced_chi2 = 0;   ///< chi^2 / (points - 4), with the weights used in the fit
  int points = 0;            ///< bins in the window
};

/// Least-squares fit of f(z) = a + b tanh((z - z0) / w) to the bins with z in [z_lo, z_hi];
/// weights 1/se^2 when se is given (non-empty, and finite and positive in every bin of the
/// window), else unweighted with the errors scaled by the reduced chi^2.
///
/// z are bin centres, strictly increasing; a bin extends half-way to its neighbours (the outer
/// bins symmetrically), and the model compared with f is the tanh averaged over each bin, as
/// MD bins and continuum cells are averages. That is what lets a front thinner than a bin be
/// measured; for bins much thinner than w it is the tanh at the centre.
///
/// Nothing if the fit does not converge, has fewer than 5 points, the front's centre is
/// outside [z_lo, z_hi], a value in the window is not finite, or the parameters are not
/// determined (a singular covariance, e.g. a front much thinner than a bin, whose width the
/// bin averages no longer see; short of that, such a front can give a width_error far larger
/// than the width, meaning the same). Throws std::invalid_argument if the lengths of z, f and a
/// non-empty se differ, or z is not strictly increasing.
std::optional<FrontFit> fit_front(const std::vector<double>& z, const std::vector<double>& f,
                                  const std::vector<double>& se, double z_lo, double z_hi);

}  // namespace shaker::analysis
