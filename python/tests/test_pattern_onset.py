"""The onset fits of granular_shaker.patterns on synthetic sweeps of known onset: the bias of
the fitted onset and the coverage of its error, over many independent noisy sweeps, at the
relative errors of the order parameter the study measures (a few per cent)."""
import numpy as np
import pytest
from estimator_coverage import coverage

from granular_shaker.patterns import NoOnset, fit_onset, fit_swift_hohenberg

GAMMA = np.round(np.arange(2.0, 3.21, 0.1), 10)
ONSET, SLOPE, FLOOR = 2.55, 0.04, 4e-4
BELOW = np.round(np.arange(2.0, 2.61, 0.05), 10)
MEAN_FIELD, STRENGTH, SH_FLOOR = 2.7, 2e-4, 1e-4
SWEEPS = 300


def supercritical(gamma):
    return np.sqrt(FLOOR + SLOPE * np.maximum(gamma - ONSET, 0.0))


def swift_hohenberg(gamma):
    return np.sqrt(SH_FLOOR + STRENGTH / np.sqrt((MEAN_FIELD - gamma) / MEAN_FIELD))


def noisy(truth, relative_error, seed):
    error = relative_error * truth
    return truth + error * np.random.default_rng(seed).standard_normal(truth.size), error


def test_a_noiseless_sweep_gives_the_onset_and_the_coefficients():
    fit = fit_onset(GAMMA, supercritical(GAMMA), 0.03 * supercritical(GAMMA))
    assert fit.gamma_c == pytest.approx(ONSET, abs=2e-4)
    assert fit.slope == pytest.approx(SLOPE, rel=1e-3)
    assert fit.floor == pytest.approx(FLOOR, rel=1e-3)
    assert fit.chi2_per_dof < 1e-6
    sh = fit_swift_hohenberg(BELOW, swift_hohenberg(BELOW), 0.03 * swift_hohenberg(BELOW))
    assert sh.gamma_mf == pytest.approx(MEAN_FIELD, abs=2e-4)
    assert sh.strength == pytest.approx(STRENGTH, rel=1e-3)


def test_the_onset_error_covers_the_truth_as_a_standard_error_should():
    fits = [fit_onset(GAMMA, *noisy(supercritical(GAMMA), 0.03, seed)) for seed in range(SWEEPS)]
    deviation, error, one, two = coverage([f.gamma_c for f in fits],
                                          [f.gamma_c_error for f in fits], ONSET)
    assert abs(deviation.mean()) < 0.2 * error.mean()
    assert 0.6 <= one <= 0.8
    assert 0.9 <= two <= 1.0


def test_the_mean_field_onset_error_covers_the_truth():
    fits = [fit_swift_hohenberg(BELOW, *noisy(swift_hohenberg(BELOW), 0.03, seed))
            for seed in range(SWEEPS)]
    deviation, error, one, two = coverage([f.gamma_mf for f in fits],
                                          [f.gamma_mf_error for f in fits], MEAN_FIELD)
    # The interval is skewed (the divergence bounds it from below), so the median is the
    # estimator's centre.
    assert abs(np.median(deviation)) < 0.2 * error.mean()
    assert 0.6 <= one <= 0.85
    assert 0.88 <= two <= 1.0


def test_only_points_below_the_given_onset_enter_the_swift_hohenberg_fit():
    order = np.concatenate([swift_hohenberg(BELOW), [1.0, 1.0]])  # two saturated points
    gamma = np.concatenate([BELOW, [2.8, 2.9]])
    fit = fit_swift_hohenberg(gamma, order, 0.03 * order, onset_at_most=2.65)
    assert fit.points == BELOW.size
    assert fit.gamma_mf == pytest.approx(MEAN_FIELD, abs=2e-4)


def test_a_sweep_that_misses_the_onset_is_refused():
    flat = np.full(GAMMA.size, 0.02)
    rising = supercritical(GAMMA + 2.0)  # onset below the sweep
    for order in (flat, rising):
        with pytest.raises(NoOnset, match="does not bracket"):
            fit_onset(GAMMA, order, 0.03 * order)
    with pytest.raises(NoOnset, match="do not grow"):
        fit_swift_hohenberg(BELOW, np.full(BELOW.size, 0.02), np.full(BELOW.size, 1e-3))


@pytest.mark.parametrize("order, error, message", [
    ([0.1, 0.2], [0.01], "1D arrays of one length"),
    ([0.1, np.nan, 0.1, 0.1, 0.1], [0.01] * 5, "finite"),
    ([0.1] * 5, [0.01, 0.0, 0.01, 0.01, 0.01], "> 0"),
    ([0.1] * 3, [0.01] * 3, "at least 5"),
])
def test_bad_input_is_refused_with_what_is_wrong(order, error, message):
    with pytest.raises(ValueError, match=message):
        fit_onset(GAMMA[:len(order)], order, error)
