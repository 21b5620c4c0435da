"""The named quantities that reference-data/claims.toml refers to, and the comparisons.

Every physical quantity comes from the project's one analysis (solvers/analysis, through
`shaker analyze --json` and `shaker compare --csv`; definitions in docs/analysis.md) or from
the run's exit status and stderr. This module only selects (a phase, a window, a case),
combines values of different runs (differences, ratios, orderings) and compares them with
the claims' bands.

A quantity is a function f(query) -> value, where the query gives the runs of the claim's
cases for one solver (or both), the claim's parameters and `shaker compare` results. A value
is a float, a list of floats (NaN marks "not found at that phase") or raises NotMeasured.
"""
import math

import numpy as np

# The span above the layer's top over which `shaker analyze` fits dT/dz
# (solvers/analysis/run_analysis.hpp, gas_span_above_layer).
GAS_SPAN_ABOVE_LAYER = 10.0


class NotMeasured(Exception):
    """The quantity cannot be computed: a run is missing, failed, or lacks the data."""


class Bound:
    """A value that is only a bound (kind "lower"), or exact (kind None)."""

    def __init__(self, value, kind):
        self.value, self.kind = value, kind


class Quantized:
    """A value (or list) quantised to a grid: `resolution` is the grid step per value, from
    `shaker analyze` (its rounding error, resolution / sqrt(12), is part of the uncertainty)."""

    def __init__(self, value, resolution):
        self.value, self.resolution = value, resolution


class Measured:
    """A value with the standard error `shaker analyze` gives it directly (a count's
    between-cycle error), used where leave-one-out replicates are not available."""

    def __init__(self, value, error):
        self.value, self.error = value, error


# A claim passes when its value lies inside the band by more than this many standard errors,
# fails when it lies outside by more; in between the data cannot decide ("unresolved").
DECISION_ERRORS = 2.0


# ---- selecting from one run's analysis table ------------------------------------------------

def _cyclic_distance(a, b):
    return abs(((a - b + 0.5) % 1.0) - 0.5)


def _row_at(table, phase):
    phases = table["phase"]
    k = int(np.argmin([_cyclic_distance(p, phase) for p in phases]))
    spacing = 1.0 / max(len(phases), 1)
    if _cyclic_distance(phases[k], phase) > 0.51 * spacing:
        raise NotMeasured(f"no stored phase near f t = {phase}")
    return k


def _window(table, lo, hi):
    p = table["phase"]
    return np.nonzero((p >= lo - 1e-9) & (p <= hi + 1e-9))[0]


# ---- the query a quantity sees ----------------------------------------------------------------

class Query:
    """What a quantity may look at: the runs of its claim for one solver (or both), the
    claim's parameters and cases, and `shaker compare`."""

    def __init__(self, get_run, compare, solver, cases, parameters, partial_cases_ok):
        self._get_run, self._compare = get_run, compare
        self.solver, self.cases, self.params = solver, cases, parameters
        self.partial_cases_ok = partial_cases_ok

    def run(self, case, solver=None):
        view = self._get_run(case, solver or self.solver)
        if view is None:
            raise NotMeasured(f"no {solver or self.solver} run of case {case}")
        return view

    def table(self, case, solver=None):
        return self.run(case, solver).analysis

    def compare(self, case_a, case_b, solver_a=None, solver_b=None):
        """`shaker compare` of run A against reference B (metric -> value)."""
        return self._compare(self.run(case_a, solver_a), self.run(case_b, solver_b))


def _window_rows(q):
    """The run of the claim's first case and its stored phases in [from, to]."""
    view = q.run(q.cases[0])
    idx = _window(view.analysis, q.params["from"], q.params["to"])
    if not len(idx):
        raise NotMeasured("no stored phase in the window")
    return view, idx


def _resolutions(view, column, rows):
    resolution = view.resolution.get(column)
    return [None if resolution is None or resolution[k] is None else float(resolution[k])
            for k in rows]


# ---- the quantities -----------------------------------------------------------------------

def _per_run(view, name):
    return Quantized(view.per_run[name], view.per_run_resolution.get(name))


def q_shock_formation_phase(q):
    return _per_run(q.run(q.cases[0]), "formation_phase")


def q_shock_exit_phase(q):
    return q.run(q.cases[0]).per_run["exit_phase"]


def q_width_over_mfp_peak_phase(q):
    return _per_run(q.run(q.cases[0]), "width_over_mfp_peak_phase")


def q_width_over_mfp_in_window(q):
    view, idx = _window_rows(q)
    return Quantized([float(v) for v in view.analysis["width_over_mfp"][idx]],
                     _resolutions(view, "width_over_mfp", idx))


def _at(q, column):
    t = q.table(q.cases[0])
    return float(t[column][_row_at(t, q.params["phase"])])


def q_shock_location_at(q):
    return _at(q, "shock_location")


def q_center_of_mass_at(q):
    return _at(q, "center_of_mass")


def q_front_width_over_mfp_in_window(q):
    view, idx = _window_rows(q)
    return [float(v) for v in view.analysis["front_width_over_mfp"][idx]]


def q_shock_lifetime(q):
    return _per_run(q.run(q.cases[0]), "lifetime")


def q_shock_width_at(q):
    view = q.run(q.cases[0])
    k = _row_at(view.analysis, q.params["phase"])
    return Quantized(float(view.analysis["shock_width"][k]),
                     _resolutions(view, "shock_width", [k])[0])


def q_max_mach_in_window(q):
    view, idx = _window_rows(q)
    return float(np.max(view.analysis["max_mach"][idx]))


def q_min_max_mach_in_window(q):
    view, idx = _window_rows(q)
    return float(np.min(view.analysis["max_mach"][idx]))


def q_layer_temperature_fraction_at(q):
    view = q.run(q.cases[0])
    k = _row_at(view.analysis, q.params["phase"])
    peak = view.per_run["layer_temperature_peak"]
    return float(view.analysis["layer_temperature"][k] / peak) if peak > 0 else math.nan


def q_temperature_slope_above_layer_at(q):
    t = q.table(q.cases[0])
    if q.params["span"] != GAS_SPAN_ABOVE_LAYER:
        raise NotMeasured(f"`shaker analyze` fits the slope over {GAS_SPAN_ABOVE_LAYER:g} "
                          "above the layer's top")
    return float(t["temperature_slope_above_layer"][_row_at(t, q.params["phase"])])


def q_layer_gap_at(q):
    return _at(q, "layer_gap")


def q_mass_gap_at(q):
    return _at(q, "mass_gap")


def q_com_fractional_rms_md_vs_continuum(q):
    values, missing = [], []
    for case in q.cases:
        try:
            m = q.compare(case, case, "continuum", "md")
        except NotMeasured:
            missing.append(case)
            continue
        values.append(m["center_of_mass_fractional_rms"])
    if missing and not (q.partial_cases_ok and values):
        raise NotMeasured("missing runs: " + ", ".join(missing))
    return float(max(values))


def q_com_rms_ratio_deep_over_shallow(q):
    p = q.params
    deep = q.compare(p["deep"], p["middle"])["center_of_mass_absolute_rms"]
    shallow = q.compare(p["shallow"], p["middle"])["center_of_mass_absolute_rms"]
    return float(deep / shallow) if shallow > 0 else math.nan


def q_com_mean_excess_of_shallow(q):
    p = q.params
    mean = {c: q.run(p[c]).per_run["center_of_mass_mean"] for c in ("shallow", "middle", "deep")}
    return mean["shallow"] - max(mean["middle"], mean["deep"])


def q_shock_formation_phase_by_case(q):
    values = [_per_run(q.run(c), "formation_phase") for c in q.params["order"]]
    return Quantized([v.value for v in values], [v.resolution for v in values])


def q_shock_speed_by_case(q):
    return [q.run(c).shock_speed for c in q.params["order"]]


def q_shock_speed_trend_deviation_at_last(q):
    order = q.params["order"]
    e = [q.run(c).switch_e for c in order]
    v = [q.run(c).shock_speed for c in order]
    if any(math.isnan(x) for x in v):
        return math.nan
    coeffs = np.polyfit(e[:-1], v[:-1], 2)
    return float(abs(v[-1] - np.polyval(coeffs, e[-1])) / abs(v[-1]))


def q_shock_speed_relative_change(q):
    v = q.run(q.params["run"]).shock_speed
    ref = q.run(q.params["reference"]).shock_speed
    return float(abs(v - ref) / abs(ref))


def q_shock_location_fractional_rms(q):
    m = q.compare(q.params["run"], q.params["reference"])
    if m["shock_location_phases"] < 1:
        return math.nan
    return float(m["shock_location_fractional_rms"])


def q_crossings_per_cycle_above(q):
    value, error = q.run(q.cases[0]).per_cycle_count(f"crossings_z{q.params['height']:g}")
    return Measured(value, error)


def q_distinct_particles_per_cycle_above(q):
    value, error = q.run(q.cases[0]).per_cycle_count(f"particles_z{q.params['height']:g}")
    return Measured(value, error)


def q_collapse_detected(q):
    """1 if the MD run stopped with an error naming inelastic collapse, else 0 (a run that
    finishes, hangs until its time limit, or fails for another reason detected nothing)."""
    view = q.run(q.cases[0], q.solver)
    if view.status == "collapse":
        return 1.0
    if view.status == "not run":
        raise NotMeasured(f"the run is {view.status}")
    if view.status.startswith("timed out"):
        view.notes.add("the run did not finish within its time limit (a hang, not a detection)")
    else:
        view.notes.add("the run finished without reporting collapse" if view.status == "ok"
                       else f"the run failed without naming collapse: {view.stderr_tail}")
    return 0.0


def q_com_apex_difference(q):
    return (q.run(q.params["high"]).per_run["center_of_mass_apex"]
            - q.run(q.params["low"]).per_run["center_of_mass_apex"])


def q_shock_curvature_difference(q):
    return (q.run(q.params["high"]).per_run["shock_curvature"]
            - q.run(q.params["low"]).per_run["shock_curvature"])


QUANTITIES = {
    "shock_formation_phase": q_shock_formation_phase,
    "shock_exit_phase": q_shock_exit_phase,
    "width_over_mfp_peak_phase": q_width_over_mfp_peak_phase,
    "width_over_mfp_in_window": q_width_over_mfp_in_window,
    "front_width_over_mfp_in_window": q_front_width_over_mfp_in_window,
    "shock_lifetime": q_shock_lifetime,
    "shock_width_at": q_shock_width_at,
    "shock_location_at": q_shock_location_at,
    "center_of_mass_at": q_center_of_mass_at,
    "max_mach_in_window": q_max_mach_in_window,
    "min_max_mach_in_window": q_min_max_mach_in_window,
    "layer_temperature_fraction_at": q_layer_temperature_fraction_at,
    "temperature_slope_above_layer_at": q_temperature_slope_above_layer_at,
    "layer_gap_at": q_layer_gap_at,
    "mass_gap_at": q_mass_gap_at,
    "com_fractional_rms_md_vs_continuum": q_com_fractional_rms_md_vs_continuum,
    "com_rms_ratio_deep_over_shallow": q_com_rms_ratio_deep_over_shallow,
    "com_mean_excess_of_shallow": q_com_mean_excess_of_shallow,
    "shock_formation_phase_by_case": q_shock_formation_phase_by_case,
    "shock_speed_by_case": q_shock_speed_by_case,
    "shock_speed_trend_deviation_at_last": q_shock_speed_trend_deviation_at_last,
    "shock_speed_relative_change": q_shock_speed_relative_change,
    "shock_location_fractional_rms": q_shock_location_fractional_rms,
    "crossings_per_cycle_above": q_crossings_per_cycle_above,
    "distinct_particles_per_cycle_above": q_distinct_particles_per_cycle_above,
    "collapse_detected": q_collapse_detected,
    "com_apex_difference": q_com_apex_difference,
    "shock_curvature_difference": q_shock_curvature_difference,
}

# The units of each quantity's value (docs/units.md; definitions in docs/analysis.md), one entry
# per key of QUANTITIES (harness/validation/test_claims_file.py fails on a missing one). The
# validation report gives them beside the claims' values and bands and the diagnoses' evidence.
# Phases and phase spans are f t (a lifetime is in cycles), so dimensionless; so are d/xi, Mach
# numbers, ratios, relative changes, counts per cycle and the 1/0 of a detection.
UNITS = {
    "shock_formation_phase": "1",
    "shock_exit_phase": "1",
    "width_over_mfp_peak_phase": "1",
    "width_over_mfp_in_window": "1",
    "front_width_over_mfp_in_window": "1",
    "shock_lifetime": "1",
    "shock_width_at": "sigma",
    "shock_location_at": "sigma",
    "center_of_mass_at": "sigma",
    "max_mach_in_window": "1",
    "min_max_mach_in_window": "1",
    "layer_temperature_fraction_at": "1",
    # dT/dz: (g sigma) / sigma
    "temperature_slope_above_layer_at": "g",
    "layer_gap_at": "sigma",
    "mass_gap_at": "sigma",
    "com_fractional_rms_md_vs_continuum": "1",
    "com_rms_ratio_deep_over_shallow": "1",
    "com_mean_excess_of_shallow": "sigma",
    "shock_formation_phase_by_case": "1",
    "shock_speed_by_case": "sqrt(g sigma)",
    "shock_speed_trend_deviation_at_last": "1",
    "shock_speed_relative_change": "1",
    "shock_location_fractional_rms": "1",
    "crossings_per_cycle_above": "1",
    "distinct_particles_per_cycle_above": "1",
    "collapse_detected": "1",
    # The apex is the largest centre of mass over the stored phases: a height.
    "com_apex_difference": "sigma",
    # 2 c of the parabola a + b t + c t^2 through the shock's height: sigma / (sigma/g)
    "shock_curvature_difference": "g",
}

# Parameters each quantity needs (checked by validation/check_claims.py).
REQUIRED_PARAMETERS = {
    "width_over_mfp_in_window": ("from", "to"),
    "front_width_over_mfp_in_window": ("from", "to"),
    "shock_width_at": ("phase",),
    "shock_location_at": ("phase",),
    "center_of_mass_at": ("phase",),
    "max_mach_in_window": ("from", "to"),
    "min_max_mach_in_window": ("from", "to"),
    "layer_temperature_fraction_at": ("phase",),
    "temperature_slope_above_layer_at": ("phase", "span"),
    "layer_gap_at": ("phase",),
    "mass_gap_at": ("phase",),
    "com_rms_ratio_deep_over_shallow": ("shallow", "middle", "deep"),
    "com_mean_excess_of_shallow": ("shallow", "middle", "deep"),
    "shock_formation_phase_by_case": ("order",),
    "shock_speed_by_case": ("order",),
    "shock_speed_trend_deviation_at_last": ("order",),
    "shock_speed_relative_change": ("run", "reference"),
    "shock_location_fractional_rms": ("run", "reference"),
    "crossings_per_cycle_above": ("height",),
    "distinct_particles_per_cycle_above": ("height",),
    "com_apex_difference": ("high", "low"),
    "shock_curvature_difference": ("high", "low"),
}

# Parameters that name cases (must be among the claim's cases).
CASE_PARAMETERS = ("shallow", "middle", "deep", "order", "run", "reference", "high", "low")

# ---- comparisons --------------------------------------------------------------------------

BAND_LENGTH = {"range": 2, "all_in_range": 2, "less_than": 1, "greater_than": 1,
               "strictly_increasing": 0, "true": 0}


def finite(x):
    return x is not None and not (isinstance(x, float) and math.isnan(x))


def _measured(values, errors=None):
    """The (value, error) pairs of a per-phase list where the value exists, if they are at
    least half of the list (a phase without a shock has no width: not measured there, but a
    list measured at under half its phases says nothing); else []."""
    errors = errors or [None] * len(values)
    pairs = [(v, e) for v, e in zip(values, errors) if finite(v)]
    return pairs if 2 * len(pairs) >= len(values) else []


def check(comparison, band, value):
    """True if the value meets the band."""
    if comparison == "range":
        return finite(value) and band[0] <= value <= band[1]
    if comparison == "all_in_range":
        measured = _measured(value)
        return bool(measured) and all(band[0] <= v <= band[1] for v, _ in measured)
    if comparison == "less_than":
        return finite(value) and value < band[0]
    if comparison == "greater_than":
        return finite(value) and value > band[0]
    if comparison == "outside":
        return finite(value) and not band[0] <= value <= band[1]
    if comparison == "strictly_increasing":
        return (len(value) >= 2 and all(finite(v) for v in value)
                and all(b > a for a, b in zip(value, value[1:])))
    if comparison == "true":
        return finite(value) and value == 1.0
    raise ValueError(f"unknown comparison '{comparison}'")


def margin(comparison, band, value, error):
    """How many standard errors the value lies inside its band (negative: outside): +inf or
    -inf for a value without an error, -inf for a missing one. For orderings, the smallest
    step over its error (errors of neighbours combined as independent); for lists in a
    range, the worst measured entry. `true` comparisons have no error: +-inf."""
    def sigmas(distance, e):
        if finite(e) and e > 0:
            return distance / e
        return math.inf if distance > 0 else -math.inf

    def in_range(v, e):
        return sigmas(min(v - band[0], band[1] - v), e)

    if comparison == "all_in_range":
        errors = error if isinstance(error, list) else [None] * len(value)
        measured = _measured(value, errors)
        return min((in_range(v, e) for v, e in measured), default=-math.inf)
    if not (finite(value) if not isinstance(value, list) else all(finite(v) for v in value)):
        return -math.inf
    if comparison == "range":
        return in_range(value, error)
    if comparison == "less_than":
        return sigmas(band[0] - value, error)
    if comparison == "greater_than":
        return sigmas(value - band[0], error)
    if comparison == "outside":
        return sigmas(max(band[0] - value, value - band[1]), error)
    if comparison == "strictly_increasing":
        errors = error if isinstance(error, list) else [None] * len(value)
        if len(value) < 2:
            return -math.inf
        return min(sigmas(b - a, math.hypot(ea, eb) if finite(ea) and finite(eb) else None)
                   for a, b, ea, eb in zip(value, value[1:], errors, errors[1:]))
    return math.inf if check(comparison, band, value) else -math.inf


def verdict(inside):
    """pass, fail or unresolved for a value `inside` standard errors inside its band."""
    if inside > DECISION_ERRORS:
        return "pass"
    return "fail" if inside < -DECISION_ERRORS else "unresolved"
