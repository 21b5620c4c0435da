"""ctest reports.benchmark_report: granular_shaker.reports.make_benchmark_report on synthetic
Google Benchmark JSON.

Two runs of three benchmarks with 9 repetitions each: one
20% slower, one 20% faster, one unchanged (seeded noise). Checks the throughput rows per
commit, the comparison rows and verdicts, the exit code and the benchmark named on stderr,
the threshold option, the units in the table headers (a throughput counter without declared
units is refused), the Mann-Whitney U implementation against brute-force enumeration, and bad
input.
"""
import itertools
import json
import math
import os
import subprocess

import numpy as np
import pytest

from granular_shaker.reports import make_benchmark_report as mbr

from .. import harness_command, package_environment


def google_benchmark_json(commit, benchmarks, rng):
    """benchmarks: {name: (median time in ns, counter name or None, work per iteration)}"""
    entries = []
    for name, (time_ns, counter, work) in benchmarks.items():
        times = time_ns * (1.0 + 0.01 * rng.standard_normal(9))
        for k, t in enumerate(times):
            entry = {"name": name, "family_index": 0, "per_family_instance_index": 0,
                     "run_name": name, "run_type": "iteration", "repetitions": 9,
                     "repetition_index": k, "threads": 1, "iterations": 100,
                     "real_time": t / 1e3, "cpu_time": t / 1e3 * 0.99, "time_unit": "us"}
            if counter and counter.startswith("bytes_per_"):
                entry[counter] = work  # a memory benchmark: `work` is its bytes per item
            elif counter:
                entry[counter] = work / (t * 1e-9)
            entries.append(entry)
        for aggregate in ("mean", "median", "stddev", "cv"):
            entries.append({"name": f"{name}_{aggregate}", "run_name": name,
                            "run_type": "aggregate", "aggregate_name": aggregate,
                            "real_time": 1.0, "cpu_time": 1.0, "time_unit": "us"})
    return {"context": {"date": "2026-11-22T03:00:00+00:00", "host_name": "synthetic",
                        "num_cpus": 2, "library_build_type": "release", "commit": commit},
            "benchmarks": entries}


def write_run(history, run_id, commit, benchmarks, seed):
    rng = np.random.default_rng(seed)
    os.makedirs(os.path.join(history, run_id))
    document = google_benchmark_json(commit, benchmarks, rng)
    with open(os.path.join(history, run_id, "bench_all.json"), "w") as f:
        json.dump(document, f)


def run(*args):
    """The report made as users make it: its command run in a process of its own."""
    return subprocess.run(harness_command("reports.make_benchmark_report", *args),
                          capture_output=True, text=True, env=package_environment())


def line_with(text, *fragments):
    return next((line for line in text.splitlines() if all(f in line for f in fragments)), "")


# ---- Mann-Whitney U against enumeration and hand values ------------------------------------
def brute_force_p(x, y):
    pooled = list(x) + list(y)
    n1 = len(x)
    observed = sum((a > b) + 0.5 * (a == b) for a in x for b in y)
    mean = n1 * len(y) / 2.0
    count = total = 0
    for subset in itertools.combinations(range(len(pooled)), n1):
        chosen = set(subset)
        u = sum((pooled[i] > pooled[j])
                for i in chosen for j in range(len(pooled)) if j not in chosen)
        total += 1
        count += abs(u - mean) >= abs(observed - mean) - 1e-12
    return count / total


def test_mann_whitney_u_against_enumeration_and_hand_values():
    x = [0.3, 1.2, 2.5, 4.1, 0.7]
    y = [1.0, 3.3, 2.2, 5.0, 4.4, 6.1]
    u, p, method = mbr.mann_whitney_u(x, y)
    assert method == "exact" and u == 6.0, f"U = {u} ({method}), expected 6 exact"
    assert abs(p - brute_force_p(x, y)) < 1e-12, \
        f"exact p {p} vs enumeration {brute_force_p(x, y)}"
    assert abs(mbr.mann_whitney_u([1, 2, 3], [4, 5, 6])[1] - 0.1) < 1e-15, \
        "3 vs 3 separated: p = 2/20"
    # 9 vs 9 fully separated, normal approximation: z = (40.5 - 0.5) / sqrt(81 * 19 / 12).
    p9 = mbr.mann_whitney_u(range(1, 10), range(10, 19))[1]
    assert (abs(p9 - math.erfc(40.0 / math.sqrt(128.25) / math.sqrt(2.0))) < 1e-15
            and 4.0e-4 < p9 < 4.3e-4), \
        f"9 vs 9 separated: p = {p9}"
    tied = mbr.mann_whitney_u([1, 1, 2, 5, 7, 7, 8, 9, 9], [2, 3, 3, 4, 6, 6, 10, 11, 12])
    tied_swapped = mbr.mann_whitney_u([2, 3, 3, 4, 6, 6, 10, 11, 12], [1, 1, 2, 5, 7, 7, 8, 9, 9])
    assert tied[2] == "asymptotic" and abs(tied[1] - tied_swapped[1]) < 1e-15 and 0 < tied[1] < 1, \
        f"tied samples: {tied} vs swapped {tied_swapped}"


# ---- The report on a synthetic history ------------------------------------------------------
def test_report_on_a_synthetic_history(work_dir):
    work = work_dir
    history = os.path.join(work, "history")
    before = {"BM_md_collisions": (2.0e6, "collisions_per_second", 2000.0),
              "BM_continuum_step": (5.0e5, "cell_updates_per_second", 1.0e4),
              "BM_unchanged": (1.0e5, None, 0.0),
              "BM_memory": (3.0e6, "bytes_per_cell", 565.0),
              "BM_memory_grows": (3.0e6, "bytes_per_cell", 565.0)}
    after = {"BM_md_collisions": (2.4e6, "collisions_per_second", 2000.0),   # 20% slower
             "BM_continuum_step": (4.0e5, "cell_updates_per_second", 1.0e4),  # 20% faster
             "BM_unchanged": (1.0e5, None, 0.0),
             "BM_memory": (1.2e8, "bytes_per_cell", 565.0),          # 40x the time, same bytes
             "BM_memory_grows": (3.0e6, "bytes_per_cell", 700.0)}    # same time, 24% more bytes
    write_run(history, "20261120T030000Z-aaaaaaaaaaaa", "a" * 40, before, seed=1)
    write_run(history, "20261121T030000Z-bbbbbbbbbbbb", "b" * 40, after, seed=2)
    out = os.path.join(work, "out", "benchmarks.md")
    result = run("--history", history, "--output", out)
    assert result.returncode == 1, f"a 20% slowdown must exit 1, got {result.returncode}"
    assert ("BM_md_collisions" in result.stderr and "BM_continuum_step" not in result.stderr
            and "BM_unchanged" not in result.stderr and "BM_memory:" not in result.stderr
            and "BM_memory_grows: bytes_per_cell +23.9%" in result.stderr), \
        f"stderr must name the slow one and the grown one: {result.stderr}"
    check_report(open(out).read() if os.path.exists(out) else "", work)
    check_options_and_refusals(work, history, before)


def check_report(text, work):
    """The report of the two runs: throughputs per commit, units in the headers, the slowdown,
    the faster and the unchanged benchmark, memory judged by its bytes, the history plot."""
    assert "### collisions per second" in text and "### cell updates per second" in text, \
        "throughput sections missing"
    # 2000 collisions per 2 ms = 1e6 /s before, 8.333e5 /s after (medians, 1% noise).
    row_a = line_with(text, "| 20261120T030000Z-aaaaaaaaaaaa | aaaaaaaaaa | ")
    row_b = line_with(text, "| 20261121T030000Z-bbbbbbbbbbbb | bbbbbbbbbb | ")
    assert row_a != "" and row_b != "", "per-commit throughput rows missing"
    try:
        a = float(row_a.split("|")[3])
        b = float(row_b.split("|")[3])
        assert abs(a / 1e6 - 1) < 0.02 and abs(b / 8.3333e5 - 1) < 0.02, \
            f"collisions/s medians {a}, {b} (expected 1e6, 8.33e5)"
    except (IndexError, ValueError):
        pytest.fail(f"throughput rows unreadable: '{row_a}', '{row_b}'")
    # Units in the headers: a rate per real second, times per iteration in ns.
    assert line_with(text, "| run | commit | BM_md_collisions (collisions_per_second) [1/s] |"), \
        "collisions-per-second header lacks its units [1/s]"
    assert line_with(text, "| run | commit | BM_continuum_step (cell_updates_per_second) "
                     "[1/s] |"), \
        "cell-updates-per-second header lacks its units [1/s]"
    assert line_with(text, "| benchmark | previous [ns] | latest [ns] | change [%] | "
                     "cpu time change [%] | p (Mann-Whitney U) [1] | verdict |"), \
        "comparison header lacks its units"
    slow = line_with(text, "| BM_md_collisions |", "%")
    fast = line_with(text, "| BM_continuum_step |", "%")
    same = line_with(text, "| BM_unchanged |", "%")

    def change_of(row):
        try:
            return float(row.split("|")[4].strip().rstrip("%"))
        except (IndexError, ValueError):
            return float("nan")
    assert "**SLOWDOWN**" in slow and 17 < change_of(slow) < 23, f"slowdown row: '{slow}'"
    assert "faster" in fast and -23 < change_of(fast) < -17 and "SLOWDOWN" not in fast, \
        f"faster row: '{fast}'"
    assert "SLOWDOWN" not in same and "faster" not in same, f"unchanged row: '{same}'"
    assert "- BM_md_collisions: median real_time +" in text, "slowdown list missing"
    # A memory benchmark is judged by its bytes, not by the time it takes to allocate them.
    memory = line_with(text, "| BM_memory |")
    grows = line_with(text, "| BM_memory_grows |")
    assert ("memory only: bytes_per_cell 565 -> 565" in memory and "SLOWDOWN" not in memory
            and "+0.0%" in memory), f"memory row: '{memory}'"
    assert "**MEMORY GROWTH** (> 10%): bytes_per_cell 565 -> 700" in grows and "+23.9%" in grows, \
        f"memory growth row: '{grows}'"
    png = os.path.join(work, "out", "benchmark-history.png")
    assert os.path.exists(png) and open(png, "rb").read(4) == b"\x89PNG", "history plot missing"


def check_options_and_refusals(work, history, before):
    """--threshold and --metric change the verdict; a single run has nothing to compare; a
    counter without units and a history of bad JSON are refused (exit 2, nothing written)."""
    relaxed = run("--history", history, "--output", os.path.join(work, "relaxed.md"),
                  "--threshold", "0.25")
    assert relaxed.returncode == 0, \
        f"--threshold 0.25 must accept a 20% slowdown, got {relaxed.returncode}"
    relaxed_row = line_with(open(os.path.join(work, "relaxed.md")).read(),
                            "| BM_md_collisions |", "%")
    assert "significant change within 25%" in relaxed_row, f"relaxed row: '{relaxed_row}'"

    cpu = run("--history", history, "--output", os.path.join(work, "cpu.md"),
              "--metric", "cpu_time")
    assert cpu.returncode == 1 and "median cpu_time +" in cpu.stderr, \
        f"--metric cpu_time must judge CPU time: exit {cpu.returncode}, {cpu.stderr.strip()}"

    single = os.path.join(work, "single")
    write_run(single, "20261120T030000Z-aaaaaaaaaaaa", "a" * 40, before, seed=3)
    result = run("--history", single, "--output", os.path.join(work, "single.md"))
    assert (result.returncode == 0
            and "nothing to compare" in open(os.path.join(work, "single.md")).read()), \
        "a single run must report nothing to compare and exit 0"

    # A throughput counter without declared units is refused, not shown with a blank.
    undeclared = os.path.join(work, "undeclared")
    write_run(undeclared, "20261120T030000Z-aaaaaaaaaaaa", "a" * 40,
              {"BM_md_steps": (2.0e6, "collisions_per_step", 2000.0)}, seed=4)
    result = run("--history", undeclared, "--output", os.path.join(work, "undeclared.md"))
    assert (result.returncode == 2 and "'collisions_per_step'" in result.stderr
            and not os.path.exists(os.path.join(work, "undeclared.md"))), \
        f"a counter without units: exit {result.returncode}, {result.stderr.strip()}"

    broken = os.path.join(work, "broken", "20261120T030000Z-x")
    os.makedirs(broken)
    with open(os.path.join(broken, "bench.json"), "w") as f:
        f.write("{not json")
    result = run("--history", os.path.dirname(broken), "--output", os.path.join(work, "broken.md"))
    assert result.returncode == 2 and not os.path.exists(os.path.join(work, "broken.md")), \
        f"bad JSON: exit {result.returncode}"


def test_report_keeps_the_sections_measured_by_hand(work_dir):
    history = os.path.join(work_dir, "history")
    write_run(history, "20261120T030000Z-aaaaaaaaaaaa", "a" * 40,
              {"BM_continuum_step": (5.0e5, "cell_updates_per_second", 1.0e4)}, seed=4)
    out = os.path.join(work_dir, "benchmarks.md")
    hand = "## Ranks (measured by hand)\n\n| ranks | rate |\n| 2 | 7 |\n"
    with open(out, "w") as f:
        f.write("# Benchmark report\n\n## Old generated section\n\nstale\n\n" + hand)
    assert run("--history", history, "--output", out).returncode == 0
    text = open(out).read()
    assert text.rstrip().endswith(hand.rstrip()) and "stale" not in text, \
        f"the hand-measured section must survive, the generated one be replaced:\n{text}"
