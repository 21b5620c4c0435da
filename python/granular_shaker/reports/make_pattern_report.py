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


def claim_verdicts(claims, cases):
    """Every claim with its verdict: measured by the sweep, or not measured and why."""
    md = {name: case for name, case in cases.items() if name.startswith("pattern_md")}
    rows = []
    for claim in claims:
        value, verdict, reason = "n/a", "not measured", ""
        if claim["solvers"] in ("both", "md_vs_continuum") or claim["id"] in ("P4", "P7"):
            reason = {"P4": "the experiments' dispersion relation is not yet in reference-data",
                      "P7": "the Swift-Hohenberg coefficients (xi0, tau0, q0) that make the "
                            "fitted noise power dimensionless are not measured"}.get(
                claim["id"], "the continuum's sweep is not run (a point of its 64 x 16 box "
                             "costs hours on 2 cores: docs/patterns.md, Cost)")
            if claim["id"] == "P1":
                reason += "; MD: " + "; ".join(
                    f"{name}: " + (", ".join(f"{p['gamma']:g}" for p in case["points"]
                                             if ordered(p)) or "none")
                    for name, case in md.items()) + " (Gamma of ordered stripes)"
        elif claim["id"] == "P9":
            strengths = {name: case.get("swift_hohenberg", {}).get("strength")
                         for name, case in md.items()}
            if len(strengths) == 2 and None not in strengths.values():
                low, high = (strengths[n] for n in sorted(strengths))  # f0p25 before f0p40
                value = low / high
                verdict = "pass" if value < claim["band"][0] else "fail"
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


def report_text(results, claims, figure):
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
    for row in claim_verdicts(claims, results["cases"]):
        lines.append(f"| {row['id']} ({row['status']}) | {row['statement']} | {row['value']} | "
                     f"{row['verdict']} | {row['reason']} |")
    if results["failures"]:
        lines += ["", "## Runs that failed", ""] + [f"- {f}" for f in results["failures"]]
    return "\n".join(lines) + "\n"


def write(results, repository, output):
    with open(os.path.join(repository, CLAIMS), "rb") as f:
        claims = tomllib.load(f)["claim"]
    figures = os.path.join(os.path.dirname(os.path.abspath(output)), FIGURES)
    name = rc.write_figure(figure_order_parameter(results["cases"]), figures,
                           "order_parameter.png")
    rc.write_text_atomically(output, report_text(results, claims, f"{FIGURES}/{name}"))


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
