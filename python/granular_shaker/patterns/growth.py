"""The continuum's onset from the growth rate of its pattern (docs/patterns.md).

The continuum has no noise: a flat layer seeded with a small perturbation keeps its pattern
modes linear for many cycles, each growing or decaying by a fixed factor per cycle. The order
parameter M (the rms of the column mass about its mean) is then dominated by the fastest mode,
and ln M rises or falls on a straight line in the cycle count until the pattern saturates (or,
below onset, reaches the round-off of the solver). The onset is where that growth rate, per
cycle, crosses zero as Gamma rises.

- fit_growth_rate: the slope of ln M against the cycle over the linear stage: from
  `first_cycle` (after the layer's first impacts have settled) to the last cycle before M
  exceeds `saturation_fraction` of its largest value (a supercritical amplitude, M = L /
  sqrt(1 + (L / M_sat)^2) for the linear growth L, bends ln M by 2 % there), by least
  squares (a decaying one ends before it falls within 1 / saturation_fraction^2 of its
  smallest value, the solver's floor), with the standard error of the slope from the
  scatter about the line (the cycle-to-cycle modulation of a mode that is not purely
  subharmonic).
- column_mass_modes and fastest_pattern_mode: the amplitude of each Fourier mode of the column
  mass along the box's long side, from a continuum run's column mass, and the growth rate of
  the fastest-growing one. The pattern modes are m >= 2: mode 1, the box's own length, carries
  a slow sloshing of the whole layer (a period of several cycles, not a standing wave).
- grid_scale_gain: whether the growth reaches the grid scale, from the gain over the run of
  the modes of a few cells per wavelength (a broadband growth that does is not a pattern the
  cell resolves).
- growth_bands and fit_zero_crossing: the bands of Gamma over which the pattern grows, each
  edge where a weighted straight line through the growth rates of the points around a change
  of sign crosses zero, its error from the line's covariance (delta method); Gamma_c is the
  lower edge of the band holding the saturated pattern.

python/tests/test_pattern_growth.py measures the bias and the coverage of both errors on
synthetic series and sweeps of known rate and onset.
"""
from dataclasses import dataclass

import numpy as np

from .onset import linear_fit
from .views import mode_amplitudes

FIRST_PATTERN_MODE = 2
# The modes of a run sit on a floor of the solver's when their typical amplitude over the last
# frames is this fraction of their typical first amplitude or less (three decades of decay);
# a mode is fitted only while it stands FLOOR_MARGIN above that floor.
FLOOR_DECAY = 1e-3
FLOOR_MARGIN = 10.0
FLOOR_FRAMES = 10


# A growth rate places the onset by its sign when it lies this many standard errors above 0.
SIGNIFICANT_GROWTH = 2.0
# Modes of this many cells per wavelength or fewer are at the grid scale, where the
# discretisation rather than the equations sets their dynamics.
GRID_SCALE_CELLS = 4


class NoGrowthFit(ValueError):
    """The series or the sweep cannot give the quantity asked for."""


@dataclass
class GrowthRate:
    rate: float          # per cycle: ln M grows by this much each cycle
    rate_error: float
    first_cycle: float
    last_cycle: float
    points: int


@dataclass
class ZeroCrossing:
    gamma_c: float
    gamma_c_error: float
    slope: float         # d(rate)/d(Gamma), per cycle
    slope_error: float
    chi2_per_dof: float
    points: int


@dataclass
class GrowthBand:
    """A range of Gamma over which the pattern grows: consecutive points with a positive rate,
    at least one of them significantly. Its edges are where the rate crosses zero, None where
    the band reaches the end of the sweep."""
    first_gamma: float   # the band's lowest and highest points
    last_gamma: float
    lower: ZeroCrossing | None
    upper: ZeroCrossing | None


def fit_growth_rate(cycles, order, first_cycle=5.0, saturation_fraction=0.2, min_points=5,
                    floor=0.0):
    """The growth rate of ln(order) per cycle over the linear stage (module docstring), which
    also ends before the first frame within FLOOR_MARGIN of a known `floor` of the solver.
    Raises NoGrowthFit when fewer than min_points frames lie in it."""
    cycles, order = np.asarray(cycles, float), np.asarray(order, float)
    if cycles.shape != order.shape or cycles.ndim != 1:
        raise ValueError("cycles and order parameters must be 1D arrays of one length")
    usable = np.isfinite(order) & (order > 0) & (cycles >= first_cycle)
    cycles, order = cycles[usable], order[usable]
    if floor > 0:
        at_floor = np.flatnonzero(order <= FLOOR_MARGIN * floor)
        if at_floor.size:
            cycles, order = cycles[:at_floor[0]], order[:at_floor[0]]
    end = _end_of_linear_stage(order, saturation_fraction)
    cycles, order = cycles[:end], order[:end]
    if cycles.size < min_points:
        raise NoGrowthFit(f"{cycles.size} frames in the linear stage from cycle {first_cycle} "
                          f"(need {min_points})")
    # Unit weights: the scatter about the line sets the variance.
    coefficients, covariance, chi2 = linear_fit([np.ones_like(cycles), cycles], np.log(order),
                                                np.ones_like(cycles))
    covariance = covariance * chi2 / (cycles.size - 2)
    return GrowthRate(float(coefficients[1]), float(np.sqrt(covariance[1, 1])),
                      float(cycles[0]), float(cycles[-1]), int(cycles.size))


def _end_of_linear_stage(order, fraction):
    """The number of leading frames in the linear stage: a growing series ends before it first
    exceeds `fraction` of its largest value, a decaying one before it first falls below
    1 / `fraction`^2 times its smallest (a floor of the solver's adds to the mode, where a
    saturation multiplies it, so it needs the wider margin), each only when the series spans
    more than the square of that factor, so that the stage cut off is at most the later half
    of the series."""
    if order.size < 2:
        return order.size
    if np.polyfit(np.arange(order.size), np.log(order), 1)[0] > 0:
        beyond = order > fraction * order.max()
        spans = order.max() > order[0] / fraction ** 2
    else:
        beyond = order < order.min() / fraction ** 2
        spans = order.min() < order[0] * fraction ** 4
    return int(np.argmax(beyond)) if spans else order.size


def _sorted_rates(gamma, rate, rate_error):
    gamma, rate, error = (np.asarray(a, float) for a in (gamma, rate, rate_error))
    if not (gamma.shape == rate.shape == error.shape) or gamma.ndim != 1:
        raise ValueError("one growth rate and one error per acceleration")
    if not (np.all(np.isfinite(rate)) and np.all(error > 0)):
        raise ValueError("growth rates must be finite and their errors > 0")
    if gamma.size == 0:
        raise NoGrowthFit("no growth rate measured (no finished run)")
    order = np.argsort(gamma)
    return gamma[order], rate[order], error[order]


def _crossing(gamma, rate, error, rising):
    """Where a weighted straight line through the points crosses zero; its slope must have the
    edge's sign (rising: a lower edge)."""
    coefficients, covariance, chi2 = linear_fit([np.ones_like(gamma), gamma], rate, error)
    dof = gamma.size - 2
    chi2_per_dof = chi2 / dof if dof > 0 else float("nan")
    covariance = covariance * (max(1.0, chi2_per_dof) if dof > 0 else 1.0)
    intercept, slope = coefficients
    if not (slope > 0 if rising else slope < 0):
        raise NoGrowthFit(f"the growth rate does not {'rise' if rising else 'fall'} with Gamma "
                          f"near the change of sign (slope {slope:.3g})")
    gradient = np.array([-1.0 / slope, intercept / slope ** 2])
    return ZeroCrossing(float(-intercept / slope), float(np.sqrt(gradient @ covariance @ gradient)),
                        float(slope), float(np.sqrt(covariance[1, 1])), chi2_per_dof,
                        int(gamma.size))


def growth_bands(gamma, rate, rate_error, neighbours=2, significance=SIGNIFICANT_GROWTH):
    """Every band of growth over the sweep (GrowthBand), lowest first. The lower edge is fitted
    by a straight line through up to `neighbours` points on each side of the change of sign,
    those below it from the gap since the previous band only (a rate within its errors of zero
    enters the line as a neighbour, but does not make a band by itself). The upper edge is the
    line through the two points around it: the rate peaks inside the band, so that a line
    through more of its points bends away from the change of sign."""
    gamma, rate, error = _sorted_rates(gamma, rate, rate_error)
    runs, start = [], None
    for i, positive in enumerate(np.append(rate > 0, False)):
        if positive and start is None:
            start = i
        elif not positive and start is not None:
            if np.any(rate[start:i] > significance * error[start:i]):
                runs.append((start, i - 1))
            start = None
    bands = []
    for k, (first, last) in enumerate(runs):
        gap_below = runs[k - 1][1] + 1 if k else 0
        lower = upper = None
        if first > 0:
            lower = slice(max(first - neighbours, gap_below), min(first + neighbours, last + 1))
            lower = _crossing(gamma[lower], rate[lower], error[lower], rising=True)
        if last < gamma.size - 1:
            upper = slice(last, last + 2)
            upper = _crossing(gamma[upper], rate[upper], error[upper], rising=False)
        bands.append(GrowthBand(float(gamma[first]), float(gamma[last]), lower, upper))
    return bands


def fit_zero_crossing(gamma, rate, rate_error, neighbours=2, significance=SIGNIFICANT_GROWTH,
                      holding=None):
    """Gamma_c: the lower edge of the band of growth holding the acceleration `holding` (the
    saturated pattern's), or without it of the lowest band that has one (growth_bands,
    lower_edge). The change of sign needs a rate above zero by `significance` of its standard
    errors. Raises NoGrowthFit when the rates do not change sign so."""
    gamma, rate, error = _sorted_rates(gamma, rate, rate_error)
    return lower_edge(growth_bands(gamma, rate, error, neighbours, significance),
                      (gamma[0], gamma[-1]), holding, significance)


def lower_edge(bands, gamma_range, holding=None, significance=SIGNIFICANT_GROWTH):
    """The onset from a sweep's bands of growth (growth_bands over Gamma `gamma_range`, its
    lowest and highest): the lower edge of the band holding `holding`, or without it of the
    lowest band that has one. Raises NoGrowthFit naming why there is none."""
    if holding is not None:
        band = next((b for b in bands if b.first_gamma <= holding <= b.last_gamma), None)
        if band is None:
            raise NoGrowthFit(f"no band of growth holds Gamma {holding:g}")
        if band.lower is None:
            raise NoGrowthFit(f"the band of growth holding Gamma {holding:g} reaches the "
                              f"sweep's lowest Gamma {gamma_range[0]:.4g}")
        return band.lower
    edges = [b.lower for b in bands if b.lower is not None]
    if not edges:
        raise NoGrowthFit("the growth rates do not change sign from negative to positive "
                          f"(by {significance:g} standard errors) over Gamma "
                          f"{gamma_range[0]:.4g} to {gamma_range[1]:.4g}")
    return edges[0]


def column_mass_modes(frames, modes=12):
    """From a continuum run's column mass (views.column_mass_frames: cycle, phase, fields
    [frame, x, y], box): per frame its cycle and phase, the amplitudes |c_m| / c_0 of the
    Fourier modes m = 1..modes along x (averaged over y), and the box's length along x
    [sigma]."""
    cycle, phase, fields, (length, _) = frames
    if fields.shape[1] <= 2 * modes:
        raise NoGrowthFit(f"{fields.shape[1]} cells along x cannot hold {modes} modes")
    return cycle, phase, mode_amplitudes(fields, modes), length


def grid_scale_gain(frames):
    """The largest factor by which a grid-scale mode of the column mass (GRID_SCALE_CELLS or
    fewer cells per wavelength along x, below the Nyquist mode, present in the first frame)
    grows from the first to the last frame, at the stored phase where those modes are larger.
    Above 1 the growth reaches the grid scale: the pattern it feeds is not resolved by the
    cell."""
    cycle, phase, fields, _ = frames
    nx = fields.shape[1]
    first = -(-nx // GRID_SCALE_CELLS)
    amplitudes = mode_amplitudes(fields, nx // 2 - 1)[:, first - 1:]
    if amplitudes.shape[1] == 0:
        raise NoGrowthFit(f"{nx} cells along x hold no grid-scale mode below the Nyquist mode")
    best = max(np.unique(phase), key=lambda p: amplitudes[phase == p].mean())
    at = amplitudes[phase == best]
    seeded = at[0] > 0.0    # a mode absent at the start has no gain to measure
    if not np.any(seeded):
        raise NoGrowthFit("no grid-scale mode is present in the first frame")
    return float(np.max(at[-1, seeded] / at[0, seeded]))


def solver_floor(amplitudes):
    """The amplitude the modes decay to and stay at (round-off and the solver's floors), or 0
    when the run shows none: the median over the modes of the last FLOOR_FRAMES frames, if it
    lies FLOOR_DECAY or more below the median of the first frame."""
    late = float(np.median(amplitudes[-FLOOR_FRAMES:]))
    return late if late <= FLOOR_DECAY * float(np.median(amplitudes[0])) else 0.0


def fastest_pattern_mode(cycles, phases, amplitudes, min_points=10, **fit_options):
    """At the stored phase with the larger mean amplitude, the growth rate of every pattern
    mode (m >= FIRST_PATTERN_MODE) with at least `min_points` frames in its linear stage above
    the solver's floor (a mode that reaches the floor sooner decays by more than a decade per
    cycle or two, and frames on the floor are noise, not growth); returns (m, its GrowthRate,
    {m: rate}). Raises NoGrowthFit when no mode has enough frames."""
    best_phase = max(np.unique(phases), key=lambda p: amplitudes[phases == p].mean())
    at = phases == best_phase
    floor = solver_floor(amplitudes[at])
    rates = {}
    for m in range(FIRST_PATTERN_MODE, amplitudes.shape[1] + 1):
        try:
            rates[m] = fit_growth_rate(cycles[at], amplitudes[at, m - 1],
                                       min_points=min_points, floor=floor, **fit_options)
        except NoGrowthFit:
            continue
    if not rates:
        raise NoGrowthFit(f"no pattern mode has {min_points} frames in its linear stage")
    fastest = max(rates, key=lambda m: rates[m].rate)
    return fastest, rates[fastest], {m: fit.rate for m, fit in rates.items()}
