"""reports/patterns.md from the onset-of-patterns sweep's results (granular_shaker.patterns.sweep):
the order parameter against Gamma with the onset fits, the points' wavelengths and symmetry,
and a verdict for every claim of reference-data/pattern-claims.toml, "not measured" with its
reason where the sweep does not give the claim's quantity.

    shaker-pattern-report --results validation/work/patterns/patterns.json [--output FILE]
        [--repository DIR]
"""
import argparse
import json
import os
import sys
import tomllib

import numpy as np

from granular_shaker.reports import report_common as rc
from granular_shaker.repository import add_repository_option, repository_argument

CLAIMS = os.path.join("reference-data", "pattern-claims.toml")
# A point shows an ordered standing wave when its spectrum's angular moments name stripes (A2,
# docs/analysis.md "Patterns": the symmetry threshold) and its pattern inverts from one cycle to
# the next (the subharmonic response).
STRIPES_A2 = 0.5
SUBHARMONIC_CORRELATION = -0.5


def ordered(point):
    return (point["a2"] >= STRIPES_A2
            and point["correlation_previous_cycle"] <= SUBHARMONIC_CORRELATION)


FIGURES = "patterns"  # beside the report


def onset_curve(fit, gamma):
    return np.sqrt(fit["floor"] + fit["slope"] * np.maximum(gamma - fit["gamma_c"], 0.0))


def figure_order_parameter(cases):
    """The saturated order parameter against Gamma, each case with its onset fit."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for name, case in cases.items():
        points = case["points"]
        gamma = np.array([p["gamma"] for p in points])
        drawn = ax.errorbar(gamma, [p["order"] for p in points],
                            yerr=[p["order_error"] for p in points],
                            label=f"MD {name} (± standard error)", **rc.MD_STYLE)
        if "gamma_c" in case.get("onset", {}):
            fine = np.linspace(gamma.min(), gamma.max(), 200)
            ax.plot(fine, onset_curve(case["onset"], fine), color=drawn[0].get_color(), lw=1,
                    label=f"{name}: onset fit, Gamma_c = {case['onset']['gamma_c']:.3f}")
    ax.set_xlabel("plate acceleration Gamma [g]")
    ax.set_ylabel("order parameter of the column mass [1/sigma^2]")
    rc.legend_above(fig, columns=1)
    return fig


# A layer H diameters deep as poured holds 9.8425 / 9 particles per sigma^2 per diameter of
# depth (the base case: 3937 particles on 20 x 20 for H = 9, docs/models.md).
PARTICLES_PER_AREA_AND_DEPTH = 9.8425 / 9.0
NOT_RUN = ("the continuum's sweep is not run (a point of its 128 x 8 box costs hours on 2 "
           "cores: docs/patterns.md, Cost)")


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


def stripes_above_onset_only(case):
    """MD part of P1: ordered stripes at the Gamma above the fitted onset, none below it."""
    onset = case.get("onset", {}).get("gamma_c")
    shown = ordered_gammas(case)
    if onset is None or not shown:
        return None
    below = [g for g in shown if g < onset]
    above = [p["gamma"] for p in case["points"] if p["gamma"] > onset]
    return not below and bool(above) and all(g in shown for g in above)


def judge(value, claim):
    lo_hi = claim["band"]
    if claim["comparison"] == "range":
        return "pass" if lo_hi[0] <= value <= lo_hi[1] else "fail"
    if claim["comparison"] == "greater_than":
        return "pass" if value > lo_hi[0] else "fail"
    if claim["comparison"] == "less_than":
        return "pass" if value < lo_hi[0] else "fail"
    raise ValueError(f"claim {claim['id']}: comparison {claim['comparison']} not judged here")


def md_part(claim, md, parameters, dispersion):
    """(value, MD verdict) of a claim on both solvers, from the MD cases alone, or None."""
    if claim["id"] == "P1":
        found = {name: stripes_above_onset_only(case) for name, case in md.items()}
        if None in found.values():
            return None
        return ("; ".join(f"{n}: ordered at Gamma " + ", ".join(
            f"{g:g}" for g in ordered_gammas(md[n])) for n in md),
                "pass" if all(found.values()) else "fail")
    wavelengths = {name: stripe_wavelength(case) for name, case in md.items()}
    if claim["id"] == "P3" and len(md) == 2 and None not in wavelengths.values():
        low, high = sorted(md, key=lambda n: parameters[n][0])
        (a, da), (b, db) = wavelengths[low], wavelengths[high]
        ratio = a / b
        error = ratio * np.hypot(da / a, db / b)
        return f"{rc.fmt(ratio)} ± {rc.fmt(error, 2)}", judge(ratio, claim)
    if claim["id"] == "P4" and dispersion is not None:
        values, verdicts = [], []
        for name in claim["cases"]:
            if name in md and wavelengths[name] is not None:
                expected = experiment_wavelength(dispersion, *parameters[name])
                (length, error), ratio = wavelengths[name], wavelengths[name][0] / expected
                values.append(f"{name}: {rc.fmt(ratio)} ± {rc.fmt(error / expected, 2)} "
                              f"({rc.fmt(length)} against {rc.fmt(expected)} sigma)")
                verdicts.append(judge(ratio, claim))
        if values:
            return "; ".join(values), "pass" if all(v == "pass" for v in verdicts) else "fail"
    return None


def claim_verdicts(claims, cases, parameters=None, dispersion=None):
    """Every claim with its verdict: measured by the sweep, or not measured and why. A claim on
    both solvers that the MD cases measure gets the MD's verdict, marked as the MD's alone."""
    md = {name: case for name, case in cases.items() if name.startswith("pattern_md")}
    parameters = parameters or {}
    rows = []
    for claim in claims:
        value, verdict, reason = "n/a", "not measured", ""
        if claim["id"] == "P7":
            reason = ("the Swift-Hohenberg coefficients (xi0, tau0, q0) that make the fitted "
                      "noise power dimensionless are not measured")
        elif claim["solvers"] == "md_vs_continuum":
            reason = NOT_RUN
        elif claim["solvers"] == "both":
            part = md_part(claim, md, parameters, dispersion)
            if part is None:
                reason = NOT_RUN + "; the MD sweep does not measure it either (" + (
                    "no stripes above a fitted onset" if claim["id"] != "P4" or dispersion
                    else "no experimental dispersion relation") + ")"
            else:
                value, verdict = "MD: " + part[0], f"MD {part[1]}; continuum not measured"
                reason = NOT_RUN
        elif claim["id"] == "P9":
            strengths = {name: case.get("swift_hohenberg", {}).get("strength")
                         for name, case in md.items()}
            if len(strengths) == 2 and None not in strengths.values():
                low, high = (strengths[n] for n in sorted(
                    strengths, key=lambda n: parameters.get(n, (0.0, 0.0))[0]))
                value = low / high
                verdict = judge(value, claim)
            else:
                reason = "needs Swift-Hohenberg fits at both frequencies: " + "; ".join(
                    f"{n}: {c.get('swift_hohenberg', c.get('onset', {})).get('reason', 'fitted')}"
                    for n, c in md.items())
        rows.append(dict(id=claim["id"], statement=claim["statement"], value=value,
                         verdict=verdict, reason=reason, status=claim["status"]))
    return rows


def case_lines(name, case):
    lines = [f"### {name}", "", "| Gamma [g] | order parameter [1/sigma^2] | seeds | "
             "wavelength [sigma] | A2 | cycle-to-cycle correlation |", "| --- | --- | --- | --- "
             "| --- | --- |"]
    for p in case["points"]:
        lines.append(f"| {p['gamma']:g} | {rc.fmt(p['order'])} ± {rc.fmt(p['order_error'], 2)} "
                     f"| {p['seeds']} | {rc.fmt(p['wavelength'])} | {rc.fmt(p['a2'], 3)} | "
                     f"{rc.fmt(p['correlation_previous_cycle'], 3)} |")
    lines.append("")
    shown = [p["gamma"] for p in case["points"] if ordered(p)]
    if shown:
        lines.append(f"- ordered standing waves (A2 >= {STRIPES_A2}, cycle-to-cycle correlation "
                     f"<= {SUBHARMONIC_CORRELATION}) at Gamma "
                     + ", ".join(f"{g:g}" for g in shown))
    else:
        lines.append(f"- no ordered standing wave at any Gamma of the sweep (A2 >= {STRIPES_A2} "
                     f"with cycle-to-cycle correlation <= {SUBHARMONIC_CORRELATION} nowhere): the "
                     "order parameter is the layer's disordered fluctuation, and an onset fitted "
                     "to it is the rise of that noise, not a pattern's onset")
    for model, key, parameter in (("onset fit", "onset", "gamma_c"),
                                  ("Swift-Hohenberg fit below onset", "swift_hohenberg",
                                   "gamma_mf")):
        fit = case.get(key)
        if fit is None:
            continue
        if parameter in fit:
            lines.append(f"- {model}: {parameter} = {fit[parameter]:.4f} ± "
                         f"{fit[parameter + '_error']:.2g} (chi^2 per degree of freedom "
                         f"{fit['chi2_per_dof']:.3g}, {fit['points']} points)")
        else:
            lines.append(f"- {model}: none: {fit['reason']}")
    return lines + [""]


def report_text(results, claims, figure, parameters=None, dispersion=None):
    sweep, runs = results["sweep"], results["runs"]
    lines = ["# Onset of patterns: MD sweep", "",
             f"Generated by `shaker-patterns --study {results['study']}` at commit "
             f"{results['commit'][:12]} (granular_shaker.patterns.sweep; design and definitions: "
             "docs/patterns.md). Cases "
             + ", ".join(sweep["cases"]) + f"; Gamma {sweep['gamma'][0]:g} to "
             f"{sweep['gamma'][-1]:g} ({len(sweep['gamma'])} points); seeds "
             + ", ".join(map(str, sweep["seeds"])) + "; overrides "
             + (", ".join(f"`{o}`" for o in sweep["overrides"]) or "none")
             + f". {len(runs)} runs of {sum(r['seconds'] for r in runs):.0f} s in all when they "
             f"were made ({sum(r['reused'] for r in runs)} reused from earlier calls); this call "
             f"took {results['seconds']:.0f} s.", "",
             "Errors are standard errors over independent seeds (one seed: over its sampled "
             "frames, which consecutive cycles make optimistic). The onset is fitted to the "
             "pattern's power, M^2 = floor + slope max(Gamma - Gamma_c, 0); below it the "
             "Swift-Hohenberg form floor + strength / sqrt((Gamma_mf - Gamma)/Gamma_mf) "
             "(python/granular_shaker/patterns/onset.py, whose tests measure the bias and "
             "coverage of both fits' errors).", "", f"![order parameter]({figure})", ""]
    for name, case in results["cases"].items():
        lines += case_lines(name, case)
    lines += ["## Claims (reference-data/pattern-claims.toml)", "",
              "| claim | statement | value | verdict | why |", "| --- | --- | --- | --- | --- |"]
    for row in claim_verdicts(claims, results["cases"], parameters, dispersion):
        lines.append(f"| {row['id']} ({row['status']}) | {row['statement']} | {row['value']} | "
                     f"{row['verdict']} | {row['reason']} |")
    if results["failures"]:
        lines += ["", "## Runs that failed", ""] + [f"- {f}" for f in results["failures"]]
    return "\n".join(lines) + "\n"


def write(results, repository, output):
    with open(os.path.join(repository, CLAIMS), "rb") as f:
        reference = tomllib.load(f)
    parameters = {name: case_parameters(repository, name) for name in results["cases"]}
    figures = os.path.join(os.path.dirname(os.path.abspath(output)), FIGURES)
    name = rc.write_figure(figure_order_parameter(results["cases"]), figures,
                           "order_parameter.png")
    text = report_text(results, reference["claim"], f"{FIGURES}/{name}", parameters,
                       reference.get("experiment_dispersion"))
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
