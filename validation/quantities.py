"""The named quantities that reference-data/claims.toml refers to, and the comparisons.

Every quantity is computed from what the project's C++ analysis prints (`shaker analyze --csv`,
its average shock speed, `shaker compare --csv`) or, where that has no column for it, from the
run file itself (profiles, time series) or the run's exit status and stderr. No constitutive
formula is re-typed here: the sound speed, the layer, the shock and the agreement metrics all
come from solvers/analysis through the `shaker` program.

A quantity is a function f(query) -> value, where the query gives the runs of the claim's
cases for one solver (or both), the claim's parameters and `shaker compare` results. A value
is a float, a list of floats (NaN marks "not found at that phase") or raises NotMeasured.
"""
import math

import numpy as np


class NotMeasured(Exception):
    """The quantity cannot be computed: a run is missing, failed, or lacks the data."""


class Bound:
    """A value that is only a bound (kind "lower"), or exact (kind None)."""

    def __init__(self, value, kind):
        self.value, self.kind = value, kind


# ---- helpers on one run's analysis table ---------------------------------------------------

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


def _has_shock(table):
    return ~np.isnan(table["shock_location"])


def shock_run(table):
    """Indices of the shock's life in the cycle: the longest run of consecutive stored phases
    with a shock (the first one on a tie). Empty if no phase has one."""
    present = _has_shock(table)
    best, start = (0, 0), None
    for k, flag in enumerate(list(present) + [False]):
        if flag and start is None:
            start = k
        if not flag and start is not None:
            if k - start > best[1] - best[0]:
                best = (start, k)
            start = None
    return np.arange(best[0], best[1])


def formation_phase(table, periodic=False):
    """Phase of the first stored phase of the shock's life. In a periodic run the stored
    phases are one cycle, so a life that starts at f t = 0 may have begun at the end of the
    cycle before: then the formation phase is that phase minus 1 (e.g. -0.02 for 0.98)."""
    run = shock_run(table)
    if not len(run):
        return math.nan
    first = int(run[0])
    present = _has_shock(table)
    if periodic and first == 0:
        k = len(present)
        while k - 1 > run[-1] and present[k - 1]:
            k -= 1
        if k < len(present):
            return float(table["phase"][k]) - 1.0
    return float(table["phase"][first])


def _periodic(view):
    return view.config.get("run", {}).get("protocol") == "periodic"


def exit_phase(table):
    """Phase at which the shock location crosses the layer top (linear interpolation between
    the stored phases); if the shock vanishes inside the layer, the first phase without it."""
    run = shock_run(table)
    if not len(run):
        return math.nan
    phase, loc, top = table["phase"], table["shock_location"], table["layer_top"]
    above = loc - top
    for i, k in enumerate(run):
        if not np.isnan(above[k]) and above[k] >= 0:
            if i == 0:
                return float(phase[k])
            j = run[i - 1]
            w = -above[j] / (above[k] - above[j])
            return float(phase[j] + w * (phase[k] - phase[j]))
    last = run[-1]
    return float(phase[last + 1]) if last + 1 < len(phase) else math.nan


def inside_layer_run(table):
    """The shock's life from formation until it leaves the layer (indices)."""
    run = shock_run(table)
    return [k for k in run
            if not np.isnan(table["layer_top"][k])
            and table["shock_location"][k] < table["layer_top"][k]]


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


# ---- the quantities -----------------------------------------------------------------------

def q_shock_formation_phase(q):
    view = q.run(q.cases[0])
    return formation_phase(view.analysis, periodic=_periodic(view))


def q_shock_exit_phase(q):
    return exit_phase(q.table(q.cases[0]))


def q_width_over_mfp_peak_phase(q):
    t = q.table(q.cases[0])
    life = inside_layer_run(t)
    if not life:
        return math.nan
    ratios = t["width_over_mfp"][life]
    return float(t["phase"][life[int(np.nanargmax(ratios))]])


def q_width_over_mfp_in_window(q):
    t = q.table(q.cases[0])
    idx = _window(t, q.params["from"], q.params["to"])
    if not len(idx):
        raise NotMeasured("no stored phase in the window")
    return [float(v) for v in t["width_over_mfp"][idx]]


def q_shock_width_at(q):
    t = q.table(q.cases[0])
    return float(t["shock_width"][_row_at(t, q.params["phase"])])


def q_max_mach_in_window(q):
    t = q.table(q.cases[0])
    idx = _window(t, q.params["from"], q.params["to"])
    if not len(idx):
        raise NotMeasured("no stored phase in the window")
    return float(np.max(t["max_mach"][idx]))


def q_min_max_mach_in_window(q):
    t = q.table(q.cases[0])
    idx = _window(t, q.params["from"], q.params["to"])
    if not len(idx):
        raise NotMeasured("no stored phase in the window")
    return float(np.min(t["max_mach"][idx]))


def _layer_mean_temperature(view, k):
    t, prof = view.analysis, view.profiles()
    lo, hi = t["layer_bottom"][k], t["layer_top"][k]
    if np.isnan(lo):
        return math.nan
    z, n, T = prof["z"][k], prof["n"][k], prof["T"][k]
    inside = (z >= lo) & (z <= hi) & (n > 0)
    if not inside.any():
        return math.nan
    return float(np.sum(n[inside] * T[inside]) / np.sum(n[inside]))


def q_layer_temperature_fraction_at(q):
    view = q.run(q.cases[0])
    k = _row_at(view.analysis, q.params["phase"])
    means = [_layer_mean_temperature(view, j) for j in range(len(view.analysis["phase"]))]
    peak = np.nanmax(means) if not all(np.isnan(means)) else math.nan
    return float(means[k] / peak) if peak and peak > 0 else math.nan


def q_temperature_slope_above_layer_at(q):
    view = q.run(q.cases[0])
    t = view.analysis
    k = _row_at(t, q.params["phase"])
    top = t["layer_top"][k]
    if np.isnan(top):
        return math.nan
    prof = view.profiles()
    z, n, T = prof["z"][k], prof["n"][k], prof["T"][k]
    sel = (z > top) & (z <= top + q.params["span"]) & (n > 0)
    if sel.sum() < 3:
        return math.nan
    return float(np.polyfit(z[sel], T[sel], 1)[0])


def q_layer_gap_at(q):
    t = q.table(q.cases[0])
    k = _row_at(t, q.params["phase"])
    return float(t["layer_bottom"][k] - t["plate_z"][k])


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
    mean = {c: float(np.mean(q.table(p[c])["center_of_mass"])) for c in ("shallow", "middle",
                                                                           "deep")}
    return mean["shallow"] - max(mean["middle"], mean["deep"])


def q_shock_formation_phase_by_case(q):
    views = [q.run(c) for c in q.params["order"]]
    return [formation_phase(v.analysis, periodic=_periodic(v)) for v in views]


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


def q_particles_per_cycle_above(q):
    view = q.run(q.cases[0])
    bound, source = view.particles_per_cycle_above(q.params["height"])
    view.notes.add(f"particles above z = {q.params['height']:g}: {source}")
    return bound


def q_collapse_detected(q):
    """1 if the MD run stopped with an error naming inelastic collapse, else 0 (a run that
    finishes, hangs until its time limit, or fails for another reason detected nothing)."""
    view = q.run(q.cases[0], q.solver)
    if view.status == "collapse":
        return 1.0
    if view.status in ("unavailable", "not run"):
        raise NotMeasured(f"the run is {view.status}")
    view.notes.add({"ok": "the run finished without reporting collapse",
                    "hang": "the run did not finish within its time limit (a hang, not a "
                            "detection)"}.get(view.status, f"the run failed without naming "
                                                           f"collapse: {view.stderr_tail}"))
    return 0.0


def q_com_apex_difference(q):
    hi = np.max(q.table(q.params["high"])["center_of_mass"])
    lo = np.max(q.table(q.params["low"])["center_of_mass"])
    return float(hi - lo)


def _shock_curvature(table):
    life = shock_run(table)
    if len(life) < 4:
        return math.nan
    return float(2.0 * np.polyfit(table["time"][life], table["shock_location"][life], 2)[0])


def q_shock_curvature_difference(q):
    return (_shock_curvature(q.table(q.params["high"]))
            - _shock_curvature(q.table(q.params["low"])))


QUANTITIES = {
    "shock_formation_phase": q_shock_formation_phase,
    "shock_exit_phase": q_shock_exit_phase,
    "width_over_mfp_peak_phase": q_width_over_mfp_peak_phase,
    "width_over_mfp_in_window": q_width_over_mfp_in_window,
    "shock_width_at": q_shock_width_at,
    "max_mach_in_window": q_max_mach_in_window,
    "min_max_mach_in_window": q_min_max_mach_in_window,
    "layer_temperature_fraction_at": q_layer_temperature_fraction_at,
    "temperature_slope_above_layer_at": q_temperature_slope_above_layer_at,
    "layer_gap_at": q_layer_gap_at,
    "com_fractional_rms_md_vs_continuum": q_com_fractional_rms_md_vs_continuum,
    "com_rms_ratio_deep_over_shallow": q_com_rms_ratio_deep_over_shallow,
    "com_mean_excess_of_shallow": q_com_mean_excess_of_shallow,
    "shock_formation_phase_by_case": q_shock_formation_phase_by_case,
    "shock_speed_by_case": q_shock_speed_by_case,
    "shock_speed_trend_deviation_at_last": q_shock_speed_trend_deviation_at_last,
    "shock_speed_relative_change": q_shock_speed_relative_change,
    "shock_location_fractional_rms": q_shock_location_fractional_rms,
    "particles_per_cycle_above": q_particles_per_cycle_above,
    "collapse_detected": q_collapse_detected,
    "com_apex_difference": q_com_apex_difference,
    "shock_curvature_difference": q_shock_curvature_difference,
}

# Parameters each quantity needs (checked by validation/check_claims.py).
REQUIRED_PARAMETERS = {
    "width_over_mfp_in_window": ("from", "to"),
    "shock_width_at": ("phase",),
    "max_mach_in_window": ("from", "to"),
    "min_max_mach_in_window": ("from", "to"),
    "layer_temperature_fraction_at": ("phase",),
    "temperature_slope_above_layer_at": ("phase", "span"),
    "layer_gap_at": ("phase",),
    "com_rms_ratio_deep_over_shallow": ("shallow", "middle", "deep"),
    "com_mean_excess_of_shallow": ("shallow", "middle", "deep"),
    "shock_formation_phase_by_case": ("order",),
    "shock_speed_by_case": ("order",),
    "shock_speed_trend_deviation_at_last": ("order",),
    "shock_speed_relative_change": ("run", "reference"),
    "shock_location_fractional_rms": ("run", "reference"),
    "particles_per_cycle_above": ("height",),
    "com_apex_difference": ("high", "low"),
    "shock_curvature_difference": ("high", "low"),
}

# Parameters that name cases (must be among the claim's cases).
CASE_PARAMETERS = ("shallow", "middle", "deep", "order", "run", "reference", "high", "low")

# ---- comparisons --------------------------------------------------------------------------

BAND_LENGTH = {"range": 2, "all_in_range": 2, "less_than": 1, "greater_than": 1,
               "strictly_increasing": 0, "true": 0}


def _finite(x):
    return x is not None and not (isinstance(x, float) and math.isnan(x))


def check(comparison, band, value):
    """True if the value meets the band."""
    if comparison == "range":
        return _finite(value) and band[0] <= value <= band[1]
    if comparison == "all_in_range":
        return bool(value) and all(_finite(v) and band[0] <= v <= band[1] for v in value)
    if comparison == "less_than":
        return _finite(value) and value < band[0]
    if comparison == "greater_than":
        return _finite(value) and value > band[0]
    if comparison == "strictly_increasing":
        return (len(value) >= 2 and all(_finite(v) for v in value)
                and all(b > a for a, b in zip(value, value[1:])))
    if comparison == "true":
        return _finite(value) and value == 1.0
    raise ValueError(f"unknown comparison '{comparison}'")


def describe_band(comparison, band):
    return {
        "range": lambda: f"{band[0]:g} to {band[1]:g}",
        "all_in_range": lambda: f"all in {band[0]:g} to {band[1]:g}",
        "less_than": lambda: f"< {band[0]:g}",
        "greater_than": lambda: f"> {band[0]:g}",
        "strictly_increasing": lambda: "strictly increasing",
        "true": lambda: "detected",
    }[comparison]()
