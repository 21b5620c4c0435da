"""The error of a sweep point averaged over seeds (granular_shaker.patterns.sweep.seeds_error)
on synthetic seeds of known mean: the coverage of its error bar with two seeds of ten frames,
as the reduced study runs them, when the seeds differ only by their frames' noise and when a
seed-to-seed scatter adds to it."""
import numpy as np
import pytest
from estimator_coverage import coverage

from granular_shaker.patterns.sweep import seeds_error, standard_error

FRAMES, SEEDS, POINTS = 10, 2, 4000


def synthetic_points(scatter, seed):
    """POINTS points of SEEDS runs each (true mean 0): each run's mean and frame error, its
    frames of unit noise about a seed offset of standard deviation scatter / sqrt(FRAMES)."""
    rng = np.random.default_rng(seed)
    offsets = scatter / np.sqrt(FRAMES) * rng.standard_normal((POINTS, SEEDS, 1))
    frames = offsets + rng.standard_normal((POINTS, SEEDS, FRAMES))
    return [[dict(order=float(f.mean()), order_error=standard_error(f)) for f in point]
            for point in frames]


def measured(points, estimator):
    means = [np.mean([r["order"] for r in runs]) for runs in points]
    return coverage(means, [estimator(runs) for runs in points], 0.0)


def spread_only(runs):
    return standard_error([r["order"] for r in runs])


def with_floor(runs):
    return seeds_error(runs, "order", "order_error")


def test_two_seeds_spread_alone_covers_half_the_time_and_the_frames_floor_restores_it():
    points = synthetic_points(scatter=0.0, seed=1)
    _, _, spread_one, _ = measured(points, spread_only)
    assert spread_one == pytest.approx(0.5, abs=0.03)   # one degree of freedom
    deviation, error, one, two = measured(points, with_floor)
    assert abs(deviation.mean()) < 0.05 * error.mean()
    assert 0.68 <= one <= 0.78
    assert 0.93 <= two <= 0.99


def test_where_seeds_scatter_more_than_their_frames_the_error_tends_to_the_spread():
    # A scatter three times the frames' noise: the floor rarely acts, and two seeds cover
    # little more than half the time. The study's two-seed errors are this optimistic where
    # seeds disagree (near onset): the report names its points of coexisting states.
    points = synthetic_points(scatter=3.0, seed=2)
    _, _, spread_one, _ = measured(points, spread_only)
    _, _, one, two = measured(points, with_floor)
    assert spread_one == pytest.approx(0.5, abs=0.03)
    assert spread_one < one <= 0.6
    assert 0.7 <= two <= 0.8


def test_one_seed_keeps_its_frames_error_and_every_error_is_no_less_than_the_frames():
    runs = [dict(order=0.3, order_error=0.02), dict(order=0.3001, order_error=0.02)]
    assert seeds_error(runs[:1], "order", "order_error") == 0.02
    assert seeds_error(runs, "order", "order_error") == pytest.approx(0.02 / np.sqrt(2))
    apart = [dict(order=0.2, order_error=0.02), dict(order=0.4, order_error=0.02)]
    assert seeds_error(apart, "order", "order_error") == pytest.approx(0.1)


def test_a_spectrum_over_seeds_has_each_modes_error_as_a_number_would():
    runs = [dict(power=[0.3, 0.2], error=[0.02, 0.02]),
            dict(power=[0.3001, 0.4], error=[0.02, 0.02])]
    errors = seeds_error(runs, "power", "error")
    for mode in (0, 1):
        alone = [dict(order=r["power"][mode], order_error=r["error"][mode]) for r in runs]
        assert errors[mode] == pytest.approx(seeds_error(alone, "order", "order_error"))
    assert list(seeds_error(runs[:1], "power", "error")) == [0.02, 0.02]
