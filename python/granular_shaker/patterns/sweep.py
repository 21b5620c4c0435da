"""The onset-of-patterns sweep: every pattern case at every Gamma and seed, analysed for
patterns, the onset fitted (docs/patterns.md).

    shaker-patterns --shaker build/release/solvers/app/shaker [--study reduced|full]
        [--workdir DIR] [--jobs 2] [--results DIR/patterns.json] [--report reports/patterns.md]
        [--reuse-only] [--repository DIR]

(or `python3 -m granular_shaker.patterns.sweep ...`). The sweep is read from
validation/patterns.toml. Runs are keyed by their effective configuration as the validation
study keys them (granular_shaker.validation.plan.run_key), so an interrupted sweep resumes
where it stopped; each finished run is analysed once by `shaker analyze RUN.h5 --patterns`,
its table kept beside the run file.

A sweep may hold a `continuum` table of its own (cases, gamma, seeds, overrides, timeout):
the continuum's pattern cases, each run from a seeded flat layer and judged by the growth rate
of its fastest pattern mode (granular_shaker.patterns.growth), the onset where that rate
changes sign.

Per MD point (case, Gamma): the saturated order parameter of the column mass (the mean over the
sampled frames at the stored phase with the larger pattern) with its standard error, the
wavelength, the angular moments and the cycle-to-cycle correlation. With several seeds the
point's value is the mean over seeds and its error their standard error (independent runs);
with one seed, the standard error over its frames. Per case: the onset fit
(granular_shaker.patterns.onset.fit_onset) and, below that onset, the Swift-Hohenberg fit.
A continuum part may hold a `grid` table (gamma, cells, timeout, optionally cases: some of the
part's): its growth runs repeated at each cell (the box GRID_DEPTH_CELLS cells deep), whose
rates tell whether the onset found at the case files' cell survives refinement; and a
`saturation` table (gamma, cycles, frames, timeout, optionally cases): runs of `cycles` cycles
whose last `frames` hold the fields, summarised as the MD's are (the saturated order parameter
over those frames), the amplitude the claims compare with MD's; and a `scheme` table (gamma,
limiters, timeout, optionally cases): its growth runs repeated with each slope limiter at the
sweep's cell, whose rates tell whether the growth is the equations' or the scheme's.
Each point also keeps its first seed's view (granular_shaker.patterns.views): the layer seen
from above at the stored phases of one cycle and the spectrum of its column mass along x, which
the report draws.

Exit status 0 when the results are written; 1 if a run or an analysis failed; 2 for bad
arguments.
"""
import argparse
import os
import subprocess
import sys
import time

import numpy as np
from scipy.stats import chi2 as chi2_distribution

from granular_shaker.patterns.growth import (NoGrowthFit, column_mass_modes, fastest_pattern_mode,
                                             grid_scale_gain, growth_bands, lower_edge)
from granular_shaker.patterns.onset import (NoOnset, fit_onset, fit_swift_hohenberg, order_bracket,
                                            ordered, ordered_run, rising_branch)
from granular_shaker.patterns.views import column_mass_frames, phase_spectra, run_view
from granular_shaker.reports.report_common import read_shaker_csv
from granular_shaker.repository import (add_repository_option, fill_missing_paths,
                                        repository_argument)
from granular_shaker.validation.plan import case_file, load_toml
from granular_shaker.validation.run import execute_all, log
from granular_shaker.validation.summary import git, write_json_atomically

SWEEP_FILE = os.path.join("validation", "patterns.toml")
FIELD = "mass"  # the column mass: its noise is the counts' (docs/analysis.md "Patterns")
GRID_DEPTH_CELLS = 4  # the fewest cells across y that the continuum accepts
# Every run writes a checkpoint this often (cycles), so that a sweep stopped mid-run continues
# it (granular_shaker.validation.run.solver_command): the runs below onset take hours.
CHECKPOINT_EVERY = 10
# The continuum's slope limiters a scheme check may try (docs/configuration.md; `none` is for
# smooth solutions only).
LIMITERS = ("minmod", "van_leer", "mc", "first_order")
# A supercritical fit whose chi^2 lies above this quantile of its distribution is rejected: the
# odds that the form holds and the points' errors alone scatter them so far are 1 in 1000.
REJECTED_QUANTILE = 0.999
# The continuum's checks, each run again with one setting changed (the grid: the cell; the
# scheme: the slope limiter), and the key that names that setting in its runs and points.
CHECK_KEYS = {"grid": "cell", "scheme": "limiter"}
# The correlations of a frame with the same phase one cycle earlier (docs/analysis.md,
# "Patterns"), each with the name of its standard error: plain (-1 for a sinusoidal wave that
# inverts) and with the earlier frame shifted by half a wavelength (+1 for a subharmonic
# standing wave of any waveform; the ordered test's).
CORRELATIONS = {"correlation_previous_cycle": "correlation_error",
                "half_wavelength_correlation": "half_wavelength_error"}


def require_keys(part, keys, where):
    """ValueError naming the first of `keys` a table of the sweep lacks."""
    for key in keys:
        if key not in part:
            raise ValueError(f"{where} has no '{key}'")


def check_some_gamma(part, where):
    """ValueError unless a table's gamma is increasing and holds at least one value: one list
    for its cases, or a table of them by case (where one check belongs at a different Gamma
    in each case)."""
    gamma = part["gamma"]
    for case, values in (gamma.items() if isinstance(gamma, dict) else [("", gamma)]):
        if not isinstance(values, list) or not values or sorted(set(values)) != values:
            raise ValueError(f"{where}: gamma{f'.{case}' if case else ''} {values!r}: allowed: "
                             "increasing, at least 1 (one list, or one per case)")


def check_part(repository, part, where):
    """ValueError naming what is wrong with one solver's part of a sweep."""
    require_keys(part, ("cases", "gamma", "seeds", "overrides", "timeout"), where)
    for case in part["cases"]:
        if not os.path.isfile(case_file(repository, case)):
            raise ValueError(f"{where}: no case file for '{case}'")
    if sorted(set(part["gamma"])) != list(part["gamma"]) or len(part["gamma"]) < 5:
        raise ValueError(f"{where}: gamma must be increasing, at least 5")


def check_saturation(part, where):
    """ValueError naming what is wrong with a continuum part's saturation table."""
    require_keys(part, ("gamma", "cycles", "frames", "timeout"), where)
    check_some_gamma(part, where)
    if not (isinstance(part["frames"], int) and isinstance(part["cycles"], int)
            and 2 <= part["frames"] < part["cycles"]):
        raise ValueError(f"{where}: frames {part['frames']!r} and cycles {part['cycles']!r}: "
                         "allowed: whole numbers, 2 <= frames < cycles")


def check_grid(part, where):
    """ValueError naming what is wrong with a continuum part's grid table."""
    require_keys(part, ("gamma", "cells", "timeout"), where)
    cells = part["cells"]
    if len(cells) < 3 or sorted(set(cells), reverse=True) != list(cells) or cells[-1] <= 0:
        raise ValueError(f"{where}: cells {cells!r}: allowed: at least 3, decreasing, > 0")
    check_some_gamma(part, where)


def check_extra(part, sweep, where):
    """ValueError naming what is wrong with one of a sweep's `extra` tables: points of some MD
    cases at accelerations the sweep lacks (below it for the Swift-Hohenberg fit, or near the
    onset): one list of Gamma for its cases, or a table of them by case; optionally overrides
    of its own, which replace the sweep's of the same key."""
    require_keys(part, ("gamma", "timeout"), where)
    if not isinstance(part["gamma"], dict):
        require_keys(part, ("cases",), where)
    check_some_gamma(part, where)
    cases = table_cases(sweep, part)
    unknown = set(cases) - set(sweep["cases"])
    if unknown:
        raise ValueError(f"{where}: cases {sorted(unknown)} are not the sweep's")
    for case in cases:
        if set(gammas(part, case)) & set(sweep["gamma"]):
            raise ValueError(f"{where}: gamma {gammas(part, case)!r}: allowed: none of the "
                             "sweep's own")
    for override in part.get("overrides", []):
        if not isinstance(override, str) or "=" not in override:
            raise ValueError(f"{where}: overrides: {override!r}: allowed: 'key=value' strings, "
                             "as --set takes them")


def extra_tables(sweep):
    """The sweep's `extra` tables: none, one ([study.x.extra]) or several ([[study.x.extra]],
    each with its own Gamma and overrides)."""
    extra = sweep.get("extra", [])
    return [extra] if isinstance(extra, dict) else list(extra)


def check_extra_tables(sweep, where):
    """ValueError naming what is wrong with the sweep's `extra` tables, each on its own and
    together: no point (case, Gamma) in two of them."""
    seen = set()
    for number, table in enumerate(extra_tables(sweep)):
        at = where if isinstance(sweep["extra"], dict) else f"{where} (table {number + 1})"
        check_extra(table, sweep, at)
        points = {(case, g) for case in table_cases(sweep, table) for g in gammas(table, case)}
        if points & seen:
            raise ValueError(f"{at}: points {sorted(points & seen)} are in an earlier extra "
                             "table too")
        seen |= points


def merged_overrides(base, more):
    """`base` --set values with those of `more` in place of any of the same key."""
    keys = {o.split("=", 1)[0].strip() for o in more}
    return [o for o in base if o.split("=", 1)[0].strip() not in keys] + list(more)


def check_scheme(part, where):
    """ValueError naming what is wrong with a continuum part's scheme table."""
    require_keys(part, ("gamma", "limiters", "timeout"), where)
    limiters = part["limiters"]
    if not limiters or len(set(limiters)) != len(limiters) or not set(limiters) <= set(LIMITERS):
        raise ValueError(f"{where}: limiters {limiters!r}: allowed: one or more, distinct, of "
                         + ", ".join(LIMITERS))
    check_some_gamma(part, where)


def grid_overrides(cell):
    """The --set values of a grid-check run: the cell, and a box GRID_DEPTH_CELLS cells deep
    (the stripes lie across y, so its depth only needs to hold a few cells)."""
    return [f"continuum.cell_size={cell:g}", f"continuum.box_depth={GRID_DEPTH_CELLS * cell:g}"]


def saturation_overrides(part):
    """The --set values of a saturation run: `cycles` cycles, the fields at the case's phases
    of the last `frames` of them (all saturated, when `cycles` is long enough)."""
    first = part["cycles"] - part["frames"]
    return [f"run.transient_cycles={first}", f"run.sampled_cycles={part['frames']}",
            "continuum.field_cycles=[" + ", ".join(str(c) for c in range(first, part["cycles"]))
            + "]"]


def load_sweep(repository, name):
    """The named sweep of validation/patterns.toml; ValueError names what is wrong."""
    studies = load_toml(os.path.join(repository, SWEEP_FILE))["study"]
    if name not in studies:
        raise ValueError(f"--study {name}: allowed: {', '.join(sorted(studies))} "
                         f"({SWEEP_FILE})")
    sweep = studies[name]
    check_part(repository, sweep, f"{SWEEP_FILE} [study.{name}]")
    if "extra" in sweep:
        check_extra_tables(sweep, f"{SWEEP_FILE} [study.{name}.extra]")
    if "continuum" in sweep:
        check_part(repository, sweep["continuum"], f"{SWEEP_FILE} [study.{name}.continuum]")
        if "saturation" in sweep["continuum"]:
            check_saturation(sweep["continuum"]["saturation"],
                             f"{SWEEP_FILE} [study.{name}.continuum.saturation]")
        if "grid" in sweep["continuum"]:
            check_grid(sweep["continuum"]["grid"], f"{SWEEP_FILE} [study.{name}.continuum.grid]")
        if "scheme" in sweep["continuum"]:
            check_scheme(sweep["continuum"]["scheme"],
                         f"{SWEEP_FILE} [study.{name}.continuum.scheme]")
        for table in ("saturation", "grid", "scheme"):
            given = sweep["continuum"].get(table)
            unknown = set(table_cases(sweep["continuum"], given) if given else []) \
                - set(sweep["continuum"]["cases"])
            if unknown:
                raise ValueError(f"{SWEEP_FILE} [study.{name}.continuum.{table}]: cases "
                                 f"{sorted(unknown)} are not the continuum part's")
    return sweep


def solver_parts(sweep):
    """(solver, part) of the sweep: the MD's keys at its top, the continuum's in its table."""
    parts = [("md", sweep)]
    if "continuum" in sweep:
        parts.append(("continuum", sweep["continuum"]))
    return parts


def table_cases(part, table):
    """The cases a part's extra, saturation, grid or scheme table runs: those its gamma is
    given for, by case; else those it names; else the part's."""
    if isinstance(table["gamma"], dict):
        return list(table["gamma"])
    return table.get("cases", part["cases"])


def within(part, table):
    """The gamma, timeout and cases of a part's extra, saturation, grid or scheme table."""
    return dict(gamma=table["gamma"], timeout=table["timeout"], cases=table_cases(part, table))


def gammas(part, case):
    """A part's (or table's) values of Gamma for one case."""
    return part["gamma"][case] if isinstance(part["gamma"], dict) else part["gamma"]


def plan_points(repository, sweep):
    """One run per solver, case, Gamma and seed, in the run dicts of the validation study (the
    MD's points of the `extra` tables first, with their own overrides); the continuum's
    saturation runs (kind "saturation"), grid-check runs (kind "grid", one per cell, key
    "cell") and scheme-check runs (kind "scheme", one per limiter, key "limiter") after its
    growth runs."""
    parts = [(solver, part, [], "sweep", {}) for solver, part in solver_parts(sweep)]
    # Below onset the dense, cold layer makes these the longest runs: they go first.
    parts[:0] = [("md", dict(sweep, **within(sweep, table),
                             overrides=merged_overrides(sweep["overrides"],
                                                        table.get("overrides", []))),
                  [], "sweep", {}) for table in extra_tables(sweep)]
    continuum = sweep.get("continuum") or {}
    if "saturation" in continuum:
        saturation = continuum["saturation"]
        parts.append(("continuum", dict(continuum, **within(continuum, saturation)),
                      saturation_overrides(saturation), "saturation", {}))
    if "grid" in continuum:
        grid = continuum["grid"]
        parts += [("continuum", dict(continuum, **within(continuum, grid)), grid_overrides(cell),
                   "grid", {CHECK_KEYS["grid"]: cell}) for cell in grid["cells"]]
    if "scheme" in continuum:
        scheme = continuum["scheme"]
        parts += [("continuum", dict(continuum, **within(continuum, scheme)),
                   [f"continuum.limiter={limiter}"], "scheme", {CHECK_KEYS["scheme"]: limiter})
                  for limiter in scheme["limiters"]]
    plan = []
    for solver, part, extra, kind, variant in parts:
        for case in part["cases"]:
            for gamma in gammas(part, case):
                for seed in part["seeds"]:
                    plan.append(dict(case=case, case_file=case_file(repository, case),
                                     solver=solver, kind=kind, **variant, replicas=1,
                                     gamma=gamma, seed=seed,
                                     overrides=[f"shaker.gamma={gamma}", f"run.seed={seed}",
                                                *part["overrides"], *extra],
                                     timeout=part["timeout"], fallback=[],
                                     checkpoint_every=CHECKPOINT_EVERY,
                                     expect_failure=False))
    return plan


def has_every_column(table):
    """Whether a kept pattern table has the columns this sweep reads (one made by an older
    `shaker analyze` is made again)."""
    with open(table) as f:
        header = next((line for line in f if not line.startswith("#")), "")
    return all(f"{FIELD}_{name} " in header for name in CORRELATIONS)


def analyze(shaker, record):
    """The pattern table of a finished run (made once, kept beside the run file); None and a
    reason when there is none."""
    if record["status"] != "ok":
        return None, f"run {record['status']}"
    table = record["path"] + ".patterns.csv"
    if not os.path.exists(table) or not has_every_column(table):
        result = subprocess.run([shaker, "analyze", record["path"], "--patterns",
                                 table + ".partial"], capture_output=True, text=True)
        if result.returncode != 0:
            return None, f"shaker analyze --patterns exited {result.returncode}: " \
                         f"{result.stderr.strip()[-500:]}"
        os.replace(table + ".partial", table)
    return table, None


def frame_summary(columns):
    """The run's saturated pattern: at the stored phase with the larger mean order parameter,
    the means over its frames and their standard errors."""
    phases = np.unique(columns["phase"])
    best = None
    for phase in phases:
        at = columns["phase"] == phase
        order = columns[f"{FIELD}_order_parameter"][at]
        if best is None or order.mean() > best["order"]:
            best = dict(phase=float(phase), frames=int(at.sum()), order=float(order.mean()),
                        order_error=standard_error(order))
            for name in ("wavelength", "a2", "a4", "a6", *CORRELATIONS):
                values = columns[f"{FIELD}_{name}"][at]
                values = values[np.isfinite(values)]
                best[name] = float(values.mean()) if values.size else float("nan")
                if name in CORRELATIONS:
                    best[CORRELATIONS[name]] = standard_error(values)
    return best


def standard_error(values):
    """The standard error of the mean of independent values (nan for fewer than two)."""
    values = np.asarray(values, float)
    return float(values.std(ddof=1) / np.sqrt(values.size)) if values.size > 1 else float("nan")


def seeds_error(runs, name, error):
    """The standard error of the mean over seeds of runs[i][name] (a number, or an array
    element by element), given each run's own error (its frames'): the seeds' spread, but
    never less than their own errors combined. Two seeds give a spread of one degree of
    freedom, as often far too small as not; a seed's frames bound the point's error from
    below, since each seed's mean carries its frames' noise."""
    values = np.array([r[name] for r in runs], float)
    errors = np.array([r.get(error, np.nan) for r in runs], float)
    if len(runs) == 1:
        found = errors[0]
    else:
        own = np.sqrt(np.nansum(np.square(errors), axis=0)) / len(runs)
        found = np.maximum(values.std(axis=0, ddof=1) / np.sqrt(len(runs)), own)
    return float(found) if np.ndim(found) == 0 else found


def point_summary(runs):
    """A point (case, Gamma) from its runs' summaries: the mean over seeds with its error
    (seeds_error), and how many seeds show ordered waves (the wavelength is then theirs); with
    the runs' spectra, the mean power of each mode at each phase they all store."""
    order = np.array([r["order"] for r in runs])
    point = dict(order=float(order.mean()), seeds=len(runs),
                 ordered_seeds=sum(ordered_run(r) for r in runs),
                 order_error=seeds_error(runs, "order", "order_error"))
    for name, error in CORRELATIONS.items():
        point[error] = seeds_error(runs, name, error)
    for name in ("wavelength", "a2", "a4", "a6", *CORRELATIONS):
        point[name] = float(np.mean([r[name] for r in runs]))
    if 0 < point["ordered_seeds"] < len(runs):   # the stripes' wavelength, not the noise's
        point["wavelength"] = float(np.mean([r["wavelength"] for r in runs if ordered_run(r)]))
    if all("spectra" in r for r in runs):
        point.update(spectra_over_seeds([r["spectra"] for r in runs]))
    return point


def spectra_over_seeds(spectra):
    """The box length and, at each phase every run stores, the mean over the runs of each
    mode's power with its error (seeds_error)."""
    phases = set.intersection(*(set(s["power"]) for s in spectra))
    out = dict(box_length=spectra[0]["box_length"], mode_power={}, mode_power_error={})
    for phase in sorted(phases):
        runs = [dict(power=s["power"][phase], error=s["power_error"][phase]) for s in spectra]
        out["mode_power"][phase] = np.mean([r["power"] for r in runs], axis=0).tolist()
        out["mode_power_error"][phase] = np.atleast_1d(
            seeds_error(runs, "power", "error")).tolist()
    return out


def stripes_mode(points):
    """(phase, mode) of the stripes at the first ordered point of the rising branch: the
    box's Fourier mode nearest their wavenumber, at the stored phase where its power is the
    larger; None without an ordered point or spectra."""
    first = next((p for p in rising_branch(points) if ordered(p)), None)
    if first is None or "mode_power" not in first:
        return None
    mode = int(round(first["box_length"] / first["wavelength"]))
    phase = max(first["mode_power"], key=lambda ph: first["mode_power"][ph][mode - 1])
    return phase, mode


def critical_power(points, phase, mode):
    """(gamma, power, error) of one mode at one phase, at the points that have it with an
    error."""
    found = [(p["gamma"], p["mode_power"][phase][mode - 1],
              p["mode_power_error"][phase][mode - 1])
             for p in points if phase in p.get("mode_power", {})]
    return [np.array(column, float) for column in zip(*found)] if found else [np.array([])] * 3


def check_against_bracket(onset, bracket):
    """Raises NoOnset when the fitted onset lies, by more than its error, outside the sweep's
    bracket of ordered points (low, high): it then places the rise of the disordered
    fluctuations (or a jump the supercritical form cannot follow), not the onset of order."""
    if bracket is None:
        return
    low, high = bracket[2:]
    if onset.gamma_c + onset.gamma_c_error < low or onset.gamma_c - onset.gamma_c_error > high:
        raise NoOnset(f"the supercritical fit's onset {onset.gamma_c:.4g} ± "
                      f"{onset.gamma_c_error:.2g} (chi^2 per degree of freedom "
                      f"{onset.chi2_per_dof:.3g}) lies outside the sweep's bracket of ordered "
                      f"points, {low:g} to {high:g}: it is not the onset of order")


def check_goodness(onset):
    """Raises NoOnset when the supercritical form is rejected by its own chi^2 (above the
    chi^2 distribution's REJECTED_QUANTILE for its degrees of freedom): the order parameter
    jumps at onset, and the fit's error, scaled by chi^2 per degree of freedom, only smears
    the jump over the points around it."""
    dof = onset.points - 3
    if dof > 0 and onset.chi2_per_dof > chi2_distribution.ppf(REJECTED_QUANTILE, dof) / dof:
        raise NoOnset(f"the supercritical form does not describe the points (chi^2 per degree "
                      f"of freedom {onset.chi2_per_dof:.3g} for {dof}, above its "
                      f"{REJECTED_QUANTILE} quantile): the order parameter jumps at onset")


def fits(points):
    """The onset and Swift-Hohenberg fits of one case's points (the onset on the rising
    branch), or the reason there are none. The fitted onset stands only within the sweep's
    bracket of ordered points (order_bracket), where there is one, and where its form is not
    rejected by its chi^2 (check_goodness). The Swift-Hohenberg fit takes
    the points below the fitted onset (less its error), or where the onset fit cannot place it,
    those below the bracket's first ordered point."""
    rising = rising_branch(points)
    usable = [p for p in rising if np.isfinite(p["order_error"]) and p["order_error"] > 0]
    if 0 < len(rising) < 5 <= len(points):
        return dict(onset=dict(reason=f"the order parameter peaks at Gamma {rising[-1]['gamma']:g}"
                               f": its rising branch holds {len(rising)} points, fewer than the "
                               "5 an onset fit needs"))
    gamma = np.array([p["gamma"] for p in usable])
    order = np.array([p["order"] for p in usable])
    error = np.array([p["order_error"] for p in usable])
    out = {}
    bracket = order_bracket(dict(points=points))
    try:
        onset = fit_onset(gamma, order, error)
        check_against_bracket(onset, bracket)
        check_goodness(onset)
        out["onset"] = vars(onset)
        below = onset.gamma_c - onset.gamma_c_error
    except (NoOnset, ValueError) as reason:
        out["onset"] = dict(reason=str(reason))
        if bracket is None:
            return out
        below = bracket[3]
    out["swift_hohenberg"] = fit_critical_mode(points, below)
    return out


def fit_critical_mode(points, below):
    """The Swift-Hohenberg fit to the power of the stripes' mode (stripes_mode) at the points
    below `below`, with that mode and phase; or the reason there is none."""
    found = dict(below=float(below))
    critical = stripes_mode(points)
    if critical is None:
        return dict(found, reason="no spectra at the first ordered point, whose stripes name "
                    "the critical mode")
    found.update(phase=critical[0], mode=critical[1])
    gamma, power, error = critical_power(points, *critical)
    usable = np.isfinite(error) & (error > 0)
    try:
        found.update(vars(fit_swift_hohenberg(gamma[usable], power[usable], error[usable],
                                              below)))
    except (NoOnset, ValueError) as reason:
        found["reason"] = str(reason)
    return found


def growth_summary(frames):
    """The growth of a continuum run's fastest pattern mode, from its column mass
    (views.column_mass_frames)."""
    cycles, phases, amplitudes, length = column_mass_modes(frames)
    mode, fit, rates = fastest_pattern_mode(cycles, phases, amplitudes)
    return dict(mode=mode, mode_wavelength=length / mode, rate=fit.rate,
                rate_error=fit.rate_error, fit_cycles=[fit.first_cycle, fit.last_cycle],
                mode_rates={str(m): rate for m, rate in rates.items()},
                grid_scale_gain=grid_scale_gain(frames))


def growth_fits(points, holding=None):
    """The continuum's bands of growth and its onset: the lower edge of the band holding the
    acceleration `holding` (the saturated stripes'), else of the lowest band that has one."""
    rates = ([p["gamma"] for p in points], [p["rate"] for p in points],
             [p["rate_error"] for p in points])
    try:
        bands = growth_bands(*rates)
    except (NoGrowthFit, ValueError) as reason:
        return dict(onset=dict(reason=str(reason)), bands=[])
    try:
        onset = vars(lower_edge(bands, (min(rates[0]), max(rates[0])), holding))
    except NoGrowthFit as reason:
        onset = dict(reason=str(reason))
    return dict(onset=onset, bands=[dict(first_gamma=b.first_gamma, last_gamma=b.last_gamma,
                                         lower=b.lower and vars(b.lower),
                                         upper=b.upper and vars(b.upper)) for b in bands])


def case_points(plan, case, kind="sweep"):
    """A case's points of one kind of run (the sweep's, or the continuum's saturation runs),
    one per Gamma in increasing order, from its runs' summaries."""
    points = []
    mine = [r for r in plan if r["case"] == case and r.get("kind", "sweep") == kind]
    for gamma in sorted({r["gamma"] for r in mine}):
        runs = [r for r in mine if r["gamma"] == gamma and "summary" in r]
        if not runs:
            continue
        point = dict(gamma=gamma, **point_summary([r["summary"] for r in runs]))
        if "growth" in runs[0]:
            point.update(runs[0]["growth"], final_order=runs[0]["summary"]["final_order"])
        if "view" in runs[0]:
            point["view"] = runs[0]["view"]
        points.append(point)
    return points


def check_points(plan, case, kind, key):
    """A case's grid or scheme check (kind "grid", key "cell"; kind "scheme", key "limiter"):
    per value of the key and Gamma, its first seed's growth of the fastest pattern mode."""
    points = {}
    for run in plan:
        if run["case"] == case and run.get("kind") == kind and "growth" in run:
            points.setdefault((run[key], run["gamma"]),
                              {key: run[key], "gamma": run["gamma"], **run["growth"]})
    return list(points.values())


READ_ERRORS = (NoGrowthFit, OSError, KeyError, ValueError)


def read_growth(run, columns):
    """A growth run's final order parameter and growth rate into `run`; its column-mass frames."""
    frames = column_mass_frames(run["record"]["path"])
    run["summary"]["final_order"] = float(columns[f"{FIELD}_order_parameter"][-1])
    run["growth"] = growth_summary(frames)
    return frames


def read_run(shaker, run):
    """The finished run's summary, growth rate (continuum growth runs) and top view into `run`;
    the reason it has none of them, or None. A run without a growth rate keeps no summary."""
    table, reason = analyze(shaker, run["record"])
    if table is None:
        return reason
    columns = read_shaker_csv(table)[0]
    run["summary"] = frame_summary(columns)
    # The continuum's growth runs grow or decay to their end: their last frame is the view.
    growing = run["solver"] == "continuum" and run.get("kind") != "saturation"
    frames = None
    if growing:
        try:
            frames = read_growth(run, columns)
        except READ_ERRORS as error:
            del run["summary"]
            return f"no growth rate: {error}"
    try:
        if frames is None:
            frames = column_mass_frames(run["record"]["path"])
        run["view"] = run_view(frames, "last" if growing else "all")
        if run["solver"] == "md":
            run["summary"]["spectra"] = phase_spectra(frames)
    except READ_ERRORS as error:
        return f"no top view or spectrum: {error}"
    return None


def collect(shaker, plan):
    """Every case's points and fits from the finished runs; the failures met."""
    failures, cases = [], {}
    for run in plan:
        failure = read_run(shaker, run)
        if failure is not None:
            failures.append(f"{run['case']} Gamma {run['gamma']} seed {run['seed']}: {failure}")
    for case in dict.fromkeys(r["case"] for r in plan):
        solver = next(r["solver"] for r in plan if r["case"] == case)
        points = case_points(plan, case)
        saturated = case_points(plan, case, "saturation")
        holding = min((p["gamma"] for p in saturated), default=None)
        found = growth_fits(points, holding) if solver == "continuum" else fits(points)
        cases[case] = dict(solver=solver, points=points, **found)
        if saturated:
            cases[case]["saturation"] = saturated
        for kind, key in CHECK_KEYS.items():
            checked = check_points(plan, case, kind, key)
            if checked:
                cases[case][kind] = checked
    return cases, failures


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shaker", required=True, help="the shaker program")
    parser.add_argument("--study", default="reduced", help="a sweep of validation/patterns.toml")
    parser.add_argument("--workdir", help="runs and results (default: validation/work/patterns)")
    parser.add_argument("--jobs", type=int, default=1, help="runs side by side (>= 1)")
    parser.add_argument("--results", help="the results JSON (default: WORKDIR/patterns.json)")
    parser.add_argument("--report", help="also write the report here (reports/patterns.md)")
    parser.add_argument("--reuse-only", action="store_true", help="judge finished runs only")
    add_repository_option(parser)
    args = parser.parse_args(argv)
    repository = repository_argument(parser, args)
    if args.jobs < 1:
        parser.error(f"--jobs {args.jobs}: allowed: >= 1")
    fill_missing_paths(args, {"workdir": os.path.join(repository, "validation", "work",
                                                      "patterns")})
    args.results = args.results or os.path.join(args.workdir, "patterns.json")
    try:
        sweep = load_sweep(repository, args.study)
    except ValueError as error:
        parser.error(str(error))
    return args, repository, sweep


def main(argv=None):
    args, repository, sweep = parse_arguments(argv)
    os.makedirs(os.path.join(args.workdir, "runs"), exist_ok=True)
    start = time.monotonic()
    plan = execute_all(args.shaker, args.workdir, plan_points(repository, sweep), args.jobs,
                       rerun=False, reuse_only=args.reuse_only)
    cases, failures = collect(args.shaker, plan)
    results = dict(study=args.study, sweep=sweep, commit=git(repository, "rev-parse", "HEAD"),
                   seconds=time.monotonic() - start, cases=cases, failures=failures,
                   runs=[dict(case=r["case"], gamma=r["gamma"], seed=r["seed"],
                              status=r["record"]["status"], seconds=r["record"]["seconds"],
                              reused=r["record"].get("reused", False)) for r in plan])
    write_json_atomically(args.results, results)
    log(f"wrote {args.results}")
    if args.report:
        from granular_shaker.reports import make_pattern_report
        make_pattern_report.write(results, repository, args.report)
        log(f"wrote {args.report}")
    for failure in failures:
        print(f"shaker-patterns: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
