"""The onset of a pattern from its order parameter M (the rms of the column mass about its
mean, docs/analysis.md "Patterns") measured at accelerations Gamma, each with its standard
error from independent frames or seeds.

Two models, each fitted to a power (the onset to M^2, the Swift-Hohenberg form to one Fourier
mode's), by weighted least squares and a profile of chi^2 over the onset, so that the one
non-linear parameter is scanned and the linear ones solved exactly at each value:

- fit_onset: a supercritical bifurcation over a noise floor,
      M^2 = floor + slope * max(Gamma - Gamma_c, 0),
  the saturated amplitude growing as sqrt(Gamma - Gamma_c) above onset (the continuum's
  onset, and the MD's ordered onset).
- fit_swift_hohenberg: the fluctuations below onset of the linear Swift-Hohenberg equation
  with additive noise (Swift and Hohenberg 1977; Goldman, Swift and Swinney 2004). Each
  Fourier mode of the field relaxes at its own rate and the noise keeps it stirred, so its
  mean power (the structure factor) is the noise's over that rate; at the critical wavenumber
  q0 the rate vanishes at the mean-field onset, and the power there grows as 1 / (-epsilon):
      S(q0) = floor + strength / ((Gamma_mf - Gamma) / Gamma_mf),   Gamma < Gamma_mf.
  Fitted to the power of the box's Fourier mode at the stripes' wavenumber, not to the
  field's whole variance M^2, in which the particles' counting noise at every wavenumber
  buries the critical mode's growth. `strength` is the noise's power in that mode's units;
  turning it into the dimensionless noise strength F of Swift-Hohenberg theory needs the
  coefficients xi0, tau0 and q0 of the linear growth rates, which this fit does not measure.

The onset's error is the half-width of the interval where chi^2 rises by one above its
minimum, with chi^2 scaled by its value per degree of freedom when that exceeds one (a model
that does not describe the points within their errors widens its own interval);
python/tests/test_pattern_onset.py measures the bias and the coverage of these errors on
synthetic sweeps of known onset.
"""
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

PROFILE_POINTS = 4001
# A point shows an ordered standing wave when its spectrum's angular moments name stripes (A2,
# docs/analysis.md "Patterns": the symmetry threshold) and its pattern repeats from one cycle to
# the next shifted by half a wavelength (the subharmonic response, whatever the waveform).
STRIPES_A2 = 0.5
SUBHARMONIC_CORRELATION = 0.5


class NoOnset(ValueError):
    """The sweep does not bracket an onset the model can place."""


@dataclass
class OnsetFit:
    gamma_c: float
    gamma_c_error: float
    slope: float
    slope_error: float
    floor: float
    floor_error: float
    chi2_per_dof: float
    points: int


@dataclass
class SwiftHohenbergFit:
    gamma_mf: float
    gamma_mf_error: float
    strength: float
    strength_error: float
    floor: float
    floor_error: float
    chi2_per_dof: float
    points: int


def _checked(values, error, what):
    values, error = np.asarray(values, float), np.asarray(error, float)
    if values.shape != error.shape or values.ndim != 1:
        raise ValueError(f"{what}s and errors must be 1D arrays of one length")
    if not (np.all(np.isfinite(values)) and np.all(np.isfinite(error)) and np.all(error > 0)):
        raise ValueError(f"{what}s must be finite and their errors finite and > 0")
    return values, error


def _power_and_error(order, error):
    order, error = _checked(order, error, "order parameter")
    return order ** 2, 2.0 * np.abs(order) * error


def linear_fit(columns, y, sigma):
    """Weighted least squares of y on the columns: coefficients, their covariance, chi^2."""
    design = np.column_stack(columns) / sigma[:, None]
    target = y / sigma
    coefficients, *_ = np.linalg.lstsq(design, target, rcond=None)
    residual = target - design @ coefficients
    covariance = np.linalg.pinv(design.T @ design)
    return coefficients, covariance, float(residual @ residual)


def _profile(x_of, candidates, y, sigma):
    """chi^2 of the straight-line fit y = a + b x_c for every candidate c at once (x_of maps
    the candidates to a candidates x points array): the normal equations in closed form."""
    x = x_of(candidates[:, None])
    w = 1.0 / sigma ** 2
    s, sy, syy = w.sum(), (w * y).sum(), (w * y * y).sum()
    sx, sxx, sxy = (w * x).sum(axis=1), (w * x * x).sum(axis=1), (w * x * y).sum(axis=1)
    determinant = s * sxx - sx * sx
    with np.errstate(divide="ignore", invalid="ignore"):
        explained = (sxx * sy * sy - 2.0 * sx * sy * sxy + s * sxy * sxy) / determinant
    chi2 = np.where(determinant > 0, np.maximum(syy - explained, 0.0), np.inf)
    return int(np.argmin(chi2)), chi2


def _best_fit(x_of, candidates, chi2, best, y, sigma, what):
    """At the best candidate: (candidate, its error, [floor, coefficient], their errors,
    chi^2 per degree of freedom). The error is the half-width of {c : chi2(c) <= min + scale},
    the scale max(1, chi2_min / dof), which also scales the coefficients' covariance. Raises
    NoOnset when the coefficient of the growth is not above twice its error."""
    dof = y.size - 3
    scale = max(1.0, chi2[best] / dof) if dof > 0 else 1.0
    inside = np.flatnonzero(chi2 <= chi2[best] + scale)
    step = candidates[1] - candidates[0]
    half_width = 0.5 * (candidates[inside[-1]] - candidates[inside[0]] + step)
    # The grid's best candidate refined between its neighbours, so that the coefficients are
    # not those of a value up to half a step off.
    refined = minimize_scalar(lambda c: _profile(x_of, np.array([c]), y, sigma)[1][0],
                              bounds=(candidates[max(best - 1, 0)],
                                      candidates[min(best + 1, candidates.size - 1)]),
                              method="bounded", options=dict(xatol=1e-9 * abs(step) + 1e-12)).x
    coefficients, covariance, _ = linear_fit([np.ones_like(y), x_of(refined)], y, sigma)
    errors = np.sqrt(np.diag(covariance) * scale)
    if not coefficients[1] > 2.0 * errors[1]:
        raise NoOnset(f"{what} ({coefficients[1]:.3g} +- {errors[1]:.2g})")
    return (float(refined), float(half_width), coefficients, errors,
            chi2[best] / dof if dof > 0 else np.nan)


def fit_onset(gamma, order, error):
    """Fits M^2 = floor + slope * max(Gamma - Gamma_c, 0); Gamma_c is sought between the
    sweep's second-lowest and second-highest Gamma, so that at least two points lie on each
    side. Raises NoOnset when the best onset sits at either end of that range or the slope is
    not above twice its error."""
    gamma = np.asarray(gamma, float)
    y, sigma = _power_and_error(order, error)
    if gamma.shape != y.shape or gamma.size < 5:
        raise ValueError("an onset fit needs at least 5 accelerations, one order parameter each")
    ordered = np.sort(gamma)
    candidates = np.linspace(ordered[1], ordered[-2], PROFILE_POINTS)

    def above(c):
        return np.maximum(gamma - c, 0.0)

    best, chi2 = _profile(above, candidates, y, sigma)
    if best in (0, candidates.size - 1):
        raise NoOnset(f"the best onset is at the end of the sweep (Gamma = "
                      f"{candidates[best]:.4g}): the sweep from {ordered[0]:.4g} to "
                      f"{ordered[-1]:.4g} does not bracket it")
    onset, onset_error, (floor, slope), errors, chi2_per_dof = _best_fit(
        above, candidates, chi2, best, y, sigma,
        "the order parameter does not grow above a floor: the sweep does not bracket an onset "
        "(slope")
    return OnsetFit(onset, onset_error, float(slope), float(errors[1]), float(floor),
                    float(errors[0]), chi2_per_dof, int(gamma.size))


def fit_swift_hohenberg(gamma, power, error, onset_at_most=None):
    """Fits S = floor + strength / ((Gamma_mf - Gamma) / Gamma_mf) to the critical mode's power
    S at the points below `onset_at_most` (all points if None), Gamma_mf sought above the
    highest of them, up to twice the sweep's span beyond it. Raises NoOnset when the best
    Gamma_mf is at the upper end (no divergence in sight) or the strength is not above twice
    its error."""
    gamma = np.asarray(gamma, float)
    y, sigma = _checked(power, error, "mode power")
    if gamma.shape != y.shape:
        raise ValueError("one mode power per acceleration")
    below = gamma < onset_at_most if onset_at_most is not None else np.ones(gamma.shape, bool)
    gamma, y, sigma = gamma[below], y[below], sigma[below]
    if gamma.size < 4:
        raise ValueError(f"a Swift-Hohenberg fit needs at least 4 accelerations below onset, "
                         f"got {gamma.size}")
    top, span = gamma.max(), gamma.max() - gamma.min()
    # Above the highest point by a small fraction of the spacing, so that no point diverges.
    candidates = np.linspace(top + 1e-3 * span, top + 2.0 * span, PROFILE_POINTS)

    def growth(c):
        return c / (c - gamma)

    best, chi2 = _profile(growth, candidates, y, sigma)
    if best == candidates.size - 1:
        raise NoOnset("the fluctuations below onset do not grow towards a mean-field onset "
                      f"within {2.0 * span:.3g} in Gamma of the sweep's top")
    onset, onset_error, (floor, strength), errors, chi2_per_dof = _best_fit(
        growth, candidates, chi2, best, y, sigma,
        "the fluctuations below onset do not grow towards an onset (strength")
    return SwiftHohenbergFit(onset, onset_error, float(strength), float(errors[1]), float(floor),
                             float(errors[0]), chi2_per_dof, int(gamma.size))


def rising_branch(points):
    """The points, in order of Gamma, up to the one with the largest order parameter. Past it
    the pattern's amplitude falls again as Gamma grows (the layer's flight lengthens towards
    the next bifurcation), which the supercritical form near onset does not describe."""
    points = sorted(points, key=lambda p: p["gamma"])
    if not points:
        return points
    top = int(np.argmax([p["order"] for p in points]))
    return points[:top + 1]


def ordered_run(summary):
    """One run's (or a bare point's) saturated pattern is an ordered standing wave; without a
    symmetry measurement (a figure's bare points) it is not."""
    return (summary.get("a2", 0.0) >= STRIPES_A2
            and summary.get("half_wavelength_correlation", 0.0) >= SUBHARMONIC_CORRELATION)


def ordered(point):
    """Ordered standing waves at the point: in some of its seeds (a point of several seeds
    counts them in `ordered_seeds`), else by its own values. Near a hysteretic onset the flat
    layer of one seed orders where another's stays disordered; the onset of order from a flat
    start is the lowest Gamma where any does."""
    if "ordered_seeds" in point:
        return point["ordered_seeds"] > 0
    return ordered_run(point)


def coexisting(point):
    """Some of the point's seeds ordered and some not: ordered and disordered states coexist."""
    return 0 < point.get("ordered_seeds", 0) < point.get("seeds", 1)


def order_bracket(case):
    """The onset of ordered standing waves bracketed by the sweep: (midpoint, its standard
    error as a uniform distribution over the bracket, last disordered Gamma, first ordered
    Gamma), when on the rising branch of the order parameter (the points the onset fit uses)
    every point above some Gamma is ordered and none below it; else None."""
    points = rising_branch(case["points"])
    flags = [ordered(p) for p in points]
    if True not in flags or False not in flags:
        return None
    first = flags.index(True)
    if first == 0 or not all(flags[first:]):
        return None
    low, high = points[first - 1]["gamma"], points[first]["gamma"]
    return 0.5 * (low + high), (high - low) / np.sqrt(12.0), low, high
