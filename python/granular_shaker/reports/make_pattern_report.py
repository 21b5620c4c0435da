"""reports/patterns.md from the onset-of-patterns sweep's results (granular_shaker.patterns.sweep):
the order parameter against Gamma with the onset fits, the points' wavelengths and symmetry,
and a verdict for every claim of reference-data/pattern-claims.toml, "not measured" with its
reason where the sweep does not give the claim's quantity.

    shaker-pattern-report --results validation/work/patterns/patterns.json [--output FILE]
        [--repository DIR]

The results go beside the report too (reports/patterns/results.json), so that a report can be
drawn again from the repository alone.
"""
import argparse
import json
import os
import sys
import tomllib
from typing import NamedTuple

import numpy as np

from granular_shaker.patterns.growth import GRID_SCALE_CELLS, SIGNIFICANT_GROWTH
from granular_shaker.patterns.onset import (STRIPES_A2, SUBHARMONIC_CORRELATION, coexisting,
                                            order_bracket, ordered, rising_branch)
from granular_shaker.patterns.sweep import (CHECK_KEYS, CORRELATIONS, critical_power,
                                            extra_tables, gammas, table_cases)
from granular_shaker.reports import report_common as rc
from granular_shaker.repository import add_repository_option, repository_argument
from granular_shaker.validation import quantities
from granular_shaker.validation.claims import worst_status
from granular_shaker.validation.summary import write_json_atomically

CLAIMS = os.path.join("reference-data", "pattern-claims.toml")
FIGURES = "patterns"  # beside the report
# The sweep's results, kept with the figures: the report can be drawn again, and checked,
# without the hours of runs behind it.
RESULTS = "results.json"


def solver_cases(cases, solver):
    """The cases of one solver (results before the continuum joined the sweep name none)."""
    return {name: case for name, case in cases.items() if case.get("solver", "md") == solver}


def onset_curve(fit, gamma):
    return np.sqrt(fit["floor"] + fit["slope"] * np.maximum(gamma - fit["gamma_c"], 0.0))


def swift_hohenberg_curve(fit, gamma):
    return fit["floor"] + fit["strength"] * fit["gamma_mf"] / (fit["gamma_mf"] - gamma)


def figure_order_parameter(cases):
    """The saturated order parameter against Gamma, each MD case with its onset fit."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for name, case in solver_cases(cases, "md").items():
        points = case["points"]
        gamma = np.array([p["gamma"] for p in points])
        drawn = ax.errorbar(gamma, [p["order"] for p in points],
                            yerr=[p["order_error"] for p in points],
                            label=f"MD {name} (± standard error)", **rc.MD_STYLE)
        if "gamma_c" in case.get("onset", {}):
            fine = np.linspace(gamma.min(), gamma.max(), 200)
            ax.plot(fine, onset_curve(case["onset"], fine), color=drawn[0].get_color(), lw=1,
                    label=f"{name}: onset fit, Gamma_c = {case['onset']['gamma_c']:.3f}")
        elif bracket := order_bracket(case):
            low, high = bracket[2:]
            ax.axvspan(low, high, color=drawn[0].get_color(), alpha=0.15,
                       label=f"{name}: onset of order between Gamma {low:g} and {high:g}")
    ax.set_xlabel("plate acceleration Gamma [g]")
    ax.set_ylabel("order parameter of the column mass [1/sigma^2]")
    rc.legend_above(fig, columns=1)
    return fig


def critical_cases(cases):
    """The MD cases whose Swift-Hohenberg fit names a critical mode."""
    return {name: case for name, case in solver_cases(cases, "md").items()
            if "mode" in case.get("swift_hohenberg", {})}


def figure_critical_mode(cases):
    """The power of each MD case's critical mode (its stripes' Fourier mode at their phase)
    against Gamma, with the Swift-Hohenberg fit over the points below onset."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for name, case in critical_cases(cases).items():
        fit = case["swift_hohenberg"]
        gamma, power, error = critical_power(case["points"], fit["phase"], fit["mode"])
        drawn = ax.errorbar(gamma, power, yerr=error, label=f"MD {name}: mode {fit['mode']} at "
                            f"phase {fit['phase']} (± standard error)", **rc.MD_STYLE)
        if "gamma_mf" in fit:
            below = gamma[gamma < fit["below"]]   # the points fitted
            fine = np.linspace(below.min(), below.max(), 200)
            ax.plot(fine, swift_hohenberg_curve(fit, fine), color=drawn[0].get_color(), lw=1,
                    ls="--", label=f"{name}: Swift-Hohenberg fit below onset, Gamma_mf = "
                    f"{fit['gamma_mf']:.3f}")
    ax.set_yscale("log")
    ax.set_xlabel("plate acceleration Gamma [g]")
    ax.set_ylabel("power of the critical mode, |c_m|^2 / |c_0|^2 [1]")
    rc.legend_above(fig, columns=1)
    return fig


def figure_growth_rate(cases):
    """The continuum's growth rate of its fastest pattern mode against Gamma, one panel per
    case (their rates differ by a decade), with its bands of growth (from their edges, or
    their outermost points where a band reaches the sweep's end) and the onset."""
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(cases), 1, sharex=True, squeeze=False,
                             figsize=(6.4, 1.2 + 2.2 * len(cases)))
    for ax, (name, case) in zip(axes[:, 0], cases.items()):
        points = case["points"]
        drawn = ax.errorbar([p["gamma"] for p in points], [p["rate"] for p in points],
                            yerr=[p["rate_error"] for p in points],
                            label="continuum: fastest pattern mode (± standard error)",
                            **{**rc.CONTINUUM_STYLE, "marker": "s", "ms": 3})
        colour = drawn[0].get_color()
        onset = case.get("onset", {})
        ax.set_title(name + (f": Gamma_c = {onset['gamma_c']:.3f}" if "gamma_c" in onset
                             else ": no onset"), fontsize=9)
        if "gamma_c" in onset:
            ax.axvline(onset["gamma_c"], color=colour, lw=1, ls="--", label="onset Gamma_c")
        for band in case.get("bands", []):
            edges = [band[side]["gamma_c"] if band[side] else point
                     for side, point in (("lower", band["first_gamma"]),
                                         ("upper", band["last_gamma"]))]
            ax.axvspan(*edges, color=colour, alpha=0.1, lw=0, label="bands of growth")
        ax.axhline(0.0, color="0.5", lw=0.8, label="no growth")
        ax.set_ylabel("growth rate [1/cycle]")
    axes[-1, 0].set_xlabel("plate acceleration Gamma [g]")
    rc.legend_above(fig, columns=1)
    return fig


# A layer H diameters deep as poured holds 9.8425 / 9 particles per sigma^2 per diameter of
# depth (the base case: 3937 particles on 20 x 20 for H = 9, docs/models.md).
PARTICLES_PER_AREA_AND_DEPTH = 9.8425 / 9.0
NOT_RUN = ("the continuum's sweep is not part of this study (a point of its full design costs "
           "hours on 2 cores: docs/patterns.md, Cost)")
NO_SATURATION = ("the continuum has no saturation run above its onset in this study (its growth "
                 "runs end in the linear stage of the pattern's growth; a continuum part's "
                 "`saturation` table runs them to saturation)")


def case_parameters(repository, name):
    """The drive frequency f [sqrt(g/sigma)] and the layer depth H [sigma] of a pattern case."""
    with open(os.path.join(repository, "validation", "cases", f"{name}.toml"), "rb") as f:
        case = tomllib.load(f)
    md = case["md"]
    area = md["box_width"] * (md.get("box_depth") or md["box_width"])
    depth = case["layer"]["particles"] / area / PARTICLES_PER_AREA_AND_DEPTH
    return case["shaker"]["frequency"], depth


def experiment_wavelength(dispersion, frequency, depth):
    """The experiments' stripe wavelength [sigma] at f [sqrt(g/sigma)] and H [sigma]."""
    scaled = frequency * np.sqrt(depth)
    return depth * (dispersion["offset"] + dispersion["amplitude"]
                    * scaled ** -dispersion["exponent"])


def ordered_gammas(case):
    return [p["gamma"] for p in case["points"] if ordered(p)]


def stripe_wavelength(case):
    """Mean wavelength of a case's ordered points and its standard error over them (None when
    fewer than two points are ordered)."""
    lengths = np.array([p["wavelength"] for p in case["points"] if ordered(p)])
    if lengths.size < 2:
        return None
    return float(lengths.mean()), float(lengths.std(ddof=1) / np.sqrt(lengths.size))


def onset_of(case, key="onset", parameter="gamma_c"):
    fit = (case or {}).get(key, {})
    return (fit[parameter], fit[parameter + "_error"]) if parameter in fit else None


def md_onset(case):
    """The MD's onset of order: the onset fit's, else the sweep's bracket of ordered points."""
    fitted = onset_of(case)
    if fitted is not None:
        return fitted
    bracket = order_bracket(case) if case else None
    return bracket[:2] if bracket else None


def stripes_above_onset_only(case):
    """MD part of P1: ordered stripes at the Gamma above the onset on the rising branch of the
    order parameter, none below it."""
    onset = (md_onset(case) or (None,))[0]
    shown = ordered_gammas(case)
    if onset is None or not shown:
        return None
    below = [g for g in shown if g < onset]
    above = [p["gamma"] for p in rising_branch(case["points"]) if p["gamma"] > onset]
    return not below and bool(above) and all(g in shown for g in above)


def judge(value, claim, error=None):
    """A value's verdict against the claim's band. With its standard error, as the validation
    report judges (validation.quantities): pass or fail only beyond DECISION_ERRORS errors of
    the band's edge, unresolved within them; without one, by the value alone."""
    if error is None:
        return "pass" if quantities.check(claim["comparison"], claim["band"], value) else "fail"
    return quantities.verdict(quantities.margin(claim["comparison"], claim["band"], value,
                                                error))


def no_onset_of_order(case):
    """Why an MD case without an onset of order has none."""
    if not ordered_gammas(case):
        return " (no ordered point)"
    if all(ordered(p) for p in case["points"]):
        return " (no onset of order in the sweep: ordered at every Gamma)"
    return " (no onset of order: ordered and disordered points alternate)"


def md_part(claim, md, parameters, dispersion):
    """(value, MD verdict) of a claim on both solvers, from the MD cases alone, or None."""
    if claim["id"] == "P1":
        # A case whose ordered points do not all lie above its disordered ones has no onset
        # of order, and so does not show stripes above one: it fails the part.
        found = {name: stripes_above_onset_only(case) for name, case in md.items()}
        if all(f is None for f in found.values()):
            return None
        return ("; ".join(f"{n}: ordered at Gamma " + (", ".join(
            f"{g:g}" for g in ordered_gammas(md[n])) or "none") + (
                "" if found[n] is not None else no_onset_of_order(md[n])) for n in md),
                "pass" if all(f is True for f in found.values()) else "fail")
    wavelengths = {name: stripe_wavelength(case) for name, case in md.items()}
    if claim["id"] == "P3" and len(md) == 2 and None not in wavelengths.values():
        low, high = sorted(md, key=lambda n: parameters[n][0])
        (a, da), (b, db) = wavelengths[low], wavelengths[high]
        ratio = a / b
        error = ratio * np.hypot(da / a, db / b)
        return f"{rc.fmt(ratio)} ± {rc.fmt(error, 2)}", judge(ratio, claim, error)
    if claim["id"] == "P4" and dispersion is not None:
        values, verdicts = [], []
        for name in claim["cases"]:
            if name in md and wavelengths[name] is not None:
                expected = experiment_wavelength(dispersion, *parameters[name])
                (length, error), ratio = wavelengths[name], wavelengths[name][0] / expected
                values.append(f"{name}: {rc.fmt(ratio)} ± {rc.fmt(error / expected, 2)} "
                              f"({rc.fmt(length)} against {rc.fmt(expected)} sigma)")
                verdicts.append(judge(ratio, claim, error / expected))
        if values:
            return "; ".join(values), worst_status(verdicts)
    return None


def ratio_with_error(a, b):
    (x, dx), (y, dy) = a, b
    return x / y, x / y * np.hypot(dx / x, dy / y)


def band_top(case):
    """The upper edge of the continuum's band of growth that starts at its onset (infinity when
    the band reaches the sweep's end)."""
    onset = onset_of(case)[0]
    band = next(b for b in case["bands"] if b["lower"] and b["lower"]["gamma_c"] == onset)
    return band["upper"]["gamma_c"] if band["upper"] else np.inf


def first_growing_point(case):
    """The continuum's first point above its onset (its fastest mode is the pattern's)."""
    onset = onset_of(case)
    above = [p for p in case["points"] if onset and p["gamma"] > onset[0]]
    return above[0] if above else None


def continuum_part(claim, continuum, parameters, dispersion):
    """(value, verdict) of a claim's continuum part, or None when it does not measure it."""
    measured = {n: c for n, c in continuum.items() if n in claim["cases"] and onset_of(c)}
    if not measured:
        return None
    if claim["id"] == "P1":
        # In a box a few cells deep every mode along x is a stripe: the planform follows from
        # the geometry, so the part judged is growth from the onset to the top of its band
        # and decay below the onset; a point goes against it when its rate has the wrong sign
        # beyond its errors (the test of significance that places the onset).
        contrary = {n: [p["gamma"] for p in c["points"]
                        if abs(p["rate"]) > SIGNIFICANT_GROWTH * p["rate_error"]
                        and (p["rate"] > 0) != (onset_of(c)[0] < p["gamma"] < band_top(c))]
                    for n, c in measured.items()}
        described = [f"{n}: growth from Gamma_c {rc.fmt(onset_of(c)[0])}"
                     + (f" to {rc.fmt(band_top(c))}" if np.isfinite(band_top(c)) else "")
                     + ("; against it at Gamma " + ", ".join(f"{g:g}" for g in contrary[n])
                        if contrary[n] else "") for n, c in measured.items()]
        return "; ".join(described), "fail" if any(contrary.values()) else "pass"
    first = {n: first_growing_point(c) for n, c in measured.items()}
    if claim["id"] == "P3" and len(first) == 2 and None not in first.values():
        low, high = sorted(first, key=lambda n: parameters[n][0])
        ratio = first[low]["mode_wavelength"] / first[high]["mode_wavelength"]
        return f"{rc.fmt(ratio)} (box modes {first[low]['mode']}, {first[high]['mode']})", \
            judge(ratio, claim)
    if claim["id"] == "P4" and dispersion is not None:
        values, verdicts = [], []
        for name, point in first.items():
            if point is None:
                continue
            expected = experiment_wavelength(dispersion, *parameters[name])
            ratio = point["mode_wavelength"] / expected
            values.append(f"{name}: {rc.fmt(ratio)} ({rc.fmt(point['mode_wavelength'])} sigma, "
                          f"box mode {point['mode']}, at Gamma {point['gamma']:g}, against "
                          f"{rc.fmt(expected)})")
            verdicts.append(judge(ratio, claim))
        if values:
            return "; ".join(values), worst_status(verdicts)
    return None


def combined(md, continuum):
    """One verdict of a claim on both solvers from its parts ((value, verdict) or None)."""
    if md is None and continuum is None:
        return None
    parts = [f"{who}: {part[0]}" for who, part in (("MD", md), ("continuum", continuum)) if part]
    if md and continuum:
        verdict = worst_status([md[1], continuum[1]])
    elif md:
        verdict = f"MD {md[1]}; continuum not measured"
    else:
        verdict = f"continuum {continuum[1]}; MD not measured"
    return "; ".join(parts), verdict


def amplitude_ratio(claim, md, continuum):
    """((value, verdict), "") of P5: the MD's saturated order parameter over the continuum's
    at the first Gamma of the continuum's saturation runs above both solvers' onsets; (None,
    reason) when there is none."""
    onset = onset_of(continuum)[0]
    saturated = [p for p in continuum.get("saturation", []) if p["gamma"] > onset]
    if not saturated:
        return None, NO_SATURATION
    onset_md = md_onset(md)
    above_md = {p["gamma"]: p for p in (md or {}).get("points", [])
                if onset_md is not None and p["gamma"] > onset_md[0]}
    pairs = [(above_md[p["gamma"]], p) for p in saturated if p["gamma"] in above_md]
    if not pairs:
        return None, ("no MD point above its onset at the Gamma of the continuum's saturation "
                      "runs (" + ", ".join(f"{p['gamma']:g}" for p in saturated) + ")")
    mine, theirs = pairs[0]
    value, error = ratio_with_error((mine["order"], mine["order_error"]),
                                    (theirs["order"], theirs["order_error"]))
    return (f"{rc.fmt(value)} ± {rc.fmt(error, 2)} (MD {rc.fmt(mine['order'])}, continuum "
            f"{rc.fmt(theirs['order'])} saturated, at Gamma {mine['gamma']:g} [1/sigma^2])",
            judge(value, claim, error)), ""


def continuum_missing(claim, continuum):
    """Why the continuum does not measure a claim's part: cases not run, or no onset."""
    if not continuum:
        return NOT_RUN
    reasons = []
    for name in claim["cases"]:
        if "continuum" not in name:
            continue
        if name not in continuum:
            reasons.append(f"{name}: not run in this study")
        elif onset_of(continuum[name]) is None:
            reasons.append(f"{name}: no continuum onset: "
                           f"{continuum[name]['onset'].get('reason', '')} (docs/patterns.md, "
                           "'The continuum's onset')")
    return "; ".join(reasons) or "the continuum's cases do not give its quantity"


def md_against_continuum(claim, md, continuum):
    """(value, verdict) of a claim comparing the two solvers at one frequency, or a reason."""
    name_md = next((n for n in claim["cases"] if n in md), None)
    name_continuum = next((n for n in claim["cases"] if n in continuum), None)
    if name_continuum is None or onset_of(continuum[name_continuum]) is None:
        return None, continuum_missing(claim, continuum)
    case_md, case_continuum = md.get(name_md), continuum[name_continuum]
    onset_continuum = onset_of(case_continuum)
    if claim["id"] == "P5":
        return amplitude_ratio(claim, case_md, case_continuum)
    if claim["id"] == "P2":
        if md_onset(case_md) is None:
            return None, "the MD's onset is neither fitted nor bracketed by ordered points"
        value, error = ratio_with_error(md_onset(case_md), onset_continuum)
    elif claim["id"] == "P8":
        if onset_of(case_md, "swift_hohenberg", "gamma_mf") is None:
            fit = (case_md or {}).get("swift_hohenberg") or (case_md or {}).get("onset", {})
            return None, ("no Swift-Hohenberg fit of the MD below onset: "
                          + fit.get("reason", "not fitted"))
        value, error = ratio_with_error(onset_of(case_md, "swift_hohenberg", "gamma_mf"),
                                        onset_continuum)
    elif claim["id"] == "P6":
        # Each solver below its own onset: the MD's noise at its highest Gamma below its onset,
        # the continuum's last frame at its Gamma nearest to that below its own onset and
        # outside its bands of growth (where it decays, or stays within its errors of flat).
        onset_md = md_onset(case_md)
        below_md = [p for p in (case_md or {}).get("points", [])
                    if onset_md is not None and p["gamma"] < onset_md[0]]
        below = [p for p in case_continuum["points"] if p["gamma"] < onset_continuum[0]
                 and not any(b["first_gamma"] <= p["gamma"] <= b["last_gamma"]
                             for b in case_continuum.get("bands", []))]
        if not below_md or not below:
            return None, "no point below its onset in one of the solvers' sweeps"
        mine = max(below_md, key=lambda p: p["gamma"])
        point = min(below, key=lambda p: abs(p["gamma"] - mine["gamma"]))
        value = mine["order"] / point["final_order"]
        error = value * mine["order_error"] / mine["order"]
        return (f"{rc.fmt(value)} ± {rc.fmt(error, 2)} (MD {rc.fmt(mine['order'])} at Gamma "
                f"{mine['gamma']:g}, continuum's last frame {rc.fmt(point['final_order'])} at "
                f"Gamma {point['gamma']:g} [1/sigma^2])", judge(value, claim, error)), ""
    else:
        return None, f"claim {claim['id']} is not judged from the sweep"
    return (f"{rc.fmt(value)} ± {rc.fmt(error, 2)}", judge(value, claim, error)), ""


def onset_ratio_lines(cases, parameters):
    """The MD's onset of order and its Swift-Hohenberg fit's mean-field onset, each over the
    continuum's onset of growth at each frequency both solvers ran, with the caveats of the
    continuum's checks: P2 and P8 name f = 0.18, and this table shows whether the ratios they
    judge hold at the other frequency."""
    md, continuum = solver_cases(cases, "md"), solver_cases(cases, "continuum")
    rows = []
    for name_md, case_md in md.items():
        frequency = parameters.get(name_md, (None,))[0]
        name_continuum = next((n for n in continuum if frequency is not None
                               and parameters.get(n, (None,))[0] == frequency), None)
        if name_continuum is None:
            continue
        ordered_md = md_onset(case_md)
        mean_field = onset_of(case_md, "swift_hohenberg", "gamma_mf")
        growing = onset_of(continuum[name_continuum])
        shown = ["n/a" if o is None else f"{rc.fmt(o[0])} ± {rc.fmt(o[1], 2)}"
                 for o in (ordered_md, mean_field, growing,
                           *(None if None in (o, growing) else ratio_with_error(o, growing)
                             for o in (ordered_md, mean_field)))]
        caveat = "; ".join(caveats(continuum[name_continuum])) or "none"
        rows.append(f"| {frequency:g} | " + " | ".join(shown) + f" | {caveat} |")
    if not rows:
        return []
    return ["## Onsets at each frequency", "",
            "The MD's onset of order (fitted, else the bracket of ordered points) and the "
            "mean-field onset of its Swift-Hohenberg fit below it, each over the continuum's "
            "onset of growth at the same drive frequency; P2 and P8 judge f = 0.18.", "",
            "| f [sqrt(g/sigma)] | MD Gamma_c | MD Gamma_mf | continuum Gamma_c | "
            "MD Gamma_c / continuum | MD Gamma_mf / continuum | the continuum's checks |",
            "| --- | --- | --- | --- | --- | --- | --- |", *rows, ""]


def coarse_continuum_note(sweep):
    """The caveat of a continuum run at a coarser cell than its case files' (a study override),
    or "" when it ran as designed."""
    cells = [o.split("=", 1)[1] for o in (sweep.get("continuum") or {}).get("overrides", [])
             if o.startswith("continuum.cell_size=")]
    if not cells:
        return ""
    return (f"the continuum ran at cell {cells[-1]} (this study's override), coarser than its "
            "case files': its growth rates there are not grid-converged (docs/patterns.md, 'The "
            "continuum's onset', compares them with the case files' cell)")


class Check(NamedTuple):
    """How the report names one of the continuum's checks (sweep.CHECK_KEYS) and what it
    finds."""
    heading: str       # its column in the check's table
    title: str         # the line above the table
    reverses: str      # a reversal, and the two runs compared: the sweep's and the check's
    mine: str
    theirs: str        # with {} for the key's value
    consequence: str   # what a reversal means for the verdicts


# The growth runs repeated at finer cells (grid) or with other slope limiters at the sweep's
# cell (scheme).
CHECKS = {
    "grid": Check("cell [sigma]",
                  "Grid check (the same run at each cell, the box 4 cells deep):",
                  "refinement reverses the growth", "at the sweep's cell", "at cell {}",
                  "so its onset there is not the converged continuum's"),
    "scheme": Check("limiter",
                    "Scheme check (the same run with other slope limiters at the sweep's cell):",
                    "another slope limiter reverses the growth", "with the sweep's limiter",
                    "with {}", "so the growth there is the scheme's, not the equations'"),
}


def reversals(case, kind):
    """A check's (Gamma, the sweep's rate, the run's key, its rate) where the check reverses a
    growth rate significant in both runs (the test that places the onset): for the grid, the
    finest cell at each Gamma; for the scheme, every limiter."""
    key = CHECK_KEYS[kind]
    checked = case.get(kind, [])
    if kind == "grid":
        checked = [min((p for p in checked if p["gamma"] == g), key=lambda p: p["cell"])
                   for g in sorted({p["gamma"] for p in checked})]
    sweep_rate = {p["gamma"]: p for p in case["points"]}
    changes = []
    for point in checked:
        mine = sweep_rate.get(point["gamma"])
        if mine is None:
            continue
        significant = [abs(p["rate"]) > SIGNIFICANT_GROWTH * p["rate_error"]
                       for p in (mine, point)]
        if all(significant) and (mine["rate"] > 0) != (point["rate"] > 0):
            changes.append((point["gamma"], mine["rate"], point[key], point["rate"]))
    return changes


def reversal_text(kind, gamma, rate, which, other):
    check = CHECKS[kind]
    value = f"{which:g}" if kind == "grid" else which
    return (f"{check.reverses} at Gamma {gamma:g} ({rc.fmt(rate, 3)} per cycle {check.mine}, "
            f"{rc.fmt(other, 3)} {check.theirs.format(value)})")


def refinement_keeps(case, gamma, rate):
    """The grid check's finest run at Gamma (cell, rate) when it keeps the sign of the sweep's
    growth rate there, significantly; else None."""
    runs = [p for p in case.get("grid", []) if p["gamma"] == gamma]
    if not runs:
        return None
    finest = min(runs, key=lambda p: p["cell"])
    if abs(finest["rate"]) > SIGNIFICANT_GROWTH * finest["rate_error"] \
            and (finest["rate"] > 0) == (rate > 0):
        return finest["cell"], finest["rate"]
    return None


def consequence(case, kind, change):
    """What a check's reversal means. A limiter that reverses growth which refinement keeps
    damps it by its own dissipation at the sweep's cell (that error shrinks with the cell): the
    growth is then the equations'; without that refinement it is the scheme's."""
    kept = refinement_keeps(case, change[0], change[1]) if kind == "scheme" else None
    if kept is None:
        return CHECKS[kind].consequence
    return (f"but refinement keeps it ({rc.fmt(kept[1], 3)} per cycle at cell {kept[0]:g}): "
            "the limiter's own dissipation at the sweep's cell hides growth that is the "
            "equations'")


def caveats(case, weakening_only=False):
    """Each reversal of a continuum case's growth by its grid or scheme check, and what it
    means; with weakening_only, only those that put the growth in doubt (not a limiter's
    reversal that refinement undoes)."""
    return [f"{reversal_text(kind, *change)}, {consequence(case, kind, change)}"
            for kind in CHECKS for change in reversals(case, kind)
            if not (weakening_only and kind == "scheme"
                    and refinement_keeps(case, change[0], change[1]))]


def check_note(cases, names=None):
    """The caveat, on a verdict, of the continuum cases (of `names`, if given) whose growth a
    grid or scheme check puts in doubt, or ""."""
    return "; ".join(f"{name}: {caveat}" for name, case in solver_cases(cases, "continuum").items()
                     if names is None or name in names
                     for caveat in caveats(case, weakening_only=True))


def check_lines(case, kind):
    """A continuum case's grid or scheme check: its table and what it finds."""
    key, check = CHECK_KEYS[kind], CHECKS[kind]
    checked = sorted(case.get(kind, []), key=lambda p: (
        p["gamma"], -p[key] if kind == "grid" else p[key]))
    if not checked:
        return []
    lines = ["", check.title, "", f"| Gamma [g] | {check.heading} | growth rate [1/cycle] | "
             "fastest pattern mode m | cycles fitted | grid-scale gain |",
             "| --- | --- | --- | --- | --- | --- |"]
    lines += [f"| {p['gamma']:g} | {p[key]:{'g' if kind == 'grid' else ''}} | "
              f"{rc.fmt(p['rate'])} ± {rc.fmt(p['rate_error'], 2)} | {p['mode']} | "
              f"{p['fit_cycles'][0]:g} to {p['fit_cycles'][1]:g} | "
              f"{gain_text(p)} |"
              for p in checked]
    found = [f"- {reversal_text(kind, *change)}, {consequence(case, kind, change)}"
             for change in reversals(case, kind)]
    if not found and kind == "grid" and len({p["cell"] for p in checked}) < 2:
        found = ["- no run at a finer cell has finished: the grid check is incomplete"]
    return lines + [""] + (found or [f"- the {kind} check keeps the sign of every growth rate "
                                     "checked"]) + [""]


def claim_verdicts(claims, cases, parameters=None, dispersion=None, continuum_note=""):
    """Every claim with its verdict: measured by the sweep, or not measured and why. A claim on
    both solvers that only one of them measures gets that one's verdict, marked as its alone.
    `continuum_note` is added to the reason of every verdict the continuum takes part in, and
    the caveats of the grid and scheme checks of the claim's continuum cases (check_note)."""
    md = {n: c for n, c in solver_cases(cases, "md").items() if n.startswith("pattern_md")}
    continuum = solver_cases(cases, "continuum")
    parameters = parameters or {}
    rows = []
    for claim in claims:
        value, verdict, reason = "n/a", "not measured", ""
        if claim["id"] == "P7":
            reason = ("the Swift-Hohenberg coefficients (xi0, tau0, q0) that make the fitted "
                      "noise power dimensionless are not measured (they come from the "
                      "continuum's linear growth near its onset at the same frequency, which "
                      "at f = 0.18 no scheme-independent onset gives); and the claim's band is "
                      "relative to a reference the claims file lacks: " + claim.get(
                          "missing", "none named"))
        elif claim["solvers"] == "md_vs_continuum":
            part, reason = md_against_continuum(claim, md, continuum)
            if part is not None:
                value, verdict = part
        elif claim["solvers"] == "both":
            part = combined(md_part(claim, md, parameters, dispersion),
                            continuum_part(claim, continuum, parameters, dispersion))
            if part is None:
                reason = continuum_missing(claim, continuum) + (
                    "; the MD sweep does not measure it either (" + (
                        "no stripes above a fitted onset" if claim["id"] != "P4" or dispersion
                        else "no experimental dispersion relation") + ")")
            else:
                value, verdict = part
                if "not measured" in verdict:
                    reason = continuum_missing(claim, continuum) if "continuum not" in verdict \
                        else "the MD sweep does not measure it"
        elif claim["id"] == "P9":
            strengths = {name: onset_of(case, "swift_hohenberg", "strength")
                         for name, case in md.items()}
            if len(strengths) == 2 and None not in strengths.values():
                low, high = (strengths[n] for n in sorted(
                    strengths, key=lambda n: parameters.get(n, (0.0, 0.0))[0]))
                ratio, error = ratio_with_error(low, high)
                value = (f"{rc.fmt(ratio)} ± {rc.fmt(error, 2)} (strengths "
                         f"{low[0]:.3g} ± {low[1]:.2g} at the lower frequency, {high[0]:.3g} ± "
                         f"{high[1]:.2g} at the higher)")
                verdict = judge(ratio, claim, error)
            else:
                reason = "needs Swift-Hohenberg fits at both frequencies: " + "; ".join(
                    f"{n}: {c.get('swift_hohenberg', c.get('onset', {})).get('reason', 'fitted')}"
                    for n, c in md.items())
        uses_continuum = claim["solvers"] == "md_vs_continuum" and verdict != "not measured" \
            or claim["solvers"] == "both" and "continuum:" in str(value)
        if uses_continuum:
            reason = "; ".join(r for r in (reason, continuum_note,
                                           check_note(cases, claim["cases"])) if r)
        rows.append(dict(id=claim["id"], statement=claim["statement"], value=value,
                         verdict=verdict, reason=reason, status=claim["status"]))
    return rows


def shown_points(case):
    """(below, above) onset points of a case whose views the figures show: in MD the ordered
    point of largest order parameter and the highest disordered point below the first ordered
    one; in the continuum the point of fastest growth and the highest decaying point below
    it. Either may be None."""
    points = [p for p in sorted(case["points"], key=lambda p: p["gamma"]) if "view" in p]
    if case.get("solver") == "continuum":
        growing = [p for p in points if p["rate"] > 0.0]
        above = max(growing, key=lambda p: p["rate"]) if growing else None
        saturated = [p for p in case.get("saturation", []) if "view" in p]
        if saturated:
            above = max(saturated, key=lambda p: p["order"])
        below = [p for p in points
                 if p["rate"] < 0.0 and (above is None or p["gamma"] < above["gamma"])]
    else:
        shown = [p for p in points if ordered(p)]
        above = max(shown, key=lambda p: p["order"]) if shown else None
        below = [p for p in points if not ordered(p)
                 and (not shown or p["gamma"] < shown[0]["gamma"])]
    return (below[-1] if below else None), above


def shown_cases(cases, parameters=None):
    """{solver: (name, case)} of the cases whose views the figures show, among those whose
    points carry views: the first continuum case whose growth no check puts in doubt (else the
    first), and the MD case at that continuum case's drive frequency (else the first)."""
    parameters = parameters or {}
    with_views = {solver: {name: case for name, case in solver_cases(cases, solver).items()
                           if any("view" in p for p in case["points"])}
                  for solver in ("md", "continuum")}
    continuum, md = with_views["continuum"], with_views["md"]
    trusted = [name for name, case in continuum.items() if not caveats(case, True)]
    chosen = (trusted or list(continuum) or [None])[0]
    frequency = parameters.get(chosen, (None,))[0]
    same = [name for name in md if frequency is not None
            and parameters.get(name, (None,))[0] == frequency]
    shown = {"continuum": chosen, "md": (same or list(md) or [None])[0]}
    return {solver: (name, with_views[solver][name]) for solver, name in shown.items()
            if name is not None}


def figure_top_views(cases, parameters=None):
    """The column mass seen from above at the stored phases of one cycle, relative to its
    mean (column mass / mean - 1), at a point above onset of the MD and the continuum case
    shown (shown_cases)."""
    import matplotlib.pyplot as plt
    rows = []
    shown = shown_cases(cases, parameters)
    for solver in ("md", "continuum"):
        name, case = shown.get(solver, (None, None))
        point = shown_points(case)[1] if case else None
        if point is not None:
            rows += [(solver, name, point, phase) for phase in point["view"]["fields"]]
    fig, axes = plt.subplots(len(rows), 1, figsize=(7.0, 0.9 + 1.4 * len(rows)), squeeze=False,
                             sharex=True)
    for ax, (solver, name, point, phase) in zip(axes[:, 0], rows):
        view = point["view"]
        field = np.array(view["fields"][phase], dtype=float)
        limit = float(np.nanmax(np.abs(field))) or 1.0
        image = ax.imshow(field.T, origin="lower", aspect="auto", cmap="RdBu_r", vmin=-limit,
                          vmax=limit, extent=(0.0, view["box"][0], 0.0, view["box"][1]))
        ax.set_title(f"{'MD' if solver == 'md' else 'continuum'} {name}, Gamma "
                     f"{point['gamma']:g}, cycle {view['cycle']:g}, f t = {phase}", fontsize=8)
        ax.set_ylabel("y [sigma]", fontsize=8)
        ax.tick_params(labelsize=7)
        fig.colorbar(image, ax=ax, pad=0.01).set_label("relative [1]", fontsize=7)
    axes[-1, 0].set_xlabel("x [sigma]")
    fig.tight_layout()
    return fig


def md_spectrum(point):
    """(power, error, what they are over) of an MD point's spectrum at its view's phase: the
    mean over its seeds where the point has it, else its first seed's over its frames."""
    view = point["view"]
    phase = f"{view['spectrum_phase']:g}"
    if phase in point.get("mode_power", {}):
        return (np.array(point["mode_power"][phase], dtype=float),
                np.array(point["mode_power_error"][phase], dtype=float),
                f"{point.get('seeds', 1)} seeds of {view['frames']} frames")
    return (np.array(view["power"], dtype=float), np.array(view["power_error"], dtype=float),
            f"{view['frames']} frames")


def figure_spectra(cases, parameters=None):
    """The power of the column mass's Fourier modes along x, below and above onset, of the
    cases shown (shown_cases): the MD's mean over its seeds and sampled frames with standard
    errors, the continuum's last frame."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    shown = shown_cases(cases, parameters)
    for solver in ("md", "continuum"):
        name, case = shown.get(solver, (None, None))
        if case is None:
            continue
        for where, point in zip(("below onset", "above onset"), shown_points(case)):
            if point is None:
                continue
            view = point["view"]
            modes = np.arange(1, len(view["power"]) + 1)
            if solver == "md":
                power, error, over = md_spectrum(point)
                ax.errorbar(modes, power, yerr=error, label=f"MD {name}, Gamma "
                            f"{point['gamma']:g} ({where}; {over}, ± standard error)",
                            **rc.MD_STYLE)
            else:
                ax.plot(modes, np.array(view["power"], dtype=float), marker="s", ms=3,
                        **rc.CONTINUUM_STYLE,
                        label=f"continuum {name}, Gamma {point['gamma']:g} ({where}; cycle "
                              f"{view['cycle']:g})")
    ax.set_yscale("log")
    ax.set_xlabel("mode m along x (wavelength Lx / m) [1]")
    ax.set_ylabel("|c_m|^2 / c_0^2 of the column mass [1]")
    rc.legend_above(fig, columns=1)
    return fig


def figure_wavelength(cases, parameters, dispersion):
    """The stripes' wavelength against the drive frequency: the MD's mean over its ordered
    points, the continuum's fastest mode at its first point above onset, and the experiments'
    dispersion relation at the cases' layer depth."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    md = [(parameters[n][0], stripe_wavelength(c)) for n, c in solver_cases(cases, "md").items()]
    md = [(f, w) for f, w in md if w is not None]
    if md:
        ax.errorbar([f for f, _ in md], [w[0] for _, w in md], yerr=[w[1] for _, w in md],
                    label="MD: mean over ordered points (± standard error)", **rc.MD_STYLE)
    continuum = [(parameters[n][0], first_growing_point(c))
                 for n, c in solver_cases(cases, "continuum").items() if onset_of(c)]
    continuum = sorted((f, p["mode_wavelength"]) for f, p in continuum if p is not None)
    if continuum:
        ax.plot(*zip(*continuum), marker="s", ms=4, **rc.CONTINUUM_STYLE,
                label="continuum: fastest mode at its first point above onset")
    frequencies = [parameters[n][0] for n in cases if n in parameters]
    if dispersion is not None and frequencies:
        depth = parameters[next(iter(cases))][1]
        fine = np.linspace(0.8 * min(frequencies), 1.2 * max(frequencies), 100)
        ax.plot(fine, [experiment_wavelength(dispersion, f, depth) for f in fine], color="0.4",
                lw=1, ls="--", label=f"experiments' dispersion relation at H = {depth:.3g} sigma")
    boxes = [p["view"]["box"][0] for c in cases.values() for p in c["points"] if "view" in p]
    if boxes:
        (left, right), (low, high) = ax.get_xlim(), ax.get_ylim()
        allowed = [boxes[0] / m for m in range(1, 64) if low <= boxes[0] / m <= high]
        # One line of separate segments, so that the legend names it once.
        ax.plot(np.tile([left, right, np.nan], len(allowed)), np.repeat(allowed, 3),
                color="0.6", lw=0.6, ls=":",
                label=f"wavelengths the box allows (Lx / m, Lx = {boxes[0]:g} sigma)")
        ax.set_xlim(left, right)
    ax.set_xlabel("drive frequency f [sqrt(g/sigma)]")
    ax.set_ylabel("wavelength [sigma]")
    rc.legend_above(fig, columns=1)
    return fig


def gain_text(point):
    """A continuum run's grid-scale gain (results made before it was recorded have none)."""
    return rc.fmt(point["grid_scale_gain"], 3) if "grid_scale_gain" in point else "n/a"


def band_text(band):
    """One band of growth in words: its points and its edges (where the rate crosses zero)."""
    def edge(crossing, beyond):
        return (f"{crossing['gamma_c']:.4g} ± {crossing['gamma_c_error']:.2g}" if crossing
                else f"{beyond} the sweep")
    return (f"band of growth, points Gamma {band['first_gamma']:g} to {band['last_gamma']:g}: "
            f"from {edge(band['lower'], 'below')} to {edge(band['upper'], 'beyond')}")


def continuum_case_lines(name, case):
    lines = [f"### {name} (continuum)", "", "| Gamma [g] | growth rate [1/cycle] | fastest pattern "
             "mode m | its wavelength [sigma] | cycles fitted | order parameter, last frame "
             "[1/sigma^2] | grid-scale gain |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for p in case["points"]:
        lines.append(f"| {p['gamma']:g} | {rc.fmt(p['rate'])} ± {rc.fmt(p['rate_error'], 2)} | "
                     f"{p['mode']} | {rc.fmt(p['mode_wavelength'])} | {p['fit_cycles'][0]:g} to "
                     f"{p['fit_cycles'][1]:g} | {rc.fmt(p['final_order'])} | "
                     f"{gain_text(p)} |")
    lines += [""] + [f"- {band_text(b)}" for b in case.get("bands", [])]
    unresolved = [p["gamma"] for p in case["points"] if p.get("grid_scale_gain", 0.0) > 1.0]
    if unresolved:
        lines.append(f"- growth reaches the grid scale (a mode of {GRID_SCALE_CELLS} cells or "
                     "fewer per wavelength grows over the run: grid-scale gain above 1) at Gamma "
                     + ", ".join(f"{g:g}" for g in unresolved) + ": the pattern there is not "
                     "resolved by the cell")
    onset = case.get("onset", {})
    saturated = [p["gamma"] for p in case.get("saturation", [])]
    which = (f"the lower edge of the band holding Gamma {min(saturated):g}, where the stripes "
             "saturate" if saturated else "the lower edge of the lowest band that has one")
    if "gamma_c" in onset:
        lines += [f"- onset ({which}): Gamma_c = {onset['gamma_c']:.4f} ± "
                  f"{onset['gamma_c_error']:.2g} (straight line through {onset['points']} points "
                  f"nearest the change of sign, chi^2 per degree of freedom "
                  f"{onset['chi2_per_dof']:.3g})"]
    else:
        lines += [f"- onset: none: {onset.get('reason', 'not fitted')}"]
    lines += check_lines(case, "grid") + check_lines(case, "scheme")
    for p in case.get("saturation", []):
        lines.append(f"- saturated at Gamma {p['gamma']:g} (over the last frames of a long "
                     f"run): order parameter {rc.fmt(p['order'])} ± "
                     f"{rc.fmt(p['order_error'], 2)} [1/sigma^2], wavelength "
                     f"{rc.fmt(p['wavelength'])} sigma, A2 {rc.fmt(p['a2'], 3)}, "
                     f"{correlations_text(p)}")
    return lines + [""]


def correlations_text(point, named=True):
    """A point's cycle-to-cycle correlations, plain and half-wavelength shifted, with errors."""
    texts = []
    for name, error in CORRELATIONS.items():
        text = rc.fmt(point.get(name, np.nan), 3)
        if np.isfinite(point.get(error, np.nan)):
            text += f" ± {rc.fmt(point[error], 1)}"
        texts.append(text)
    if named:
        return f"cycle-to-cycle correlation {texts[0]}, half-wavelength shifted {texts[1]}"
    return "; ".join(texts)


def case_lines(name, case):
    if case.get("solver") == "continuum":
        return continuum_case_lines(name, case)
    lines = [f"### {name}", "", "| Gamma [g] | order parameter [1/sigma^2] | seeds (ordered) | "
             "wavelength [sigma] | A2 | cycle-to-cycle correlation, plain and half-wavelength "
             "shifted (± standard error) |",
             "| --- | --- | --- | --- | --- | --- |"]
    for p in case["points"]:
        seeds = f"{p['seeds']} ({p['ordered_seeds']})" if "ordered_seeds" in p else p["seeds"]
        lines.append(f"| {p['gamma']:g} | {rc.fmt(p['order'])} ± {rc.fmt(p['order_error'], 2)} "
                     f"| {seeds} | {rc.fmt(p['wavelength'])} | {rc.fmt(p['a2'], 3)} | "
                     f"{correlations_text(p, named=False)} |")
    lines.append("")
    shown = ordered_gammas(case)
    if shown:
        lines.append(f"- ordered standing waves (A2 >= {STRIPES_A2}, half-wavelength shifted "
                     f"correlation >= {SUBHARMONIC_CORRELATION}, in some seed) at Gamma "
                     + ", ".join(f"{g:g}" for g in shown))
        rising = {p["gamma"] for p in rising_branch(case["points"])}
        for near_onset, meaning in (
                (True, "the onset is hysteretic, and the onset of order from a flat start is "
                       "the lowest Gamma where any seed orders"),
                (False, "past the order parameter's peak, where the stripes give way")):
            mixed = [p for p in case["points"]
                     if coexisting(p) and (p["gamma"] in rising) == near_onset]
            if mixed:
                lines.append("- ordered and disordered states coexist (the seeds disagree) at "
                             "Gamma " + ", ".join(f"{p['gamma']:g} ({p['ordered_seeds']} of "
                                                  f"{p['seeds']} ordered)" for p in mixed)
                             + f": {meaning}")
    else:
        lines.append(f"- no ordered standing wave at any Gamma of the sweep (A2 >= {STRIPES_A2} "
                     f"with half-wavelength shifted correlation >= {SUBHARMONIC_CORRELATION} "
                     "nowhere): the "
                     "order parameter is the layer's disordered fluctuation, and an onset fitted "
                     "to it is the rise of that noise, not a pattern's onset")
    for model, key, parameter in (("onset fit", "onset", "gamma_c"),
                                  ("Swift-Hohenberg fit below onset", "swift_hohenberg",
                                   "gamma_mf")):
        fit = case.get(key)
        if fit is None:
            continue
        if parameter in fit:
            strength = (f", noise power strength = {fit['strength']:.3g} ± "
                        f"{fit['strength_error']:.2g} (mode {fit['mode']} at phase "
                        f"{fit['phase']}, its power relative to the mean's)"
                        if key == "swift_hohenberg" else "")
            lines.append(f"- {model}: {parameter} = {fit[parameter]:.4f} ± "
                         f"{fit[parameter + '_error']:.2g}{strength} (chi^2 per degree of "
                         f"freedom {fit['chi2_per_dof']:.3g}, {fit['points']} points)")
        else:
            lines.append(f"- {model}: none: {fit['reason']}")
    bracket = order_bracket(case)
    if "gamma_c" not in case.get("onset", {}) and bracket:
        lines.append(f"- onset of order bracketed by the sweep: Gamma_c = {bracket[0]:.4g} ± "
                     f"{bracket[1]:.2g} (last disordered point {bracket[2]:g}, first ordered "
                     f"{bracket[3]:g}; the error of a uniform distribution over the bracket)")
    return lines + [""]


def extra_points(sweep):
    """The sweep's extra points (its `extra` tables), by case, with any overrides of their own,
    for the report's first lines."""
    text = ""
    for table in extra_tables(sweep):
        own = ", ".join(f"`{o}`" for o in table.get("overrides", []))
        text += "".join(f", {case} also at Gamma "
                        + ", ".join(f"{g:g}" for g in gammas(table, case))
                        + (f" (with {own})" if own else "") for case in table_cases(sweep, table))
    return text


def report_text(results, claims, figures, parameters=None, dispersion=None):
    """The report; `figures` maps order_parameter, growth_rate, top_views, spectra and
    wavelength to their paths (any but the first may be missing)."""
    sweep, runs = results["sweep"], results["runs"]
    continuum = sweep.get("continuum")
    lines = ["# Onset of patterns: " + ("MD and continuum sweeps" if continuum else "MD sweep"),
             "",
             f"Generated by `shaker-patterns --study {results['study']}` at commit "
             f"{results['commit'][:12]} (granular_shaker.patterns.sweep; design and definitions: "
             "docs/patterns.md). Cases "
             + ", ".join(sweep["cases"]) + f"; Gamma {sweep['gamma'][0]:g} to "
             f"{sweep['gamma'][-1]:g} ({len(sweep['gamma'])} points)" + extra_points(sweep)
             + "; seeds "
             + ", ".join(map(str, sweep["seeds"])) + "; overrides "
             + (", ".join(f"`{o}`" for o in sweep["overrides"]) or "none")
             + f". {len(runs)} runs of {sum(r['seconds'] for r in runs):.0f} s in all when they "
             f"were made ({sum(r['reused'] for r in runs)} reused from earlier calls); this call "
             f"took {results['seconds']:.0f} s. Every number below is in "
             f"[{FIGURES}/{RESULTS}]({FIGURES}/{RESULTS}), the sweep's results, from which "
             f"`shaker-pattern-report --results {FIGURES}/{RESULTS}` draws this report again.",
             "",
             "Errors are standard errors over independent seeds, never less than the seeds' "
             "own errors combined (two seeds' spread has one degree of freedom); one seed's "
             "are over its sampled frames, which consecutive cycles make optimistic. The onset "
             "is fitted to the pattern's power, M^2 = floor + slope max(Gamma - Gamma_c, 0); "
             "below it the Swift-Hohenberg form floor + strength Gamma_mf / (Gamma_mf - Gamma) "
             "to the power of the critical mode, the box's Fourier mode at the stripes' "
             "wavenumber at the phase where they show (python/granular_shaker/patterns/"
             "onset.py, whose tests measure the bias and coverage of both fits' errors).", "",
             f"![order parameter]({figures['order_parameter']})", ""]
    if "critical_mode" in figures:
        lines += ["The critical mode below and above the onset of order: below it the "
                  "particles' noise stirs it, and in Swift-Hohenberg theory its power grows as "
                  "1 / (Gamma_mf - Gamma) towards the mean-field onset:", "",
                  f"![critical mode]({figures['critical_mode']})", ""]
    if continuum:
        lines += [f"The continuum: cases {', '.join(continuum['cases'])}; Gamma "
                  f"{continuum['gamma'][0]:g} to {continuum['gamma'][-1]:g} "
                  f"({len(continuum['gamma'])} points); overrides "
                  + (", ".join(f"`{o}`" for o in continuum["overrides"]) or "none")
                  + ". Each run starts from the flat layer with a seeded perturbation; the "
                  "growth rate per cycle of each Fourier mode of its column mass is fitted over "
                  "the modes' linear stage, and the onset is where the fastest pattern mode's "
                  "rate changes sign (python/granular_shaker/patterns/growth.py, whose tests "
                  "measure the bias and coverage of its errors).", "",
                  f"![growth rate]({figures['growth_rate']})", ""]
    if "top_views" in figures:
        lines += ["The layer seen from above at the stored phases of one cycle (its column mass "
                  "relative to the mean; the MD's last sampled cycle, the continuum's last "
                  "cycle), above each solver's onset, and the spectra of the column mass along "
                  "the box below and above it (python/granular_shaker/patterns/views.py); the "
                  "continuum case shown is one whose growth its grid and scheme checks keep, "
                  "where there is one, and the MD case its drive frequency's:", "",
                  f"![top views]({figures['top_views']})", "",
                  f"![spectra]({figures['spectra']})", ""]
    if "wavelength" in figures:
        lines += ["The stripes' wavelength against the drive frequency, with the experiments' "
                  "dispersion relation (reference-data/pattern-claims.toml, "
                  "`[experiment_dispersion]`):", "", f"![wavelength]({figures['wavelength']})",
                  ""]
    for name, case in results["cases"].items():
        lines += case_lines(name, case)
    lines += onset_ratio_lines(results["cases"], parameters or {})
    lines += ["## Claims (reference-data/pattern-claims.toml)", "",
              "| claim | statement | value | verdict | why |", "| --- | --- | --- | --- | --- |"]
    note = coarse_continuum_note(sweep)
    for row in claim_verdicts(claims, results["cases"], parameters, dispersion, note):
        lines.append(f"| {row['id']} ({row['status']}) | {row['statement']} | {row['value']} | "
                     f"{row['verdict']} | {row['reason']} |")
    if results["failures"]:
        lines += ["", "## Runs that failed or are not made yet", ""] + [
            f"- {f}" for f in results["failures"]]
    return "\n".join(lines) + "\n"


def write(results, repository, output):
    with open(os.path.join(repository, CLAIMS), "rb") as f:
        reference = tomllib.load(f)
    dispersion = reference.get("experiment_dispersion")
    parameters = {name: case_parameters(repository, name) for name in results["cases"]}
    directory = os.path.join(os.path.dirname(os.path.abspath(output)), FIGURES)
    cases, continuum = results["cases"], solver_cases(results["cases"], "continuum")
    drawn = {"order_parameter": lambda: figure_order_parameter(cases)}
    if critical_cases(cases):
        drawn["critical_mode"] = lambda: figure_critical_mode(cases)
    if continuum:
        drawn["growth_rate"] = lambda: figure_growth_rate(continuum)
    if any("view" in p for case in cases.values() for p in case["points"]):
        drawn["top_views"] = lambda: figure_top_views(cases, parameters)
        drawn["spectra"] = lambda: figure_spectra(cases, parameters)
    if dispersion is not None:
        drawn["wavelength"] = lambda: figure_wavelength(cases, parameters, dispersion)
    figures = {key: f"{FIGURES}/" + rc.write_figure(draw(), directory, f"{key}.png")
               for key, draw in drawn.items()}
    text = report_text(results, reference["claim"], figures, parameters, dispersion)
    write_json_atomically(os.path.join(directory, RESULTS), results)
    rc.write_text_atomically(output, text)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", required=True, help="patterns.json of the sweep")
    parser.add_argument("--output", help="the report (default: reports/patterns.md)")
    add_repository_option(parser)
    args = parser.parse_args(argv)
    repository = repository_argument(parser, args)
    with open(args.results) as f:
        results = json.load(f)
    write(results, repository, args.output or os.path.join(repository, "reports", "patterns.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
