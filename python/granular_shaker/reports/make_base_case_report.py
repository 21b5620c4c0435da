"""Writes the base-case report (markdown + PNG plots) from the run files of ci/base-case.sh.

    shaker-base-case-report --runs DIR --output DIR/base-case.md [--status SOLVER=ok:MS ...]

(or `python3 -m granular_shaker.reports.make_base_case_report ...`).

Reads only files: <runs>/<solver>.h5 (the HDF5 run-file schema of docs/output-schema.md),
<runs>/<solver>-analysis.csv (written by `shaker analyze --csv`, so the analysis is the
project's one C++ implementation) and <runs>/<solver>.log (the run's log: what the solver
showed, after its configuration).
"""
import argparse
import datetime
import os
import re
import platform
import sys
import tomllib

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from granular_shaker.reports import report_common as rc  # noqa: E402

SOLVERS = ("md", "continuum")
FIGURE_PHASES = (0.0, 0.15, 0.22, 0.40)  # the phases of the paper's Fig. 1
# The per-phase table: its header labels and the `shaker analyze --csv` columns they show.
PHASE_TABLE_COLUMNS = (("f t", "phase"), ("plate", "plate_z"), ("layer bottom", "layer_bottom"),
                       ("layer top", "layer_top"), ("centre of mass", "center_of_mass"),
                       ("shock", "shock_location"), ("d", "shock_width"),
                       ("d/xi", "width_over_mfp"), ("max Ma", "max_mach"))


def read_run(path):
    with h5py.File(path, "r") as f:
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
        profiles = {k: np.array(f["profiles"][k]) for k in f["profiles"]}
    return attrs, profiles


def resolution(attrs):
    """The run's spatial resolution as its configuration records it: the continuum's cell
    size, or the MD's sampling bin height (ci/base-case.sh runs the continuum at a coarser cell
    than the case file's, for speed)."""
    config = tomllib.loads(attrs.get("configuration", ""))
    if attrs.get("solver") == "continuum":
        return f"cell {config['continuum']['cell_size']:g} sigma"
    return f"bins {config['md']['bin_height']:g} sigma"


def terminal_part(log):
    """What the run showed on the terminal: its log after the header and the configuration
    (docs/output-schema.md, the log)."""
    with open(log) as f:
        text = f.read()
    shown = text.split("# ---- terminal ----\n", 1)[-1].splitlines()
    progress = re.compile(r"^shaker \w+: cycle \d+ of \d+, ")
    return "\n".join(line for line in shown if not progress.match(line)).strip()


def read_analysis(path):
    return rc.read_shaker_csv(path)[0]


def nearest(phases, target):
    return int(np.argmin(np.abs(((phases - target + 0.5) % 1.0) - 0.5)))


def figure_profiles(runs):
    """nu and T against height above the plate at the phases of the paper's Fig. 1."""
    fig, axes = plt.subplots(2, len(FIGURE_PHASES), figsize=(14, 7.5), sharey=True)
    for col, phase in enumerate(FIGURE_PHASES):
        for solver, (attrs, prof) in runs.items():
            k = nearest(prof["phase"], phase)
            z = prof["z"][k] - prof["plate_z"][k]
            errors = rc.profile_errors(prof, k)
            rc.draw_profile(axes[0, col], solver, prof["nu"][k], z, errors["nu"])
            rc.draw_profile(axes[1, col], solver, prof["T"][k], z, errors["T"])
        axes[0, col].set_title(f"f t = {phase:.2f}")
        axes[0, col].set_xlabel("volume fraction nu [1]")
        axes[1, col].set_xlabel("temperature T [g sigma]")
    for row in range(2):
        axes[row, 0].set_ylabel("height above the plate [sigma]")
        axes[row, 0].set_ylim(0, 40)
    rc.legend_above(fig)
    return fig


def figure_trajectories(analyses):
    """Centre of mass, shock location and plate over a cycle (lab frame), MD with the
    analysis' standard errors where its table has them (`shaker analyze --csv`: _error
    columns)."""
    fig, ax = plt.subplots(figsize=(7, 5))
    for solver, a in analyses.items():
        name = "MD" if solver == "md" else solver
        for column, what, style in (("center_of_mass", "centre of mass", {}),
                                    ("shock_location", "shock", dict(marker="^", ls="none"))):
            error = a[column + "_error"] if column + "_error" in a else None
            rc.draw_series(ax, solver, a["phase"], a[column], error,
                           label=f"{name} {what}", **style)
    plate = next(iter(analyses.values()))
    ax.plot(plate["phase"], plate["plate_z"], "k:", lw=1, label="plate")
    ax.set_xlabel("phase f t [1]")
    ax.set_ylabel("height z, lab frame [sigma]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def fmt(x, digits=3):
    return "-" if not np.isfinite(x) else f"{x:.{digits}f}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--status", nargs="*", default=[],
                        help="solver=ok:milliseconds or solver=unavailable:0")
    args = parser.parse_args(argv)

    status = dict(s.split("=", 1) for s in args.status)
    runs, analyses = {}, {}
    for solver in SOLVERS:
        h5 = os.path.join(args.runs, f"{solver}.h5")
        if status.get(solver, "").startswith("ok") and os.path.exists(h5):
            runs[solver] = read_run(h5)
            analyses[solver] = read_analysis(os.path.join(args.runs, f"{solver}-analysis.csv"))

    out_dir = os.path.dirname(os.path.abspath(args.output))
    lines = ["# Base case: Gamma = 3, f = 0.095, e = 0.9, H = 9", ""]
    commit = next((a["git_commit"] for a, _ in runs.values()), "no run")
    lines += [f"- date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M UTC}",
              f"- machine: {platform.node()} ({platform.machine()}, {os.cpu_count()} cores)",
              f"- commit: {commit}", ""]
    lines += rc.table_head(["solver", "status", rc.with_units("wall time", "s"), "model variant",
                            "resolution"])
    for solver in SOLVERS:
        state, _, ms = status.get(solver, "not run:0").partition(":")
        variant = runs[solver][0].get("model_variant", "") if solver in runs else ""
        shown = {"ok": "ran", "unavailable": "not implemented yet"}.get(state, state)
        lines.append(f"| {solver} | {shown} | {int(ms) / 1000:.1f} | {variant} | "
                     f"{resolution(runs[solver][0]) if solver in runs else ''} |")
    lines.append("")
    for solver in SOLVERS:
        log = os.path.join(args.runs, f"{solver}.log")
        if solver in runs and os.path.exists(log):
            lines += [f"## {solver} run summary", "", "```", terminal_part(log), "```", ""]
    if runs:
        profiles = rc.write_figure(figure_profiles(runs), out_dir, "base-case-profiles.png")
        trajectories = rc.write_figure(figure_trajectories(analyses), out_dir,
                                       "base-case-trajectories.png")
        lines += ["## Profiles at the phases of the paper's Fig. 1", "",
                  f"![nu and T]({profiles})", "",
                  "## Centre of mass and shock location over a cycle", "",
                  f"![trajectories]({trajectories})", ""]
        for solver, a in analyses.items():
            lines += [f"## {solver}: analysis per phase (every fifth stored phase)", ""]
            lines += rc.table_head([rc.analysis_header(label, column)
                                    for label, column in PHASE_TABLE_COLUMNS])
            for k in range(0, len(a["phase"]), 5):
                lines.append("| " + " | ".join(fmt(a[column][k])
                                               for _, column in PHASE_TABLE_COLUMNS) + " |")
            lines.append("")
    else:
        lines += ["No solver is available yet, so there is nothing to plot.", ""]
    with open(args.output + ".partial", "w") as f:
        f.write("\n".join(lines))
    os.replace(args.output + ".partial", args.output)


if __name__ == "__main__":
    sys.exit(main())
