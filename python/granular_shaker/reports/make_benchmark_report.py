"""Writes reports/benchmarks.md (+ a PNG of the history) from a history of Google Benchmark runs.

Usage:
    shaker-benchmark-report --history DIR [--output reports/benchmarks.md] [--repository DIR]
                            [--threshold 0.10] [--alpha 0.05] [--metric real_time|cpu_time]

(or `python3 -m granular_shaker.reports.make_benchmark_report ...`).

History layout (ci/nightly appends to it): DIR/<run-id>/<program>.json, one directory per
nightly run, run ids sorting in time order (ci/nightly uses YYYYmmddTHHMMSSZ-<commit>). Each
JSON file is Google Benchmark output (--benchmark_format=json --benchmark_repetitions=N
--benchmark_context=commit=SHA): its `context` block gives the commit, date and host, its
`benchmarks` list one entry per repetition (run_type "iteration") plus aggregates, which are
ignored. User counters whose name contains "collision" are reported as collisions per second,
those containing "cell_update" (or "cell update", "cellupdate") as cell updates per second
(benchmark authors: make them rate counters, e.g. counters["collisions_per_second"] with
benchmark::Counter::kIsRate). Every such counter must have its units declared in
THROUGHPUT_UNITS: one without them is unreadable input. Tables give units in their headers
(times per iteration in ns, wall-clock rates per real second).

Comparison with the previous run: for every benchmark present in both runs, the real-time
samples (or CPU-time samples with --metric cpu_time; real time is what users wait for, CPU
time is less sensitive to other load on the machine) of the repetitions are compared by a
two-sided Mann-Whitney U test, as Google Benchmark's tools/compare.py does (implemented here
with numpy and the standard library: the exact distribution when a sample has at most 8 values
and there are no ties, otherwise the normal approximation with tie and continuity corrections,
as scipy's default). A benchmark whose median time grew by more than --threshold (a fraction,
default 0.10) with p < --alpha (default 0.05) is a slowdown: it is marked in the report, named
on stderr, and the exit code is 1. Exit code 2: unreadable input. Fewer than 2 repetitions on
either side cannot be judged and are reported as such.
"""
import argparse
import glob
import json
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from granular_shaker.repository import add_repository_option, repository_argument  # noqa: E402
from granular_shaker.reports import report_common as rc  # noqa: E402

TIME_UNIT_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
STANDARD_KEYS = {"name", "family_index", "per_family_instance_index", "run_name", "run_type",
                 "repetitions", "repetition_index", "threads", "iterations", "real_time",
                 "cpu_time", "time_unit", "aggregate_name", "aggregate_unit", "label",
                 "error_occurred", "error_message", "big_o", "rms"}
THROUGHPUT_KINDS = (("collisions per second", re.compile(r"collision", re.I)),
                    ("cell updates per second", re.compile(r"cell[ _]?update", re.I)))
# The units of the throughput counters the benchmarks report (verification/benchmarks):
# rates are per second of wall-clock time, real seconds; a count per shaker cycle is a number.
THROUGHPUT_UNITS = {
    "collisions_per_second": "1/s",
    "collisions_per_cycle": rc.DIMENSIONLESS,
    "cell_updates_per_second": "1/s",
}


class InputProblem(Exception):
    pass


# ---- Mann-Whitney U ------------------------------------------------------------------------

def _ranks(values):
    """Ranks 1..n with ties given their average rank; also the tie-group sizes."""
    order = np.argsort(values, kind="mergesort")
    ranks = np.empty(len(values))
    sorted_values = values[order]
    ties = []
    start = 0
    for end in range(1, len(values) + 1):
        if end == len(values) or sorted_values[end] != sorted_values[start]:
            ranks[order[start:end]] = 0.5 * (start + 1 + end)
            ties.append(end - start)
            start = end
    return ranks, np.array(ties)


def _exact_u_cdf(u, n1, n2):
    """P(U <= u) under the null hypothesis: counts of arrangements by the recursion
    c(m, n, k) = c(m - 1, n, k - n) + c(m, n - 1, k) (Mann and Whitney, 1947)."""
    # table[n] holds the counts for the current m, as a vector over k = 0..m n.
    table = [np.zeros(1) + 1.0 for _ in range(n2 + 1)]  # m = 0: one arrangement, U = 0
    for m in range(1, n1 + 1):
        new = [np.zeros(1) + 1.0]  # n = 0: one arrangement, U = 0
        for n in range(1, n2 + 1):
            counts = np.zeros(m * n + 1)
            shifted = table[n]  # c(m - 1, n, k - n)
            counts[n:n + len(shifted)] += shifted
            counts[:len(new[n - 1])] += new[n - 1]  # c(m, n - 1, k)
            new.append(counts)
        table = new
    counts = table[n2]
    return counts[:int(math.floor(u)) + 1].sum() / counts.sum()


def mann_whitney_u(x, y):
    """Two-sided Mann-Whitney U test. Returns (U of x, p-value, method)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    n1, n2 = len(x), len(y)
    if n1 == 0 or n2 == 0:
        return float("nan"), float("nan"), "none"
    ranks, ties = _ranks(np.concatenate([x, y]))
    u1 = ranks[:n1].sum() - n1 * (n1 + 1) / 2.0
    u2 = n1 * n2 - u1
    has_ties = bool((ties > 1).any())
    if min(n1, n2) <= 8 and not has_ties:
        p = min(1.0, 2.0 * _exact_u_cdf(min(u1, u2), n1, n2))
        return u1, p, "exact"
    n = n1 + n2
    mean = n1 * n2 / 2.0
    variance = n1 * n2 / 12.0 * ((n + 1) - (ties ** 3 - ties).sum() / (n * (n - 1)))
    if variance <= 0:
        return u1, 1.0, "asymptotic"
    z = (abs(u1 - mean) - 0.5) / math.sqrt(variance)
    p = min(1.0, math.erfc(max(z, 0.0) / math.sqrt(2.0)))
    return u1, p, "asymptotic"


# ---- Reading the history --------------------------------------------------------------------

def read_run(run_dir):
    """One run directory as {'id', 'commit', 'date', 'host', 'benchmarks': {run_name:
    {'real_time': [ns per repetition], 'cpu_time': [ns...], 'counters': {name: [...]}}}}."""
    run = {"id": os.path.basename(run_dir), "commit": "unknown", "date": "", "host": "",
           "benchmarks": {}}
    files = sorted(glob.glob(os.path.join(run_dir, "*.json")))
    for path in files:
        try:
            with open(path) as f:
                document = json.load(f)
        except (OSError, json.JSONDecodeError) as error:
            raise InputProblem(f"{path}: not Google Benchmark JSON ({error})")
        if not isinstance(document, dict) or "benchmarks" not in document:
            raise InputProblem(f"{path}: no 'benchmarks' list")
        context = document.get("context", {})
        run["commit"] = context.get("commit", run["commit"])
        run["date"] = context.get("date", run["date"])
        run["host"] = context.get("host_name", run["host"])
        for entry in document["benchmarks"]:
            if entry.get("run_type", "iteration") != "iteration" or entry.get("error_occurred"):
                continue
            name = entry.get("run_name", entry.get("name"))
            unit = TIME_UNIT_NS.get(entry.get("time_unit", "ns"))
            if name is None or unit is None or "real_time" not in entry:
                raise InputProblem(f"{path}: benchmark entry without name, time or known unit")
            record = run["benchmarks"].setdefault(name, {"real_time": [], "cpu_time": [],
                                                         "counters": {}})
            record["real_time"].append(float(entry["real_time"]) * unit)
            record["cpu_time"].append(float(entry.get("cpu_time", float("nan"))) * unit)
            for key, value in entry.items():
                if key not in STANDARD_KEYS and isinstance(value, (int, float)):
                    record["counters"].setdefault(key, []).append(float(value))
    return run if files else None


def read_history(directory):
    runs = []
    for run_dir in sorted(d for d in glob.glob(os.path.join(directory, "*")) if os.path.isdir(d)):
        run = read_run(run_dir)
        if run is not None:
            runs.append(run)
    return runs


# ---- Report ---------------------------------------------------------------------------------

def throughput_series(runs):
    """{kind: {(benchmark, counter): [median per run or nan]}}"""
    out = {}
    for kind, pattern in THROUGHPUT_KINDS:
        keys = sorted({(b, c) for run in runs for b, rec in run["benchmarks"].items()
                       for c in rec["counters"] if pattern.search(c)})
        for _, counter in keys:  # refused before anything is written
            try:
                rc.units_of(THROUGHPUT_UNITS, counter, "benchmark counter")
            except rc.UnknownUnits as unknown:
                raise InputProblem(f"{unknown}: declare them in THROUGHPUT_UNITS of "
                                   "granular_shaker/reports/make_benchmark_report.py") from None
        if keys:
            out[kind] = {key: [float(np.median(run["benchmarks"][key[0]]["counters"][key[1]]))
                               if key[0] in run["benchmarks"]
                               and key[1] in run["benchmarks"][key[0]]["counters"]
                               else float("nan") for run in runs] for key in keys}
    return out


def short(commit):
    return commit[:10] if commit else "unknown"


MEMORY_COUNTER = re.compile(r"^bytes_per_")


def memory_counter(record):
    """The bytes-per-item counter of a benchmark that measures memory only (no throughput
    counter), else None: its time is that of allocating and touching the memory, not a speed."""
    counters = record["counters"]
    if any(pattern.search(c) for c in counters for _, pattern in THROUGHPUT_KINDS):
        return None
    return next((c for c in sorted(counters) if MEMORY_COUNTER.search(c)), None)


def compare(previous, latest, threshold, alpha, metric):
    rows, slowdowns = [], []
    for name in sorted(set(previous["benchmarks"]) | set(latest["benchmarks"])):
        old = previous["benchmarks"].get(name)
        new = latest["benchmarks"].get(name)
        if old is None or new is None:
            rows.append(f"| {name} | | | | | | {'new' if old is None else 'removed'} |")
            continue
        counter = memory_counter(new)
        if counter is not None and counter in old["counters"]:
            # Judged by its memory, which is deterministic: any growth over the threshold counts.
            before, after = np.median(old["counters"][counter]), np.median(new["counters"][counter])
            change = float(after / before - 1.0)
            verdict = f"memory only: {counter} {rc.fmt(before, 5)} -> {rc.fmt(after, 5)}"
            if change > threshold:
                verdict = (f"**MEMORY GROWTH** (> {threshold:.0%}): "
                           + verdict[len("memory only: "):])
                slowdowns.append(f"{name}: {counter} {change:+.1%}")
            rows.append(f"| {name} | | | {change:+.1%} | | | {verdict} |")
            continue
        old_t, new_t = np.array(old[metric]), np.array(new[metric])
        change = float(np.median(new_t) / np.median(old_t) - 1.0)
        other = "cpu_time" if metric == "real_time" else "real_time"
        other_change = float(np.median(new[other]) / np.median(old[other]) - 1.0)
        if min(len(old_t), len(new_t)) < 2:
            verdict = f"not judged: {len(old_t)} and {len(new_t)} repetitions"
            p = float("nan")
        else:
            _, p, method = mann_whitney_u(old_t, new_t)
            significant = p < alpha
            if change > threshold and significant:
                verdict = f"**SLOWDOWN** (> {threshold:.0%}, p < {alpha:g})"
                slowdowns.append(f"{name}: median {metric} {change:+.1%} (p = {p:.2g}, "
                                 f"{len(old_t)} vs {len(new_t)} repetitions)")
            elif change < -threshold and significant:
                verdict = "faster"
            elif significant:
                verdict = f"significant change within {threshold:.0%}"
            else:
                verdict = "no significant change"
            verdict += f" [{method}]"
        rows.append(f"| {name} | {rc.fmt(np.median(old_t), 5)} | {rc.fmt(np.median(new_t), 5)} | "
                    f"{change:+.1%} | {other_change:+.1%} | {rc.fmt(p, 3)} | {verdict} |")
    return rows, slowdowns


def figure_history(runs, series):
    """One panel per counter (one quantity, its units on the axis), every benchmark that
    reports it against the runs; the median real time per iteration when no run has a
    throughput counter."""
    panels = {}
    for data in series.values():
        for (bench, counter), values in data.items():
            panels.setdefault(rc.with_units(counter.replace("_", " "),
                                            THROUGHPUT_UNITS[counter]), {})[bench] = values
    if not panels:
        names = sorted({n for r in runs for n in r["benchmarks"]})
        panels["median real time per iteration [ns]"] = {
            n: [float(np.median(r["benchmarks"][n]["real_time"])) if n in r["benchmarks"]
                else float("nan") for r in runs] for n in names}
    fig, axes = plt.subplots(len(panels), 1, figsize=(13, 3.4 * len(panels)), squeeze=False)
    x = np.arange(len(runs))
    labels = [short(r["commit"])[:7] for r in runs]
    for ax, (quantity, data) in zip(axes[:, 0], panels.items()):
        for k, (bench, values) in enumerate(data.items()):
            # Ten colours, then the next marker: every series is told apart.
            ax.plot(x, values, "-", marker="os^Dv"[k // 10 % 5], ms=4, label=bench)
        ax.set_ylabel(quantity)
        ax.set_xticks(x)
        ax.set_xticklabels(labels, rotation=45, fontsize=7)
        ax.set_xlabel("run (commit)")
        ax.grid(True, alpha=0.3)
        if data:  # beside the panel, never over its data
            ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    return fig


HAND_MEASURED = "(measured by hand)"


def hand_measured_sections(path):
    """The sections of the report at `path` whose heading ends in "(measured by hand)": figures
    no history holds (measurements under mpirun, for one), kept when the report is rewritten."""
    if not os.path.exists(path):
        return []
    kept, keeping = [], False
    with open(path) as f:
        for line in f.read().split("\n"):
            if line.startswith("## "):
                keeping = line.rstrip().endswith(HAND_MEASURED)
            if keeping:
                kept.append(line)
    return kept


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--history", required=True)
    parser.add_argument("--output", help="default: reports/benchmarks.md of the repository")
    parser.add_argument("--threshold", type=float, default=0.10,
                        help="relative slowdown that fails (fraction, default 0.10)")
    parser.add_argument("--alpha", type=float, default=0.05)
    parser.add_argument("--metric", choices=("real_time", "cpu_time"), default="real_time",
                        help="the time judged for slowdowns (both are shown)")
    add_repository_option(parser)
    args = parser.parse_args(argv)
    repository = repository_argument(parser, args)
    args.output = args.output or os.path.join(repository, "reports", "benchmarks.md")
    if not (args.threshold > 0 and 0 < args.alpha < 1):
        print("make_benchmark_report: need --threshold > 0 and 0 < --alpha < 1", file=sys.stderr)
        return 2
    if not os.path.isdir(args.history):
        print(f"make_benchmark_report: --history {args.history} is not a directory",
              file=sys.stderr)
        return 2
    try:
        runs = read_history(args.history)
        series = throughput_series(runs)
    except InputProblem as problem:
        print(f"make_benchmark_report: {problem}", file=sys.stderr)
        return 2

    out_dir = os.path.dirname(os.path.abspath(args.output))
    latest = runs[-1] if runs else None
    lines = ["# Benchmark report", "",
             f"- commit: {latest['commit'] if latest else 'no run'}",
             f"- date: {rc.utc_now()}",
             f"- machine: {rc.machine_description()}",
             f"- history: {rc.repository_path(args.history, repository)} ({len(runs)} runs)",
             f"- slowdown threshold: {args.threshold:.0%} in {args.metric} with Mann-Whitney "
             f"p < {args.alpha:g}", ""]
    slowdowns = []
    if not runs:
        lines += ["No benchmark runs found in the history.", ""]
    else:
        lines += ["## Throughput per commit (median over repetitions)", ""]
        if not series:
            lines += ["No collision or cell-update counters in these runs.", ""]
        for kind, data in series.items():
            keys = list(data)
            lines += [f"### {kind}", "",
                      "| run | commit | " + " | ".join(
                          rc.with_units(f"{b} ({c})", THROUGHPUT_UNITS[c]) for b, c in keys) + " |",
                      "|---|---" + "|---" * len(keys) + "|"]
            for k, run in enumerate(runs):
                lines.append(f"| {run['id']} | {short(run['commit'])} | " +
                             " | ".join(rc.fmt(data[key][k], 4) for key in keys) + " |")
            lines.append("")
        plot_name = "benchmark-history.png"
        rc.write_figure(figure_history(runs, series), out_dir, plot_name)
        lines += [f"![benchmark history]({plot_name})", ""]
        if len(runs) >= 2:
            previous = runs[-2]
            rows, slowdowns = compare(previous, latest, args.threshold, args.alpha, args.metric)
            lines += ["## Latest run against the previous one", "",
                      f"{previous['id']} ({short(previous['commit'])}) → {latest['id']} "
                      f"({short(latest['commit'])}); {args.metric.replace('_', ' ')} per "
                      "iteration in ns (medians over repetitions) judged; the other time's "
                      "change is shown beside it.", "",
                      f"| benchmark | previous [ns] | latest [ns] | change [%] | "
                      f"{'cpu' if args.metric == 'real_time' else 'real'} time change [%] | "
                      "p (Mann-Whitney U) [1] | verdict |",
                      "|---|---|---|---|---|---|---|"] + rows + [""]
        else:
            lines += ["Only one run in the history: nothing to compare with.", ""]
    if slowdowns:
        lines += ["## Slowdowns", ""] + [f"- {s}" for s in slowdowns] + [""]
    lines += hand_measured_sections(args.output)
    rc.write_text_atomically(args.output, "\n".join(lines))
    for s in slowdowns:
        print(f"make_benchmark_report: slowdown: {s}", file=sys.stderr)
    print(f"wrote {args.output}: {len(runs)} runs, {len(slowdowns)} slowdowns")
    return 1 if slowdowns else 0


if __name__ == "__main__":
    sys.exit(main())
