"""Writes reports/continuum-sensitivity.md (markdown + PNG) from the sensitivity study's
(shaker-sensitivity, granular_shaker.validation.sensitivity) results JSON.

    shaker-sensitivity-report --results WORKDIR/sensitivity.json
        --output reports/continuum-sensitivity.md

(or `python3 -m granular_shaker.reports.make_sensitivity_report ...`).

One row per variant of validation/sensitivity.toml, grouped by the choice it varies: the
verdict and value of every claim the study evaluates (with MD's jackknife errors in the
verdict), the 1 % mass bottom above the plate at the study's phases, the single-shock speed at
e = 0.99 and the cost per cycle; figures of the same numbers against MD's; and the decision
the numbers support: the variants, if any, that bring C1, C10 and C15 into their bands.
"""
import argparse
import json
import math
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from granular_shaker.reports import report_common as rc  # noqa: E402

# What each claim's value is, with its units (reference-data/claims.toml).
CLAIM_LABELS = {
    "C1": ("shock formation f t", "1"),
    "C4": ("shock exit f t", "1"),
    "C8": ("layer T / peak T at f t = 0", "1"),
    "C10": ("largest centre-of-mass fractional RMS, H = 4.5, 9, 13.5", "1"),
    "C15": ("shock-location fractional RMS, ceiling 80 against 200", "1"),
}
DECISIVE = ("C1", "C10", "C15")


def number(x):
    return x if isinstance(x, (int, float)) and x is not None and math.isfinite(x) else None


def value_text(value, error=None, digits=3):
    if isinstance(value, list):
        return ", ".join(rc.fmt(v, digits) for v in value)
    text = rc.fmt(value, digits)
    if number(error) is not None and number(value) is not None:
        text += f" ± {rc.fmt(error, 2)}"
    return text


def claim_cell(claim):
    if claim is None:
        return "–"
    if claim.get("value") is None:
        return "not measured"
    mark = {"pass": "pass", "fail": "**FAIL**", "unresolved": "unresolved"}.get(
        claim["status"], claim["status"])
    return f"{mark} {value_text(claim['value'], claim.get('error'))}"


def gap_cell(pair):
    if not pair or pair[0] is None:
        return "–"
    return value_text(pair[0], pair[1])


def md_section(results):
    md = results["md"]
    phases = results["study"]["mass_gap_phases"]
    lines = ["## MD, the reference", "",
             "Every variant is judged against these MD numbers (jackknife errors over the sampled "
             "cycles, or over the replicas of the single-shock ensemble).", ""]
    lines += rc.table_head(["quantity", "MD", "units"])
    for name, key in (("shock formation f t", "formation_phase"), ("shock exit f t", "exit_phase")):
        pair = md.get(key) or (None, None)
        lines.append(rc.table_row([name, value_text(*pair), "1"]))
    for p in phases:
        lines.append(rc.table_row([f"1 % mass bottom above the plate at f t = {p:g}",
                                   gap_cell(md["mass_gap"].get(f"{p:g}")), "sigma"]))
    speed = md.get("single_shock_speed") or (None, None)
    lines.append(rc.table_row(["single-shock speed, e = 0.99", value_text(*speed),
                               "sqrt(g sigma)"]))
    return lines + [""]


def variants_table(results):
    study = results["study"]
    phases = study["mass_gap_phases"]
    head = ["choice", "variant"] + [f"{c}: {CLAIM_LABELS.get(c, (c, ''))[0]} [1]"
                                    for c in study["claims"]]
    head += [f"mass bottom at f t = {p:g} [sigma]" for p in phases]
    head += ["single-shock speed e = 0.99 [sqrt(g sigma)]", "base case cost [s per cycle]"]
    lines = rc.table_head(head)
    for v in results["variants"]:
        cells = [v["choice"], v["name"]]
        cells += [claim_cell(v["claims"].get(c)) for c in study["claims"]]
        cells += [gap_cell(v["mass_gap"].get(f"{p:g}")) for p in phases]
        cells.append(rc.fmt(v.get("single_shock_speed"), 3))
        cells.append(rc.fmt(v["seconds_per_cycle"].get("base"), 3))
        lines.append(rc.table_row(cells))
    notes = [f"- `{v['name']}`: `{' '.join(v['overrides']) or '(none)'}`"
             + (f". {v['note']}" if v.get("note") else "")
             + (". Not run or not finished (so their claims are not measured): "
                + ", ".join(f"{c} ({status})" for c, status in v["failed"].items())
                if v.get("failed") else "")
             + (f". Judged at commit {v['archived_at'][:10]} (from the study's archive)"
                if v.get("archived_at") else "")
             for v in results["variants"]]
    return ["## Every variant", "",
            "Verdicts as the validation report gives them: pass or **FAIL** by more than two "
            "standard errors (MD's), unresolved in between; `–`: not part of this variant.", ""] \
        + lines + ["", "The overrides of each variant (appended to every case file):", ""] \
        + notes + [""]


def decision_section(results):
    passing = [v["name"] for v in results["variants"]
               if all((v["claims"].get(c) or {}).get("status") == "pass" for c in DECISIVE)]
    lines = ["## Decision", ""]
    if passing:
        lines.append("These variants bring C1, C10 and C15 into their bands together: "
                     + ", ".join(f"`{p}`" for p in passing) + ".")
    else:
        lines.append("No variant brings C1, C10 and C15 into their bands together.")
    lines.append("")
    lines += rc.table_head(["claim", "variants that pass it", "closest variant", "its value [1]",
                            "band [1]"])
    for c in DECISIVE:
        rows = [(v["name"], v["claims"].get(c)) for v in results["variants"] if v["claims"].get(c)]
        passed = [n for n, r in rows if r["status"] == "pass"]
        measured = [(n, r) for n, r in rows if number(r.get("value")) is not None]
        closest = min(measured, key=lambda nr: distance_to_band(nr[1]), default=None)
        lines.append(rc.table_row([
            c, ", ".join(passed) or "none",
            closest[0] if closest else "–",
            value_text(closest[1]["value"], closest[1].get("error")) if closest else "–",
            band_text(rows[0][1]) if rows else "–"]))
    return lines + [""]


def distance_to_band(claim):
    value, band, comparison = claim["value"], claim["band"], claim["comparison"]
    if comparison == "range":
        return max(band[0] - value, value - band[1], 0.0)
    if comparison == "less_than":
        return max(value - band[0], 0.0)
    if comparison == "greater_than":
        return max(band[0] - value, 0.0)
    return math.inf


def band_text(claim):
    band, comparison = claim["band"], claim["comparison"]
    if comparison == "range":
        return f"{band[0]:g} to {band[1]:g}"
    return {"less_than": "< ", "greater_than": "> "}.get(comparison, comparison + " ") + \
        ", ".join(f"{b:g}" for b in band)


def figure_variants(results):
    """Four panels, one quantity each, variants on the vertical axis; MD's value and error as a
    band, the paper's band hatched where a claim has one."""
    variants = results["variants"]
    names = [v["name"] for v in variants]
    md = results["md"]
    panels = [
        ("C1", "shock formation phase f t [1]",
         lambda v: (v["claims"].get("C1") or {}).get("value"),
         md.get("formation_phase"), (0.10, 0.14)),
        ("gap0", "1 % mass bottom above the plate at f t = 0 [sigma]",
         lambda v: (v["mass_gap"].get("0") or [None])[0], md["mass_gap"].get("0"), None),
        ("C10", "largest centre-of-mass fractional RMS against MD [1]",
         lambda v: (v["claims"].get("C10") or {}).get("value"), None, (0.0, 0.03)),
        ("C15", "shock-location fractional RMS, ceiling 80 vs 200 [1]",
         lambda v: (v["claims"].get("C15") or {}).get("value"), None, (0.0, 0.01)),
    ]
    fig, axes = plt.subplots(1, 4, figsize=(16, 0.28 * len(names) + 2.0), sharey=True)
    y = list(range(len(names)))
    for ax, (key, label, get, reference, band) in zip(axes, panels):
        values = [number(get(v)) for v in variants]
        xs = [x for x in values if x is not None]
        ax.plot([x if x is not None else math.nan for x in values], y, "o", ms=4, color="C0",
                label="continuum variant")
        if band is not None:
            ax.axvspan(band[0], band[1], color="0.85", hatch="//", label="paper's band")
        if reference and number(reference[0]) is not None:
            err = number(reference[1]) or 0.0
            ax.axvspan(reference[0] - 2 * err, reference[0] + 2 * err, color="C3", alpha=0.25,
                       label="MD ± 2 standard errors")
            ax.axvline(reference[0], color="C3", lw=1.0, label="MD")
        ax.set_xlabel(textwrap.fill(label, 32))  # four panels side by side: no overlap
        ax.grid(axis="x", lw=0.3)
        if not xs:
            ax.text(0.5, 0.5, "not measured", transform=ax.transAxes, ha="center")
    axes[0].set_yticks(y)
    axes[0].set_yticklabels(names, fontsize=8)
    axes[0].set_ylabel("variant")
    axes[0].invert_yaxis()
    rc.legend_above(fig)  # one legend, over none of the points
    return fig


KNUDSEN_BINS = (0.0, 0.01, 0.03, 0.1, 0.3, math.inf)
SOLVER_NAMES = {"md": "MD", "continuum": "continuum (validation settings)"}


def read_profiles(path):
    """`shaker analyze --profiles-csv`: per phase, the columns as arrays, Kn the larger of
    Kn_n and Kn_T (NaN where neither is defined)."""
    table = rc.read_shaker_csv(path)[0]
    phases = {}
    for phase in np.unique(table["phase"]):
        rows = {name: values[table["phase"] == phase] for name, values in table.items()}
        kn = np.fmax(rows["kn_n"], rows["kn_T"])
        phases[round(float(phase), 6)] = dict(z=rows["z"], nu=rows["nu"], T=rows["T"], kn=kn)
    return phases


def figure_knudsen_maps(profiles):
    fig, axes = plt.subplots(1, len(profiles), figsize=(6 * len(profiles), 4.5), sharey=True,
                             squeeze=False)
    image = None
    for ax, (solver, phases) in zip(axes[0], profiles.items()):
        keys = sorted(phases)
        z = phases[keys[0]]["z"]
        top = 60.0
        rows = [np.interp(z, phases[k]["z"], np.log10(np.clip(phases[k]["kn"], 1e-6, None)),
                          left=np.nan, right=np.nan) for k in keys]
        grid = np.array(rows).T
        grid[~np.isfinite(grid)] = np.nan
        image = ax.pcolormesh(keys, z, grid, vmin=-3, vmax=1, cmap="viridis", shading="nearest")
        ax.set_ylim(0, top)
        ax.set_title(SOLVER_NAMES[solver])
        ax.set_xlabel("phase f t [1]")
    axes[0][0].set_ylabel("height z, lab frame [sigma]")
    fig.tight_layout(rect=(0, 0, 0.9, 1))  # the colorbar and its label take the last tenth
    colorbar = fig.colorbar(image, ax=axes[0].tolist(), fraction=0.04, pad=0.02)
    colorbar.set_label("log10 of the local Knudsen number max(Kn_n, Kn_T) [1]")
    return fig


def figure_knudsen_fraction(knudsen):
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for solver, data in knudsen.items():
        phase, fraction = np.array(data["phase"]), np.array(data["fraction"], dtype=float)
        errors = np.array(data.get("fraction_error") or [np.nan] * len(phase), dtype=float)
        if solver == "md":
            ax.errorbar(phase, fraction, yerr=np.nan_to_num(errors), fmt="o", ms=3, color="C3",
                        label="MD (± standard error over cycles)")
        else:
            ax.plot(phase, fraction, "-", color="C0", label=SOLVER_NAMES[solver])
    ax.set_xlabel("phase f t [1]")
    ax.set_ylabel("fraction of the material with Kn > 0.1 [1]")
    ax.legend(fontsize=8)
    ax.grid(lw=0.3)
    fig.tight_layout()
    return fig


def difference_by_knudsen(md, continuum):
    """|nu_MD - nu_continuum| and |T_MD - T_continuum| at MD's bins, by MD's local Kn (the
    continuum interpolated to MD's heights at the same phase)."""
    rows = []
    for lo, hi in zip(KNUDSEN_BINS[:-1], KNUDSEN_BINS[1:]):
        dnu, dT = [], []
        for phase, m in md.items():
            c = continuum.get(phase)
            if c is None:
                continue
            inside = (m["kn"] >= lo) & (m["kn"] < hi) & (m["nu"] > 0)
            nu_c = np.interp(m["z"][inside], c["z"], c["nu"], left=np.nan, right=np.nan)
            T_c = np.interp(m["z"][inside], c["z"], c["T"], left=np.nan, right=np.nan)
            dnu += list(np.abs(m["nu"][inside] - nu_c))
            dT += list(np.abs(m["T"][inside] - T_c))
        dnu, dT = np.array(dnu), np.array(dT)
        rows.append((lo, hi, int(np.isfinite(dnu).sum()), np.nanmean(dnu) if len(dnu) else None,
                     np.nanmean(dT) if len(dT) else None, np.nansum(dnu)))
    return rows


def knudsen_section(results, out_dir, link):
    knudsen = results.get("knudsen") or {}
    lines = ["## Where Navier-Stokes order is in doubt: the local Knudsen number", ""]
    if not knudsen:
        return lines + ["Not measured: the study had no base-case runs.", ""]
    lines += ["Kn_n = xi |dn/dz| / n and Kn_T = xi |dT/dz| / T per bin and phase "
              "(docs/analysis.md), base case; MD and the continuum at the validation settings. "
              "Navier-Stokes order assumes Kn << 1.", ""]
    profiles = {solver: read_profiles(d["profiles_csv"]) for solver, d in knudsen.items()}
    maps = rc.write_figure(figure_knudsen_maps(profiles), out_dir, "knudsen-maps.png")
    fraction = rc.write_figure(figure_knudsen_fraction(knudsen), out_dir, "knudsen-fraction.png")
    lines += [f"![Local Knudsen number, base case]({link}/{maps})", "",
              f"![Material above Kn = 0.1]({link}/{fraction})", ""]
    if "md" in profiles and "continuum" in profiles:
        rows = difference_by_knudsen(profiles["md"], profiles["continuum"])
        total = sum(r[5] for r in rows if np.isfinite(r[5])) or math.nan
        lines += ["The profiles' differences by MD's local Knudsen number (every phase and "
                  "bin with MD material):", ""]
        lines += rc.table_head(["Kn range [1]", "bins [1]", "mean |nu_MD - nu_continuum| [1]",
                                "mean |T_MD - T_continuum| [g sigma]",
                                "share of the summed |nu difference| [1]"])
        for lo, hi, count, dnu, dT, summed in rows:
            lines.append(rc.table_row([f"{lo:g} to {hi:g}", str(count), rc.fmt(dnu, 3),
                                       rc.fmt(dT, 3), rc.fmt(summed / total, 3)]))
        lines.append("")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--results", required=True)
    parser.add_argument("--output", required=True)
    args = parser.parse_args(argv)
    with open(args.results) as f:
        results = json.load(f)
    out_dir = os.path.splitext(args.output)[0]
    os.makedirs(out_dir, exist_ok=True)
    link = os.path.basename(out_dir)
    simulated = results.get("simulated_seconds", 0.0)
    lines = ["# Continuum sensitivity: the choices the paper leaves open", "",
             "Written by granular_shaker.reports.make_sensitivity_report from the sensitivity "
             "study (shaker-sensitivity; variants: validation/sensitivity.toml). Every choice the "
             "paper leaves open or this project made is varied one at a time from the validation "
             "settings, and each variant is judged by the claims the continuum fails, against MD "
             "with MD's errors.", "",
             f"- commit: {results['commit']}",
             f"- program: {results['shaker_version']}",
             f"- wall time of this call: {results['wall_seconds']:.0f} s; solver time of the runs "
             f"it started: {simulated:.0f} s", ""]
    lines += md_section(results)
    lines += decision_section(results)
    variants = rc.write_figure(figure_variants(results), out_dir, "variants.png")
    lines += ["## The variants against MD", "", f"![The variants against MD]({link}/{variants})",
              ""]
    lines += knudsen_section(results, out_dir, link)
    lines += variants_table(results)
    rc.write_text_atomically(args.output, "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
