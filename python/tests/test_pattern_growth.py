"""The continuum's growth-rate onset (granular_shaker.patterns.growth) on synthetic series and
sweeps of known rate and onset: the bias of the fitted values and the coverage of their errors
over many independent noisy realisations, at the scatter the continuum's series show (a few per
cent in M from cycle to cycle)."""
import numpy as np
import pytest
import synthetic_files as synthetic
from estimator_coverage import coverage

from granular_shaker.patterns import growth
from granular_shaker.patterns.views import column_mass_frames
from granular_shaker.patterns import (NoGrowthFit, column_mass_modes, fastest_pattern_mode,
                                      fit_growth_rate, fit_zero_crossing, growth_bands)

CYCLES = np.arange(40.0)
RATE, START = 0.15, 1e-4
GAMMA = np.round(np.arange(2.4, 3.21, 0.1), 10)
ONSET, DRATE = 2.72, 0.5       # the rate rises by 0.5 per cycle and unit of Gamma
REALISATIONS = 300


def growing(rate, saturation=np.inf):
    """ln M on a line of slope `rate`, saturating at M = saturation as a supercritical
    amplitude does (dA/dt = s A - g A^3)."""
    linear = START * np.exp(rate * CYCLES)
    return linear / np.sqrt(1.0 + (linear / saturation) ** 2)


def scattered(series, relative, seed):
    return series * np.exp(relative * np.random.default_rng(seed).standard_normal(series.size))


def test_a_clean_exponential_gives_its_rate_and_the_linear_stage_ends_before_saturation():
    fit = fit_growth_rate(CYCLES, growing(RATE))
    assert fit.rate == pytest.approx(RATE, rel=1e-9)
    # no plateau in sight: the frames after M first exceeds a fifth of its largest are left out
    assert fit.first_cycle == 5 and fit.last_cycle == 28
    saturating = fit_growth_rate(CYCLES, growing(RATE, saturation=0.01))
    # M passes a fifth of its largest value (0.0096) between cycles 19 and 20: frames to 19
    assert saturating.last_cycle == 19
    assert saturating.rate == pytest.approx(RATE, rel=0.01)
    decaying = fit_growth_rate(CYCLES, growing(-0.2))
    # a decaying series ends before it falls within 25 times its smallest value (cycle 22.9)
    assert decaying.rate == pytest.approx(-0.2, rel=1e-9) and decaying.last_cycle == 22
    floored = fit_growth_rate(CYCLES, growing(-0.5) + 1e-9)
    # on a floor of 1e-9 the fit stops before 2.5e-8 (cycle 16.7), where the floor is 3 % of M
    assert floored.last_cycle == 16
    assert floored.rate == pytest.approx(-0.5, rel=0.01)


def rate_fits(rate, saturation, relative):
    fits = [fit_growth_rate(CYCLES, scattered(growing(rate, saturation), relative, seed))
            for seed in range(REALISATIONS)]
    return coverage([f.rate for f in fits], [f.rate_error for f in fits], rate,
                    f"measured at rate {rate}")


def test_near_onset_the_rate_error_covers_the_truth_as_a_standard_error_should():
    # A slow mode (a factor 3 in 40 cycles) never reaches its plateau: no bend in the window.
    deviation, error, one, two = rate_fits(0.03, 1e-2, 0.05)
    assert abs(deviation.mean()) < 0.2 * error.mean()
    assert 0.6 <= one <= 0.8
    assert 0.9 <= two <= 1.0


def test_a_fast_mode_that_saturates_is_biased_low_by_its_bend_only():
    # The frames up to a fifth of the plateau bend ln M by up to 2 %: the rate comes out low by
    # about 1 % (measured), more than its error at little scatter. The onset uses the rates
    # nearest to zero, which are the slow ones above.
    deviation, error, one, two = rate_fits(RATE, 1e-2, 0.02)
    assert -0.02 * RATE < deviation.mean() < 0.0


def test_the_onset_error_covers_the_truth():
    truth = DRATE * (GAMMA - ONSET)
    fits = []
    for seed in range(REALISATIONS):
        rates = [fit_growth_rate(CYCLES, scattered(growing(r), 0.05, seed * 100 + i))
                 for i, r in enumerate(truth)]
        fits.append(fit_zero_crossing(GAMMA, [f.rate for f in rates],
                                      [f.rate_error for f in rates]))
    deviation, error, one, two = coverage([f.gamma_c for f in fits],
                                          [f.gamma_c_error for f in fits], ONSET)
    assert abs(deviation.mean()) < 0.2 * error.mean()
    assert 0.6 <= one <= 0.8
    assert 0.9 <= two <= 1.0
    assert all(f.points == 4 for f in fits)


def test_the_upper_edge_error_of_a_band_covers_the_truth():
    # A tent: the rate rises through 2.72 at 0.5 per unit Gamma, peaks at 3.42 and falls
    # through 3.86 at 0.8; the upper edge's two points (3.8, 3.9) lie on the falling side.
    gamma = np.round(np.arange(2.4, 4.21, 0.1), 10)
    truth = np.minimum(DRATE * (gamma - ONSET), -0.8 * (gamma - 3.86))
    uppers = []
    for seed in range(REALISATIONS):
        rates = [fit_growth_rate(CYCLES, scattered(growing(r), 0.05, seed * 100 + i))
                 for i, r in enumerate(truth)]
        (band,) = growth_bands(gamma, [f.rate for f in rates], [f.rate_error for f in rates])
        uppers.append(band.upper)
    deviation, error, one, two = coverage([u.gamma_c for u in uppers],
                                          [u.gamma_c_error for u in uppers], 3.86)
    assert abs(deviation.mean()) < 0.2 * error.mean()
    assert 0.6 <= one <= 0.8
    assert 0.9 <= two <= 1.0
    assert all(u.points == 2 for u in uppers)


def test_every_band_of_growth_is_found_and_the_onset_is_the_edge_of_the_one_asked_for():
    # Short modes grow at the bottom of the sweep (a band reaching its lowest Gamma), decay
    # over 2.2 to 3.0, the stripes grow over 3.2 to 3.8, decay at 4.2, grow again at 4.6.
    gamma = np.array([1.8, 2.0, 2.2, 2.6, 2.8, 3.0, 3.2, 3.4, 3.8, 4.2, 4.6])
    rate = np.array([0.04, 0.01, -0.18, -0.06, -0.03, -0.01, 0.03, 0.06, 0.09, -0.08, 0.2])
    error = np.full(gamma.size, 0.005)
    bands = growth_bands(gamma, rate, error)
    assert [(b.first_gamma, b.last_gamma) for b in bands] == [(1.8, 2.0), (3.2, 3.8),
                                                              (4.6, 4.6)]
    assert bands[0].lower is None and bands[2].upper is None
    # the upper edge of the lowest band: the line from (2.0, 0.01) to (2.2, -0.18)
    assert bands[0].upper.gamma_c == pytest.approx(2.0 + 0.2 * 0.01 / 0.19, rel=1e-9)
    # the stripes' lower edge: the line through 2.8, 3.0, 3.2, 3.4
    slope, intercept = np.polyfit(gamma[4:8], rate[4:8], 1)
    assert bands[1].lower.gamma_c == pytest.approx(-intercept / slope, rel=1e-9)
    assert bands[1].lower.points == 4
    # the top band's lower edge takes its neighbours below from the gap since the stripes'
    # band only: (4.2, -0.08) and (4.6, 0.2)
    assert bands[2].lower.points == 2
    assert bands[2].lower.gamma_c == pytest.approx(4.2 + 0.4 * 0.08 / 0.28, rel=1e-9)
    stripes = fit_zero_crossing(gamma, rate, error, holding=3.4)
    assert stripes == bands[1].lower
    assert fit_zero_crossing(gamma, rate, error) == bands[1].lower  # the lowest with an edge
    assert fit_zero_crossing(gamma, rate, error, holding=4.6).gamma_c == bands[2].lower.gamma_c
    with pytest.raises(NoGrowthFit, match="reaches the sweep's lowest Gamma 1.8"):
        fit_zero_crossing(gamma, rate, error, holding=1.8)
    with pytest.raises(NoGrowthFit, match="no band of growth holds Gamma 4.2"):
        fit_zero_crossing(gamma, rate, error, holding=4.2)


def test_a_rate_within_its_errors_of_zero_does_not_place_the_onset():
    # +0.03 +- 0.03 at Gamma 2.6 is no evidence of growth: the onset is where the rates turn
    # positive beyond their errors, between 3.0 and 3.2 (the line through 2.8, 3.0, 3.2, 3.4).
    gamma = [2.2, 2.6, 2.8, 3.0, 3.2, 3.4]
    rate = [-0.18, 0.03, -0.05, -0.01, 0.02, 0.06]
    error = [0.02, 0.03, 0.01, 0.002, 0.003, 0.003]
    crossing = fit_zero_crossing(gamma, rate, error)
    assert crossing.points == 4 and 3.0 < crossing.gamma_c < 3.2
    # Without the test of significance the sign at 2.6 would put the onset below it.
    assert fit_zero_crossing(gamma, rate, error, significance=0.0).gamma_c < 2.6
    with pytest.raises(NoGrowthFit, match="by 2 standard errors"):
        fit_zero_crossing(gamma[:2], rate[:2], error[:2])


def test_a_sweep_without_a_change_of_sign_is_refused():
    with pytest.raises(NoGrowthFit, match="do not change sign"):
        fit_zero_crossing(GAMMA, -np.ones(GAMMA.size), 0.1 * np.ones(GAMMA.size))
    with pytest.raises(NoGrowthFit, match="do not change sign"):
        fit_zero_crossing(GAMMA, np.ones(GAMMA.size), 0.1 * np.ones(GAMMA.size))
    with pytest.raises(NoGrowthFit, match="linear stage"):
        fit_growth_rate(CYCLES[:8], growing(RATE)[:8])
    with pytest.raises(NoGrowthFit, match="no growth rate measured"):
        fit_zero_crossing([], [], [])


@pytest.mark.parametrize("gamma, rate, error, message", [
    ([2.5, 2.6], [-1.0], [0.1, 0.1], "one growth rate"),
    ([2.5, 2.6], [-1.0, np.nan], [0.1, 0.1], "finite"),
    ([2.5, 2.6], [-1.0, 1.0], [0.1, 0.0], "> 0"),
])
def test_bad_input_is_refused_with_what_is_wrong(gamma, rate, error, message):
    with pytest.raises(ValueError, match=message):
        fit_zero_crossing(gamma, rate, error)


def test_the_modes_of_a_fields_file_and_the_fastest_pattern_mode(tmp_path):
    # the phase of the frame closing a cycle may be stored as 0.9999999999: it is phase 0
    frames = [(c, p) for c in range(30) for p in (0.0, 0.5)]
    frames = [(c, 0.9999999999 if p == 0.0 and c % 3 else p) for c, p in frames]
    synthetic.write_pattern_fields(tmp_path / "run.fields.h5", frames)
    cycles, phases, amplitudes, length = column_mass_modes(column_mass_frames(tmp_path / "run.h5"))
    assert length == 128.0
    assert sorted(set(phases)) == [0.0, 0.5]
    assert amplitudes[0, 5] == pytest.approx(0.5e-4, rel=1e-9)  # |c_6| / c_0 of a cosine
    mode, fit, rates = fastest_pattern_mode(cycles, phases, amplitudes)
    assert mode == 6 and fit.rate == pytest.approx(0.1, rel=1e-6)
    assert rates[3] == pytest.approx(-0.3, rel=1e-6)


def test_modes_on_the_solvers_floor_are_not_taken_for_slow_growth():
    # Modes 2 and 3 fall onto a floor of 1e-10 within a few cycles, where they scatter with a
    # rate near zero; mode 4 decays at 0.15 per cycle, the slowest true decay: the fastest.
    rng = np.random.default_rng(7)
    cycles = np.arange(40.0)
    floor = 1e-10 * np.exp(0.5 * rng.standard_normal((40, 3)))
    amplitudes = np.column_stack([
        np.full(40, 1e-5),                                   # mode 1, never a pattern mode
        1e-5 * np.exp(-3.0 * cycles) + floor[:, 0],
        1e-5 * np.exp(-4.0 * cycles) + floor[:, 1],
        1e-5 * np.exp(-0.15 * cycles) + floor[:, 2]])
    phases = np.zeros(40)
    assert growth.solver_floor(amplitudes) == 0.0  # mode 4 keeps the median up: no floor yet
    amplitudes[:, 0] = 1e-5 * np.exp(-0.5 * cycles) + 1e-10
    mode, fit, rates = fastest_pattern_mode(cycles, phases, amplitudes)
    assert growth.solver_floor(amplitudes) > 0.0
    assert mode == 4 and fit.rate == pytest.approx(-0.15, rel=0.02)
    assert set(rates) == {4}  # modes 2 and 3 have no frames 10 times above the floor


def test_a_band_of_growth_gives_the_onset_of_its_rising_side():
    gamma = np.array([2.2, 2.6, 3.0, 3.4, 3.8, 4.2])
    rate = np.array([-0.4, -0.3, -0.2, -0.1, 0.05, -0.2])  # grows near 3.8 only
    crossing = fit_zero_crossing(gamma, rate, np.full(6, 0.01))
    assert crossing.points == 3  # 3.0, 3.4 and 3.8; not 4.2, where it decays again
    # the line through (3.0, -0.2), (3.4, -0.1), (3.8, 0.05) crosses zero near 3.69
    slope, intercept = np.polyfit(gamma[2:5], rate[2:5], 1)
    assert crossing.gamma_c == pytest.approx(-intercept / slope, rel=1e-9)


def test_the_grid_scale_gain_is_the_growth_over_the_run_of_the_shortest_modes():
    # 128 cells: modes 32 to 63 have 4 cells per wavelength or fewer, all seeded by a fixed
    # background of 1e-6. Mode 6 grows six times faster than mode 40, which gains
    # exp(0.05 * 29) over 30 cycles at phase 0.5 (at phase 0 it is smaller and decays).
    cycles = np.repeat(np.arange(30.0), 2)
    phases = np.tile([0.0, 0.5], 30)
    x = (np.arange(128) + 0.5) / 128.0
    background = 1e-6 * np.random.default_rng(3).standard_normal(128)
    fields = []
    for c, p in zip(cycles, phases):
        short = 1e-3 * np.exp(0.05 * c) if p == 0.5 else 1e-4 * np.exp(-0.05 * c)
        column = 1.0 + background + 1e-4 * np.exp(0.3 * c) * np.cos(2 * np.pi * 6 * x) \
            + short * np.cos(2 * np.pi * 40 * x)
        fields.append(np.repeat(column[:, None], 4, axis=1))
    frames = (cycles, phases, np.array(fields), (128.0, 8.0))
    # the background's share of mode 40 (about 1e-7 against 1e-3) sets the tolerance
    assert growth.grid_scale_gain(frames) == pytest.approx(np.exp(0.05 * 29), rel=1e-3)
    with pytest.raises(NoGrowthFit, match="no grid-scale mode"):
        growth.grid_scale_gain((cycles, phases, np.array(fields)[:, :3, :], (3.0, 8.0)))
