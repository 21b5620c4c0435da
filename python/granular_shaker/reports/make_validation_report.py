"""Writes the validation report (markdown + PNG plots) from the results of the validation
study (shaker-validation, granular_shaker.validation).

    shaker-validation-report --results WORKDIR/results.json --output reports/validation.md
        [--gci TABLE] [--repository DIR]

(or `python3 -m granular_shaker.reports.make_validation_report ...`; the validation study calls
it itself).

Reads only files: results.json (runs, claim evaluations, agreement metrics, written by the
runner), the HDF5 run files it names (docs/output-schema.md) and their `shaker analyze --csv`
tables (RUN.h5.analysis.csv). The plots go into a folder beside the report named after it
(reports/validation/ for reports/validation.md). One section per figure of Bougie et al.,
PRE 66, 051301 (2002), then the claims table (reference-data/claims.toml), then the agreement
metrics of every case run by both solvers. Every table gives units (docs/units.md): in the
header of a column holding one quantity, in a units column where rows hold different ones
(the claims', evidence's and metrics' units come with them in results.json).
"""
import argparse
import json
import math
import os
import sys
import textwrap

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from granular_shaker.repository import add_repository_option, repository_argument  # noqa: E402
from granular_shaker.reports import report_common as rc  # noqa: E402
# One reader of the tables.
from granular_shaker.reports.make_convergence_report import GCI_HEADER, read_csv  # noqa: E402

FIG1_PHASES = (0.0, 0.15, 0.22, 0.40)
FIG2_CASES = (("single_shock_e0p99", "e = 0.99"), ("single_shock_e0p90", "e = 0.90"),
              ("single_shock_e0p85", "e = 0.85"))
DEPTHS = (("depth_h4p5", "H = 4.5"), ("base", "H = 9"), ("depth_h13p5", "H = 13.5"))
# The base case's GCI table in the repository, where the convergence report copies it.
GCI_TABLE = os.path.join("reports", "convergence-tables", "real-1d-base.gci.csv")


# ---- reading -------------------------------------------------------------------------------

class Results:
    """results.json of the validation study, with the GCI table (`gci_path`) whose path the
    report names relative to `repository`."""

    def __init__(self, path, gci_path=None, repository=None):
        with open(path) as f:
            self.data = json.load(f)
        self.views = self.data["views"]
        self.gci_path, self.repository = gci_path, repository
        self.gci_rows = []
        if gci_path and os.path.exists(gci_path):
            self.gci_rows = read_csv(gci_path, GCI_HEADER)

    def gci(self, quantity, cell_size):
        """The GCI row of the real-problem study whose finest grid is the validation run's
        cell size (so its uncertainty1 is the discretisation uncertainty of that run's
        value)."""
        if cell_size is None:
            return None
        for r in self.gci_rows:
            if r["quantity"] == quantity and math.isclose(r["h1"], cell_size, rel_tol=1e-9):
                return r
        return None

    def view(self, case, solver):
        v = self.views.get(f"{case}/{solver}")
        return v if v and v["status"] == "ok" and v["path"] and os.path.exists(v["path"]) \
            else None

    def analysis(self, case, solver):
        table = self.analysis_with_errors(case, solver)
        return table[0] if table else None

    def analysis_with_errors(self, case, solver):
        """Per-phase values and jackknife errors of `shaker analyze --json`."""
        v = self.view(case, solver)
        if not v or not v.get("analysis_json") or not os.path.exists(v["analysis_json"]):
            return None
        with open(v["analysis_json"]) as f:
            per_phase = json.load(f)["per_phase"]
        number = lambda x: math.nan if x is None else float(x)  # noqa: E731
        return ({k: np.array([number(x) for x in q["value"]]) for k, q in per_phase.items()},
                {k: np.array([number(x) for x in q["error"]]) for k, q in per_phase.items()})

    def profiles(self, case, solver):
        v = self.view(case, solver)
        if not v:
            return None
        with h5py.File(v["path"], "r") as f:
            prof = {k: np.array(f["profiles"][k]) for k in f["profiles"]}
        mach_csv = v["path"] + ".profiles.csv"  # `shaker analyze --profiles-csv`
        if os.path.exists(mach_csv):
            mach = rc.read_shaker_csv(mach_csv)[0]["mach"]
            if mach.size == prof["z"].size:
                prof["mach"] = mach.reshape(prof["z"].shape)
        return prof

    def status(self, case, solver):
        v = self.views.get(f"{case}/{solver}")
        return v["status"] if v else "not run"


def nearest(phases, target):
    return int(np.argmin(np.abs(((np.asarray(phases) - target + 0.5) % 1.0) - 0.5)))


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    return f"{x:.{digits}g}"


def missing_text(results, needs):
    absent = [f"{solver} {case} ({results.status(case, solver)})" for case, solver in needs
              if not results.view(case, solver)]
    return "runs not available: " + ", ".join(absent) if absent else ""


def write(fig, out_dir, name):
    os.makedirs(out_dir, exist_ok=True)
    return rc.write_figure(fig, out_dir, name)


# ---- figures: each fig<N>_section returns markdown, its figure_* draws the figure ------------

HEIGHT_LAB = "height z, lab frame [sigma]"
PHASE = "phase f t [1]"


def shock_region(row):
    """(low, high) of the shock region: the analysis' compressed-region top and undisturbed
    bottom when `shaker analyze` prints them, else location -/+ width/2 (approximate)."""
    if "shock_compressed_top" in row:
        return row["shock_compressed_top"], row["shock_undisturbed_bottom"], True
    return row["shock_location"] - row["shock_width"] / 2, \
        row["shock_location"] + row["shock_width"] / 2, False


def draw_plate(ax, phase, plate_z, horizontal=False):
    if horizontal:
        return ax.axhline(plate_z, color="k", lw=2, label="plate")
    return ax.plot(phase, plate_z, "k-", lw=2.5, label="plate")


def error_of(errors, name):
    return None if errors is None or name not in errors else np.nan_to_num(errors[name])


def figure_profiles(runs):
    """Fig. 1: nu and T against height at FIG1_PHASES; runs: {solver: (profiles, analysis)}.
    The continuum's shock region shaded."""
    fig, axes = plt.subplots(2, len(FIG1_PHASES), figsize=(14, 7.5), sharey="col")
    for col, phase in enumerate(FIG1_PHASES):
        top, plate = 0.0, None
        for solver, (prof, table) in runs.items():
            k = nearest(prof["phase"], phase)
            errors = rc.profile_errors(prof, k)
            rc.draw_profile(axes[0, col], solver, prof["nu"][k], prof["z"][k], errors["nu"])
            rc.draw_profile(axes[1, col], solver, prof["T"][k], prof["z"][k], errors["T"])
            row = {name: table[name][k] for name in table}
            top = max(top, np.nan_to_num(row["layer_top"]) + 12)
            plate = prof["plate_z"][k] if plate is None else min(plate, prof["plate_z"][k])
            if solver == "continuum" and not math.isnan(row["shock_location"]):
                lo, hi, _ = shock_region(row)
                for ax in axes[:, col]:
                    ax.axhspan(lo, hi, color="0.8", zorder=0, label="continuum shock region")
        for ax in axes[:, col]:
            draw_plate(ax, None, plate, horizontal=True)
            ax.set_ylim(plate - 1, max(top, plate + 20))
            ax.set_ylabel(HEIGHT_LAB)
        axes[0, col].set_title(f"f t = {phase:.2f}")
        axes[0, col].set_xlabel("volume fraction nu [1]")
        axes[1, col].set_xlabel("temperature T [g sigma]")
    rc.legend_above(fig)
    return fig


def fig1_section(results, out_dir, link):
    needs = [("base", "md"), ("base", "continuum")]
    runs = {s: (results.profiles("base", s), results.analysis("base", s)) for _, s in needs}
    runs = {s: r for s, r in runs.items() if r[0] is not None}
    text = ["## Fig. 1: volume fraction and temperature against height (base case)", ""]
    if not runs:
        return text + [f"No plot: {missing_text(results, needs)}.", ""]
    rows = rc.table_head([rc.analysis_header("f t", "phase"), "solver",
                          rc.analysis_header("plate z", "plate_z"),
                          rc.analysis_header("layer bottom", "layer_bottom"),
                          rc.analysis_header("layer top", "layer_top"),
                          rc.analysis_header("shock location", "shock_location"),
                          rc.analysis_header("width d", "shock_width")])
    exact = True
    for phase in FIG1_PHASES:
        for solver, (prof, table) in runs.items():
            k = nearest(prof["phase"], phase)
            row = {name: table[name][k] for name in table}
            rows.append(f"| {prof['phase'][k]:.2f} | {solver} | {fmt(row['plate_z'])} | "
                        f"{fmt(row['layer_bottom'])} | {fmt(row['layer_top'])} | "
                        f"{fmt(row['shock_location'])} | {fmt(row['shock_width'])} |")
            if solver == "continuum" and not math.isnan(row["shock_location"]):
                exact = exact and shock_region(row)[2]
    name = write(figure_profiles(runs), out_dir, "fig1-profiles.png")
    region = ("the continuum's shock region (compressed-region top to undisturbed bottom)"
              if exact else "location -/+ d/2 of the continuum shock (approximate: `shaker "
              "analyze` does not print the region's ends)")
    return text + [f"MD points with their standard errors, continuum lines; the plate is the "
                   f"black line; grey: {region}.", "", f"![Fig. 1]({link}/{name})", ""] \
        + rows + [""]


FIG2_MAX_NU = 0.65  # the shading's scale: random close packing


def figure_single_shock(cases):
    """Fig. 2: per case (label, continuum profiles or None, {solver: (analysis, errors)}),
    shock location, centre of mass and layer edges over the cycle on the continuum's nu."""
    # The colorbar in a column of its own, so that the layout makes room for its label.
    fig, axes = plt.subplots(1, len(cases) + 1, figsize=(5 * len(cases) + 1, 5.6),
                             gridspec_kw=dict(width_ratios=[1] * len(cases) + [0.05]))
    panels, bar = axes[:-1], axes[-1]
    mesh = None
    for ax, (label, prof, tables) in zip(panels, cases):
        if ax is not panels[0]:
            ax.sharey(panels[0])
        if prof is not None:
            phase = np.repeat(prof["phase"][:, None], prof["z"].shape[1], axis=1)
            mesh = ax.pcolormesh(phase, prof["z"], prof["nu"], cmap="Greys", shading="gouraud",
                                 vmin=0, vmax=FIG2_MAX_NU)
        for solver, (t, errors) in tables.items():
            if solver == "continuum":
                ax.plot(t["phase"], t["shock_location"], "r-", label="continuum shock")
                ax.plot(t["phase"], t["center_of_mass"], "b--", label="continuum centre of mass")
                continue
            for column, what, style in (("shock_location", "shock", dict(marker="^", color="r")),
                                        ("center_of_mass", "centre of mass",
                                         dict(marker="o", color="b")),
                                        ("layer_top", "layer top", dict(marker="+", color="g")),
                                        ("layer_bottom", "layer bottom",
                                         dict(marker="x", color="g"))):
                rc.draw_series(ax, "md", t["phase"], t[column], error_of(errors, column),
                               label=f"MD {what}", **style)
        t = next(iter(tables.values()))[0]
        draw_plate(ax, t["phase"], t["plate_z"])
        ax.set_title(label)
        ax.set_xlabel(PHASE)
        ax.set_ylim(0, 60)
    panels[0].set_ylabel(HEIGHT_LAB)
    if mesh is not None:
        fig.colorbar(mesh, cax=bar).set_label("continuum volume fraction nu [1]")
    else:
        bar.set_visible(False)
    rc.legend_above(fig)
    return fig


def fig2_section(results, out_dir, link):
    needs = [(c, s) for c, _ in FIG2_CASES for s in ("md", "continuum")]
    text = ["## Fig. 2: shock location and centre of mass, e = 0.99, 0.90, 0.85 (single shock)",
            ""]
    cases = []
    rows = rc.table_head(["case", "solver", rc.analysis_header("formation f t", "phase"),
                          rc.analysis_header("shock speed", "shock_speed"),
                          rc.analysis_header("centre-of-mass apex", "center_of_mass_apex")])
    for case, label in FIG2_CASES:
        tables = {s: results.analysis_with_errors(case, s) for s in ("continuum", "md")}
        tables = {s: t for s, t in tables.items() if t is not None}
        if not tables:
            continue
        cases.append((label, results.profiles(case, "continuum"), tables))
        for solver, (t, _) in tables.items():
            v = results.views[f"{case}/{solver}"]
            rows.append(f"| {case} | {solver} | {fmt(first_shock(t))} | "
                        f"{fmt(v['shock_speed'])}{pm(v.get('shock_speed_error'))} | "
                        f"{fmt(float(np.max(t['center_of_mass'])))} |")
    if not cases:
        return text + [f"No plot: {missing_text(results, needs)}.", ""]
    name = write(figure_single_shock(cases), out_dir, "fig2-single-shock.png")
    note = missing_text(results, needs)
    return text + ["Shading: continuum volume fraction (dark = dense). Lines continuum, "
                   "markers MD (pooled single-shock runs, with their standard errors)."
                   + (f" Missing: {note}." if note else ""), "",
                   f"![Fig. 2]({link}/{name})", ""] + rows + [""]


def first_shock(t):
    idx = np.nonzero(~np.isnan(t["shock_location"]))[0]
    return float(t["phase"][idx[0]]) if len(idx) else math.nan


def pm(error):
    return f" ± {fmt(error, 2)}" if error is not None else ""


MACH_PLOT_MIN_NU = 1e-3  # Fig. 3 draws Ma(z) only where nu exceeds this
FIG3_PHASE = 0.22


def figure_mach(runs):
    """Fig. 3: nu and Ma against height at f t = FIG3_PHASE, side by side on one height axis;
    runs: {solver: (profiles, analysis, analysis errors)}."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 6), sharey=True)
    for solver, (prof, table, errors) in runs.items():
        k = nearest(prof["phase"], FIG3_PHASE)
        name = "MD" if solver == "md" else solver
        rc.draw_profile(left, solver, prof["nu"][k], prof["z"][k],
                        rc.profile_errors(prof, k)["nu"])
        if "mach" in prof:
            # Ma of a nearly empty bin (a few particles in the dilute gas) is meaningless and
            # can reach 1e8: drawn only where there is material.
            dense = prof["nu"][k] > MACH_PLOT_MIN_NU
            right.plot(prof["mach"][k][dense], prof["z"][k][dense], label=f"{name} Ma(z)",
                       **(dict(ls="none", marker="^", ms=4) if solver == "md" else dict(ls="--")))
        if not math.isnan(table["shock_location"][k]):
            error = error_of(errors, "max_mach")
            right.errorbar([table["max_mach"][k]], [table["shock_location"][k]],
                           xerr=None if error is None else [error[k]],
                           fmt="r^" if solver == "md" else "rs", ms=8,
                           label=f"{name} max Ma (at the shock)")
    plate = min(r[0]["plate_z"][nearest(r[0]["phase"], FIG3_PHASE)] for r in runs.values())
    for ax in (left, right):
        draw_plate(ax, None, plate, horizontal=True)
        ax.legend(fontsize=8)
    left.set_xlabel("volume fraction nu [1]")
    right.set_xlabel("Mach number Ma [1]")
    left.set_ylabel(HEIGHT_LAB)
    left.set_ylim(plate - 1, plate + 30)
    fig.tight_layout()
    return fig


def fig3_section(results, out_dir, link):
    needs = [("base", "md"), ("base", "continuum")]
    text = ["## Fig. 3: Mach number and nu against height at f t = 0.22 (base case)", ""]
    runs = {s: (results.profiles("base", s), results.analysis_with_errors("base", s))
            for _, s in needs}
    runs = {s: (p, *t) for s, (p, t) in runs.items() if p is not None and t is not None}
    if not runs:
        return text + [f"No plot: {missing_text(results, needs)}.", ""]
    rows = rc.table_head(["solver", rc.analysis_header("f t", "phase"),
                          rc.analysis_header("shock location", "shock_location"),
                          rc.analysis_header("maximum Ma in the layer", "max_mach")])
    for solver, (prof, table, _) in runs.items():
        k = nearest(prof["phase"], FIG3_PHASE)
        rows.append(f"| {solver} | {prof['phase'][k]:.2f} | {fmt(table['shock_location'][k])} | "
                    f"{fmt(table['max_mach'][k])} |")
    name = write(figure_mach(runs), out_dir, "fig3-mach.png")
    has_profile = any("mach" in r[0] for r in runs.values())
    note = ("" if has_profile else " The Mach-number profile Ma(z) is not drawn: `shaker analyze` "
            "prints only the maximum Ma in the layer, which the paper locates at the leading "
            "edge of the shock; it is drawn there.")
    note += f" Ma is drawn where nu > {MACH_PLOT_MIN_NU:g}."
    return text + ["nu on the left, Ma on the right. Lines continuum, markers MD." + note, "",
                   f"![Fig. 3]({link}/{name})", ""] + rows + [""]


PAPER_FORMATION, PAPER_EXIT = 0.12, 0.35


def figure_mach_width(tables):
    """Fig. 4: maximum Ma (top) and d/xi (bottom) against f t; tables: {solver: (analysis,
    errors)}."""
    fig, axes = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    for ax, column, label in ((axes[0], "max_mach", "maximum Mach number in the layer [1]"),
                              (axes[1], "width_over_mfp", "shock width over mean free path "
                                                          "d/xi [1]")):
        for solver, (t, errors) in tables.items():
            rc.draw_series(ax, solver, t["phase"], t[column], error_of(errors, column),
                           label=rc.SOLVER_LABELS[solver])
        ax.axvline(PAPER_FORMATION, color="0.6", lw=0.8, ls="--",
                   label=f"paper: formation f t = {PAPER_FORMATION}")
        ax.axvline(PAPER_EXIT, color="0.6", lw=0.8, ls=":",
                   label=f"paper: exit f t = {PAPER_EXIT}")
        ax.set_yscale("log")
        ax.set_ylabel(textwrap.fill(label, 30))
        ax.legend(fontsize=7)
    axes[1].set_xlim(0, 0.5)
    axes[1].set_xlabel(PHASE)
    fig.tight_layout()
    return fig


def fig4_section(results, out_dir, link):
    needs = [("base", "md"), ("base", "continuum")]
    text = ["## Fig. 4: maximum Mach number and d/xi against f t (base case)", ""]
    tables = {s: results.analysis_with_errors("base", s) for _, s in needs}
    tables = {s: t for s, t in tables.items() if t is not None}
    if not tables:
        return text + [f"No plot: {missing_text(results, needs)}.", ""]
    rows = rc.table_head([rc.analysis_header("f t", "phase")] + [
        header for s in tables for header in (rc.analysis_header(f"{s} max Ma", "max_mach"),
                                              rc.analysis_header(f"{s} d/xi", "width_over_mfp"))])
    name = write(figure_mach_width(tables), out_dir, "fig4-mach-width.png")
    first = next(iter(tables.values()))[0]
    for k, phase in enumerate(first["phase"]):
        if phase > 0.5:
            break
        cells = []
        for t, _ in tables.values():
            cells += [fmt(t["max_mach"][k]), fmt(t["width_over_mfp"][k])]
        rows.append(f"| {phase:.2f} | " + " | ".join(cells) + " |")
    return text + [f"Dashed and dotted grey lines: the paper's formation ({PAPER_FORMATION}) and "
                   f"exit ({PAPER_EXIT}) phases.", "", f"![Fig. 4]({link}/{name})", ""] \
        + rows + [""]


def figure_shock_speed(points):
    """Fig. 5: shock speed against e; points: {solver: sorted [(e, speed, error or None)]}."""
    fig, ax = plt.subplots(figsize=(6, 5))
    for solver, pts in points.items():
        if not pts:
            continue
        e, v, err = zip(*pts)
        if solver == "md":
            ax.errorbar(e, v, yerr=[x or 0 for x in err], fmt="o", capsize=3,
                        label="MD (pooled, ± jackknife standard error)")
        else:
            ax.plot(e, v, "-s", label="continuum")
    ax.set_xlabel("restitution coefficient e [1]")
    ax.set_ylabel("shock speed, plate frame [sqrt(g sigma)]")
    ax.legend()
    fig.tight_layout()
    return fig


def fig5_section(results, out_dir, link):
    text = ["## Fig. 5: average shock speed against e (single shock, plate frame)", ""]
    points = {"md": [], "continuum": []}
    for key, v in sorted(results.views.items()):
        if v["protocol"] == "single_shock" and v["status"] == "ok" and \
                v["case"].startswith("single_shock_e"):
            points[v["solver"]].append((v["switch_e"], v["shock_speed"],
                                        v.get("shock_speed_error")))
    if not any(points.values()):
        return text + ["No plot: no single-shock run is available.", ""]
    rows = rc.table_head([rc.with_units("e", rc.DIMENSIONLESS),
                          rc.analysis_header("MD v_shock", "shock_speed"),
                          rc.analysis_header("continuum v_shock", "shock_speed")])
    drawn = {s: sorted((e, v, err) for e, v, err in pts if v is not None)
             for s, pts in points.items()}
    for e in sorted({p[0] for pts in points.values() for p in pts}):
        cell = {s: next((f"{fmt(v)}{pm(err)}" for ee, v, err in points[s] if ee == e), "–")
                for s in points}
        rows.append(f"| {e:.2f} | {cell['md']} | {cell['continuum']} |")
    name = write(figure_shock_speed(drawn), out_dir, "fig5-shock-speed.png")
    return text + [f"![Fig. 5]({link}/{name})", ""] + rows + [""]


RESTITUTION_PAIR = (("single_shock_e0p90", "constant e = 0.9"), ("velocity_dependent", "e(v_n)"))


def figure_restitution(tables):
    """Fig. 6: MD shock location and centre of mass for two restitution models; tables:
    [(label, analysis, errors)]."""
    fig, ax = plt.subplots(figsize=(7, 5))
    for (label, t, errors), (shock, com) in zip(tables, (("r^", "bo"), ("mx", "c+"))):
        for column, what, style in (("shock_location", "shock", shock),
                                    ("center_of_mass", "centre of mass", com)):
            rc.draw_series(ax, "md", t["phase"], t[column], error_of(errors, column),
                           label=f"MD {what}, {label}", marker=style[1], color=style[0])
    draw_plate(ax, tables[0][1]["phase"], tables[0][1]["plate_z"])
    ax.set_xlabel(PHASE)
    ax.set_ylabel(HEIGHT_LAB)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def fig6_section(results, out_dir, link):
    needs = [(c, "md") for c, _ in RESTITUTION_PAIR]
    text = ["## Fig. 6: constant against velocity-dependent restitution (MD, single shock)", ""]
    tables = [(label, results.analysis_with_errors(c, "md"), c) for c, label in RESTITUTION_PAIR]
    tables = [(label, *t, c) for label, t, c in tables if t is not None]
    if not tables:
        return text + [f"No plot: {missing_text(results, needs)}.", ""]
    rows = rc.table_head(["restitution", rc.analysis_header("shock speed", "shock_speed"),
                          rc.analysis_header("centre-of-mass apex", "center_of_mass_apex")])
    for label, t, _, case in tables:
        v = results.views[f"{case}/md"]
        rows.append(f"| {label} | {fmt(v['shock_speed'])}{pm(v.get('shock_speed_error'))} | "
                    f"{fmt(float(np.max(t['center_of_mass'])))} |")
    name = write(figure_restitution([t[:3] for t in tables]), out_dir,
                 "fig6-restitution-models.png")
    note = missing_text(results, needs)
    return text + ([f"Missing: {note}.", ""] if note else []) + \
        [f"![Fig. 6]({link}/{name})", ""] + rows + [""]


def figure_depths(runs):
    """Fig. 7: centre of mass (top) and shock location (bottom) over a cycle per depth;
    runs: [(depth label, solver, analysis, errors)]."""
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 9), sharex=True)
    colors = {}
    for label, solver, t, errors in runs:
        color = colors.setdefault(label, f"C{len(colors)}")
        for ax, column in ((a, "center_of_mass"), (b, "shock_location")):
            rc.draw_series(ax, solver, t["phase"], t[column], error_of(errors, column),
                           label=f"{label} {rc.SOLVER_LABELS[solver]}", color=color)
    a.set_ylabel("centre of mass, lab frame [sigma]")
    b.set_ylabel("shock location, lab frame [sigma]")
    b.set_xlabel(PHASE)
    rc.legend_above(fig, columns=3)
    return fig


def fig7_section(results, out_dir, link):
    needs = [(c, s) for c, _ in DEPTHS for s in ("md", "continuum")]
    text = ["## Fig. 7: centre of mass over a cycle and shock location for H = 4.5, 9, 13.5",
            ""]
    # H: the depth of the layer at rest, in particle diameters.
    rows = rc.table_head([rc.with_units("H", "sigma"), "solver",
                          rc.analysis_header("mean centre of mass", "center_of_mass_mean"),
                          rc.analysis_header("formation f t", "phase"),
                          rc.analysis_header("shock speed", "shock_speed")])
    runs = []
    for case, label in DEPTHS:
        for solver in ("md", "continuum"):
            table = results.analysis_with_errors(case, solver)
            if table is None:
                continue
            t = table[0]
            runs.append((label, solver, *table))
            v = results.views[f"{case}/{solver}"]
            rows.append(f"| {label[4:]} | {solver} | {fmt(float(np.mean(t['center_of_mass'])))}"
                        f" | {fmt(first_shock(t))} | {fmt(v['shock_speed'])} |")
    if not runs:
        return text + [f"No plot: {missing_text(results, needs)}.", ""]
    name = write(figure_depths(runs), out_dir, "fig7-depths.png")
    note = missing_text(results, needs)
    return text + (["Missing: " + note + ".", ""] if note else []) + \
        [f"![Fig. 7]({link}/{name})", ""] + rows + [""]


# ---- claims and metrics ------------------------------------------------------------------

def _exists(x):
    return x is not None and not (isinstance(x, float) and math.isnan(x))


def value_text(value, error):
    if value is None:
        return "–"
    if isinstance(value, list):
        if error is None or not isinstance(error, list):
            error = [None] * len(value)
        return "[" + ", ".join(f"{fmt(v)}{pm(e) if _exists(v) else ''}"
                               for v, e in zip(value, error)) + "]"
    return f"{fmt(value, 4)}{pm(error)}"


def band_text(check):
    c, b = check["comparison"], check["band"]
    return {"range": lambda: f"{b[0]:g} to {b[1]:g}", "all_in_range": lambda:
            f"all measured phases in {b[0]:g} to {b[1]:g}", "less_than": lambda: f"< {b[0]:g}",
            "greater_than": lambda: f"> {b[0]:g}", "strictly_increasing":
            lambda: "strictly increasing", "true": lambda: "detected"}[c]()


def check_units(item, where):
    """The units of a claim's check or a diagnosis' evidence, as the runner wrote them from
    granular_shaker.validation.quantities (UNITS); an error, not a blank, if they are missing."""
    if not item.get("units"):
        raise rc.UnknownUnits(f"{where}: no units for the quantity '{item.get('quantity')}' in "
                              "the results (written by the validation study)")
    return item["units"]


def mark(status):
    return {"pass": "pass", "fail": "**FAIL**", "inconclusive": "inconclusive",
            "unresolved": "unresolved"}.get(status, status)


def gci_text(results, claim, value):
    """The continuum value's grid uncertainty: the real-problem study's uncertainty of its
    finest value (uncertainty1, GciRow) at the validation run's cell size, relative to that
    value and applied to the validation run's, for claims whose continuum value that study
    computes (the claim's `continuum_gci` in reference-data/claims.toml)."""
    quantity = claim.get("continuum_gci")
    if not quantity or not isinstance(value, (int, float)):
        return ""
    view = results.views.get(f"{claim['cases'][0]}/continuum") or {}
    cell = view.get("continuum_cell_size")
    row = results.gci(quantity, cell)
    if row is None:
        return f" (GCI: no {quantity} row at cell {cell} in the convergence tables)"
    cells = ", ".join(f"{row[h]:g}" for h in ("h1", "h2", "h3"))
    relative = row["uncertainty1"] / abs(row["phi1"]) if row["phi1"] else float("nan")
    if not math.isfinite(relative):
        return f" (grid uncertainty n/a: {row['convergence']} on cells {cells})"
    asymptotic = "asymptotic, Fs 1.25" if row["pass"] == 1 \
        else f"not asymptotic: {row['convergence']}, p {fmt(row['order'], 2)}"
    return (f" ± {fmt(abs(value) * relative, 2)} (grid {fmt(100 * relative, 2)} %, "
            f"cells {cells}; {asymptotic})")


def solver_cell(results, claim, solver):
    r = claim["per_solver"].get(solver)
    if r is None:
        return "n/a"
    parts = []
    for check, ev in zip(claim["checks"], r["checks"]):
        if ev["status"] == "not measured":
            parts.append(f"not measured: {ev['reason']}")
        else:
            bound = " (lower bound)" if ev.get("bound") == "lower" else ""
            grid = gci_text(results, claim, ev["value"]) if solver == "continuum" else ""
            inside = ev.get("margin")
            by = ""
            if ev["status"] == "unresolved" and inside is not None:
                by = (f", inside the band by {inside:.1f} standard errors" if inside >= 0
                      else f", outside the band by {-inside:.1f} standard errors")
            parts.append(f"{value_text(ev['value'], ev.get('error'))}{grid}{bound} "
                         f"({mark(ev['status'])}{by})")
    return "; ".join(parts)


def claims_section(results):
    gci_source = (os.path.relpath(results.gci_path, results.repository) if results.gci_rows
                  else "none found")
    lines = ["## Claims C1 to C20", "",
             "Bands and claims from reference-data/claims.toml. MD uncertainty: one standard "
             "error, the jackknife over the independent samples (the sampled cycles of a "
             "periodic run, or the pooled single-shock runs), from `shaker analyze` and "
             "`shaker compare`; a value quantised to the stored phases or to the bins also "
             "carries its rounding error, grid step / sqrt(12) (docs/analysis.md). Continuum "
             "uncertainty: that rounding error where it applies, and the grid uncertainty "
             "(Roache's GCI with Fs 1.25 in the asymptotic range, Fs 3 outside it, at least "
             "half the range of an oscillating triple) of the 1D base-case grid study "
             f"(verification/grid-studies/test_real_problem.cpp, tables in {gci_source}) at "
             "the validation run's cell size, for the claims whose continuum value that "
             "study computes (field continuum_gci of the claim); the study's runs (a transient "
             "until the column is periodic to 1e-6, then one sampled cycle) estimate the "
             "discretisation error only. "
             "Other continuum values carry no uncertainty here.",
             "",
             "Verdicts: **pass** when the value lies inside the band by more than 2 standard "
             "errors; **FAIL** when it lies outside by more than 2; **unresolved** in between "
             "(the data cannot decide at that level; the margin is given in standard errors). "
             "A value without an error is judged on its value alone. An ordering is judged on "
             "its smallest step over the step's error. A list "
             "over phases is judged on the phases where it exists (a phase without a shock has "
             "no width), if they are at least half of them. Why each failing claim fails is "
             "in the next section.",
             ""] + rc.table_head(["id", "claim", rc.UNITS_COLUMN, "paper", "MD", "continuum",
                                  "band", "result"])
    counts = {}
    for claim in results.data["claims"]:
        bands = "; ".join(band_text(c) for c in claim["checks"])
        units = "; ".join(check_units(c, claim["id"]) for c in claim["checks"])
        if claim["solvers"] == "md_vs_continuum":
            md = "MD vs continuum: " + solver_cell(results, claim, "md_vs_continuum")
            co = "(one value for the pair)"
        else:
            md, co = solver_cell(results, claim, "md"), solver_cell(results, claim, "continuum")
        status = claim["status"]
        counts[status] = counts.get(status, 0) + 1
        lines.append(f"| {claim['id']} | {claim['statement']} | {units} | "
                     f"{claim['paper_value']} | {md} | {co} | {bands} | {mark(status)} |")
    notes = sorted({f"{claim['id']}: {n}" for claim in results.data["claims"]
                    for r in claim["per_solver"].values() for ev in r["checks"]
                    for n in ev.get("notes", [])})
    lines += [""] + [f"- {n}" for n in notes] + ([""] if notes else [])
    unresolved = unresolved_lines(results)
    if unresolved:
        lines += ["What would decide the unresolved checks: the error shrinks as one over the "
                  "square root of the number of independent samples (cycles or single-shock "
                  "runs), so a check at margin m standard errors needs about (2 / |m|)^2 "
                  "times its samples to reach 2 either way.", ""] + unresolved + [""]
    return lines, counts


def unresolved_lines(results):
    out = []
    for claim in results.data["claims"]:
        for solver, r in claim["per_solver"].items():
            for check, ev in zip(claim["checks"], r["checks"]):
                if ev.get("status") != "unresolved" or ev.get("margin") is None:
                    continue
                m = abs(ev["margin"])
                need = (f"about {(2.0 / m) ** 2:.0f} times the samples" if m > 0.05 else
                        "the value sits on the band's edge: more samples decide only if it moves")
                out.append(f"- {claim['id']} {solver} ({check['quantity']}): margin "
                           f"{ev['margin']:+.1f}; {need}")
    return out


CATEGORY_TEXT = {"a": "(a) the continuum and MD really differ",
                 "b": "(b) MD does not reproduce the paper's statement",
                 "c": "(c) a defect of the project still to find or fix",
                 "d": "(d) the continuum's equations give it, whatever the numerical choices"}


def measured_text(m):
    if m.get("status") == "not measured":
        return f"not measured: {m['reason']}"
    return value_text(m["value"], m.get("error"))


def diagnoses_section(results):
    """Why each failing claim fails (validation/diagnoses.toml), with its evidence measured
    on this study's runs."""
    d = results.data
    lines = ["## Why the failing claims fail", "",
             "Each failing claim's reason category and the evidence, measured on this study's "
             "runs (value ± one standard error); the reasons are the project's findings, kept in "
             "validation/diagnoses.toml.", ""]
    for diag in d.get("diagnoses", []):
        title = diag["claim"] + (f" ({diag['solver']})" if diag.get("solver") else "")
        status = diag.get("claim_status")
        lines.append(f"### {title}: {CATEGORY_TEXT[diag['category']]}")
        lines.append("")
        if diag.get("stale"):
            lines += [f"**Stale diagnosis**: the claim is now '{status}', not failing; the "
                      "reason below was written for a failure.", ""]
        lines += [" ".join(diag["reason"].split()), ""]
        solvers = sorted({s for e in diag["evidence"] for s in e["measured"]},
                         key=["md", "continuum", "md_vs_continuum"].index)
        if diag["evidence"]:
            lines += rc.table_head(["evidence", rc.UNITS_COLUMN] + solvers)
            for e in diag["evidence"]:
                lines.append(f"| {e['label']} | {check_units(e, diag['claim'])} | " + " | ".join(
                    measured_text(e["measured"][s]) if s in e["measured"] else ""
                    for s in solvers) + " |")
            lines.append("")
    if d.get("undiagnosed"):
        lines += ["Failing claims without a diagnosis (category (c) until one is found): "
                  + ", ".join(d["undiagnosed"]), ""]
    return lines


WIDTH_CASES = (("base_bin1", 1.0), ("base_bin0p5", 0.5), ("base_bin0p25", 0.25))
WIDTH_WINDOW = (0.17, 0.33)  # the shock's life after formation (claim C3)


def width_section(results):
    """The shock width against the MD bin: the paper's definition (T maximum to T minimum, a
    whole number of bins) and the fitted front's (docs/analysis.md), each over xi, with their
    jackknife errors over the sampled cycles."""
    lines = ["## Shock width against the MD bin (base case, 40 sampled cycles)", "",
             "d/xi by the paper's definition (T maximum to T minimum: a whole number of bins) "
             "and by the fitted tanh front (maximum-slope thickness, docs/analysis.md), with "
             "jackknife errors over the sampled cycles; – where no shock or no resolved fit.",
             ""]
    tables = {}
    for case, bin_height in WIDTH_CASES:
        table = results.analysis_with_errors(case, "md")
        if table:
            tables[bin_height] = table
    if not tables:
        return lines + [missing_text(results, [(c, "md") for c, _ in WIDTH_CASES]), ""]
    first = next(iter(tables.values()))[0]
    phases = [p for p in first["phase"] if WIDTH_WINDOW[0] - 1e-9 <= p <= WIDTH_WINDOW[1] + 1e-9]
    lines += rc.table_head([rc.analysis_header("f t", "phase")] + [
        header for b in tables
        for header in (rc.analysis_header(f"bin {b:g} sigma: paper d/xi", "width_over_mfp"),
                       rc.analysis_header(f"bin {b:g} sigma: fitted d/xi",
                                          "front_width_over_mfp"))])
    for phase in phases:
        cells = []
        for values, errors in tables.values():
            k = nearest(values["phase"], phase)
            cells += [value_text(values["width_over_mfp"][k], errors["width_over_mfp"][k]),
                      value_text(values["front_width_over_mfp"][k],
                                 errors["front_width_over_mfp"][k])]
        lines.append(f"| {phase:.2f} | " + " | ".join(cells) + " |")
    return lines + [""]


def sampling_section(results):
    """The shock quantities of each resampled MD case at its own and at the finer phase
    sampling (granular_shaker.validation.phase_sampling), with their jackknife errors."""
    entries = results.data.get("sampling", [])
    lines = ["## Shock quantities against the phase sampling (MD)", "",
             "The same MD runs (same seeds) stored at two phase samplings; a quantity agrees "
             "when |difference| is within the stated number of combined standard errors "
             "(granular_shaker.validation.phase_sampling). – where the run has no shock.", ""]
    if not entries:
        return lines + ["Not run (a quick study, or no case of studies.toml [sampling]).", ""]
    lines += [f"Agreement within {entries[0]['agreement']:g} combined standard errors.", ""]
    disagreeing = [f"{e['case']} {r['quantity']}" for e in entries for r in e.get("rows", [])
                   if r["agrees"] is False]
    lines += rc.table_head(["case", "quantity", "units", "phases per cycle", "coarse", "fine",
                            "|diff| / combined error", "agrees"])
    for e in entries:
        if e["status"] != "ok":
            lines.append(f"| {e['case']} | – | | | {e['status']} | | | |")
            continue
        for r in e["rows"]:
            units = rc.units_of(rc.ANALYSIS_UNITS, r["quantity"], "analysis quantity")
            agrees = {True: "yes", False: "**no**", None: "–"}[r["agrees"]]
            lines.append(f"| {e['case']} | {r['quantity']} | {units} | {e['phases'][0]} / "
                         f"{e['phases'][1]} | {value_text(*r['coarse'])} | "
                         f"{value_text(*r['fine'])} | {fmt(r['ratio'], 2)} | {agrees} |")
    summary = (f"{len(disagreeing)} quantities disagree: {', '.join(disagreeing)}" if disagreeing
               else "every measured quantity agrees")
    return lines + ["", summary + ".", ""]


def metrics_section(results):
    lines = ["## Agreement metrics (continuum against MD as reference)", ""]
    metrics = results.data["metrics"]
    if not metrics:
        return lines + ["No case has finished runs of both solvers.", ""]
    names = sorted({k for m in metrics.values() for k in m})
    declared = results.data.get("metric_units", {})
    lines += rc.table_head(["metric", rc.UNITS_COLUMN] + list(metrics))
    for name in names:
        # The "error" row holds why `shaker compare` failed for a case: text, not a quantity.
        units = "" if name == "error" else rc.units_of(declared, name, "comparison metric")
        lines.append(f"| {name} | {units} | " + " | ".join(fmt(m.get(name)) if not isinstance(
            m.get(name), str) else m[name] for m in metrics.values()) + " |")
    return lines + [""]


def header(results, counts):
    d = results.data
    lines = ["# Validation: MD against continuum against the paper", "",
             "Bougie, Moon, Swift and Swinney, Phys. Rev. E 66, 051301 (2002); its claims as data "
             "in reference-data/claims.toml. Written by granular_shaker.reports."
             "make_validation_report from the validation study (shaker-validation).", "",
             f"- commit: {d['commit']}{' (with uncommitted changes)' if d['dirty'] else ''}",
             f"- date: {d['date']}", f"- program: {d['shaker_version']}",
             f"- mode: {'quick (reduced cycles and resolution)' if d['quick'] else 'full study'}"
             f"; cases: {', '.join(d['cases'])}",
             f"- wall time of this validation: {d['wall_seconds']:.0f} s; solver time of the "
             f"runs started now: {d['simulated_seconds']:.0f} s",
             "- claims: " + ", ".join(f"{v} {k}" for k, v in sorted(counts.items())), ""]
    cps = [f"{v['case']}: {v['collisions_per_second']:.3g}" for v in d["views"].values()
           if v.get("collisions_per_second")]
    lines += ["- MD collisions per second: " + (", ".join(cps) if cps else
                                                "not available (needs a cumulative `collisions`"
                                                " time-series column and a fresh run)"), ""]
    lines += rc.table_head(["case", "solver", "replicas", "status", rc.with_units("seconds", "s"),
                            "reused", "program"])
    for r in d["runs"]:
        status = r["status"] + (f" (with {', '.join(r['fallback'])})" if r.get("fallback")
                                else "")
        lines.append(f"| {r['case']} | {r['solver']} | "
                     f"{r.get('replicas', 1)} | {status} | "
                     f"{r['seconds']:.1f} | {'yes' if r['reused'] else 'no'} | "
                     f"{(r.get('program') or '')[:10]} |")
    return lines + [""]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--results", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--gci",
                        help="GCI table of the real-problem grid study (default: "
                             f"{GCI_TABLE} of the repository, where the convergence report "
                             "copies it)")
    add_repository_option(parser)
    args = parser.parse_args(argv)
    repository = repository_argument(parser, args)
    results = Results(args.results, args.gci or os.path.join(repository, GCI_TABLE),
                      repository)
    out_dir = os.path.splitext(args.output)[0]
    link = os.path.basename(out_dir)
    body = []
    try:
        for section in (fig1_section, fig2_section, fig3_section, fig4_section, fig5_section,
                        fig6_section, fig7_section):
            body += section(results, out_dir, link)
        claims, counts = claims_section(results)
        text = header(results, counts) + body + claims + diagnoses_section(results) \
            + width_section(results) + sampling_section(results) + metrics_section(results)
    except rc.UnknownUnits as unknown:
        print(f"make_validation_report: {unknown}", file=sys.stderr)
        return 2
    tmp = args.output + ".partial"
    with open(tmp, "w") as f:
        f.write("\n".join(text) + "\n")
    os.replace(tmp, args.output)
    print(f"report: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
