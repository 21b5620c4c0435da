"""ctest validation.verdicts: the verdict of a claim from its value and standard error
(granular_shaker.validation.quantities: margin and verdict) on cases of known answer: a value
well inside its band passes, one well outside fails, one within 2 standard errors of the band's
edge is unresolved (for a band the value must lie outside, its distance beyond the
nearer edge); a value without an error is judged on its value alone; an ordering is judged on
its smallest step over that step's error; a per-phase list on the phases where it exists, if
they are at least half."""
import math

import pytest

from granular_shaker.validation import quantities

NAN = math.nan
CASES = [
    # comparison, band, value, error, expected verdict
    ("range", [0.10, 0.14], 0.12, 0.005, "pass"),
    ("range", [0.10, 0.14], 0.09, 0.03, "unresolved"),
    ("range", [0.10, 0.14], 0.125, 0.01, "unresolved"),
    ("range", [0.10, 0.14], -0.03, 0.0058, "fail"),
    ("range", [0.10, 0.14], 0.12, None, "pass"),
    ("range", [0.10, 0.14], 0.15, None, "fail"),
    ("range", [0.10, 0.14], NAN, 0.01, "fail"),
    ("less_than", [0.01], 0.0099, 0.12, "unresolved"),
    ("less_than", [1.0], 33.1, 2.0, "fail"),
    ("less_than", [0.03], 0.0262, 0.0024, "unresolved"),
    ("less_than", [0.03], 0.0351, 0.0014, "fail"),
    ("greater_than", [10.0], 30.3, 1.1, "pass"),
    ("greater_than", [1.0], 0.53, 0.025, "fail"),
    ("outside", [0.8, 1.25], 2.3, 0.03, "pass"),
    ("outside", [0.8, 1.25], 0.75, 0.03, "unresolved"),
    ("outside", [0.8, 1.25], 1.0, 0.03, "fail"),
    ("outside", [0.8, 1.25], 1.3, None, "pass"),
    ("outside", [0.8, 1.25], NAN, 0.03, "fail"),
    ("strictly_increasing", [], [1.0, 2.0, 3.0], [0.1, 0.1, 0.1], "pass"),
    ("strictly_increasing", [], [3.49, 4.0, 5.2], [0.21, 0.29, 0.31], "unresolved"),
    ("strictly_increasing", [], [2.0, 1.0], [0.1, 0.1], "fail"),
    ("strictly_increasing", [], [1.0, 2.0], None, "pass"),
    ("strictly_increasing", [], [2.0, 1.0], None, "fail"),
    ("all_in_range", [0.4, 2.5], [1.0, NAN, 1.5, 2.0], [0.1, None, 0.1, 0.1], "pass"),
    ("all_in_range", [0.4, 2.5], [1.0, NAN, NAN, NAN], [0.1, None, None, None], "fail"),
    ("all_in_range", [0.4, 2.5], [1.0, 2.65, 1.9], [0.1, 0.31, 0.1], "unresolved"),
    ("all_in_range", [0.4, 2.5], [2.8, 2.7], [0.02, 0.02], "fail"),
    ("true", [], 1.0, None, "pass"),
    ("true", [], 0.0, None, "fail"),
]


@pytest.mark.parametrize("comparison, band, value, error, expected", CASES)
def test_verdict(comparison, band, value, error, expected):
    inside = quantities.margin(comparison, band, value, error)
    got = quantities.verdict(inside)
    assert got == expected, (f"{comparison} {band} {value} +- {error}: {inside:.3g} standard "
                             f"errors inside -> {got} (expected {expected})")
