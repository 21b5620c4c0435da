#!/usr/bin/python3
"""ctest: reports/make_convergence_report.py on a small synthetic study in a temp directory.

Argument: the reports/ directory. Checks the provenance header, the order and GCI rows with
their pass/fail marks (including a check whose file claims a pass its numbers contradict),
the failure summary with measured values, the PNG plot, --strict, and bad input.
"""
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

REPORTS = os.path.abspath(sys.argv[1])
SCRIPT = os.path.join(REPORTS, "make_convergence_report.py")
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message)


def write(path, header, rows):
    with open(path, "w") as f:
        f.write(header + "\n")
        for row in rows:
            f.write(",".join(str(x) for x in row) + "\n")


def synthetic_study(directory):
    study = "synthetic-1d-space"
    h = [0.1 / 2 ** k for k in range(4)]
    models = {"n": lambda x: 0.5 * x * x * (1 + 0.1 * x),
              "uz": lambda x: 2.0 * x * x * (1 - 0.2 * x),
              "T": lambda x: 0.3 * x}  # first order: must fail the second-order band
    scale = {"L1": 1.0, "L2": 1.3, "Linf": 2.1}
    errors, orders = [], []
    for field, model in models.items():
        for norm, s in scale.items():
            e = [s * model(x) for x in h]
            for level, (x, err) in enumerate(zip(h, e)):
                errors.append((study, field, norm, level, repr(x), repr(err)))
            slope, _ = np.polyfit(np.log(h[1:]), np.log(e[1:]), 1)
            pairs = [math.log(e[k] / e[k + 1]) / math.log(2.0) for k in range(3)]
            honest = all(abs(p - 2.0) <= 0.1 for p in (slope, pairs[2], pairs[1]))
            claimed = 1 if (field, norm) == ("T", "L2") else int(honest)  # one file lies
            orders.append((study, field, norm, 3, repr(slope), "0.001", repr(pairs[2]),
                           repr(pairs[1]), "2", "0.1", claimed))
    write(os.path.join(directory, "synthetic.errors.csv"), "study,field,norm,level,h,error", errors)
    write(os.path.join(directory, "synthetic.orders.csv"),
          "study,field,norm,fit_points,fitted_order,order_std_error,pair_order_finest,"
          "pair_order_next,design_order,tolerance,pass", orders)
    phi = [2.0 + 0.3 * x * x for x in (0.025, 0.05, 0.1)]
    gci_header = ("study,quantity,h1,h2,h3,phi1,phi2,phi3,order,phi_extrapolated,"
                  "relative_difference21,extrapolated_error21,gci21,gci32,asymptotic_ratio,"
                  "convergence,asymptotic_tolerance,pass")
    e21 = abs(phi[0] - phi[1]) / phi[0]
    gci21 = 1.25 * e21 / 3.0
    gci32 = 1.25 * abs(phi[1] - phi[2]) / phi[1] / 3.0
    ratio = gci32 / (4.0 * gci21)
    write(os.path.join(directory, "qoi.gci.csv"), gci_header, [
        ("base-1d", "shock_location", 0.025, 0.05, 0.1, *phi, 2.0, 2.0, e21, 0.0, gci21, gci32,
         ratio, "monotonic", 0.1, 1),
        ("base-1d", "max_mach", 0.025, 0.05, 0.1, 3.1, 3.0, 3.3, 1.5, 3.2, 0.032, 0.03, 0.05,
         0.4, 2.8, "oscillatory", 0.1, 0),
        ("base-3d", "shock_location", 0.5, 1.0, "nan", 1.01, 1.04, "nan", 2.0, 1.0, 0.0297, 0.01,
         0.0297, "nan", "nan", "two-grids", "nan", "nan")])


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


def line_with(text, *fragments):
    for line in text.splitlines():
        if all(f in line for f in fragments):
            return line
    return ""


work = tempfile.mkdtemp(prefix="shaker-convergence-report-")
try:
    inputs = os.path.join(work, "input")
    os.makedirs(os.path.join(inputs, "nested"))
    synthetic_study(inputs)
    shutil.move(os.path.join(inputs, "qoi.gci.csv"), os.path.join(inputs, "nested", "qoi.gci.csv"))
    out_dir = os.path.join(work, "out")
    report = os.path.join(out_dir, "convergence.md")

    result = run("--input", inputs, "--output", report, "--commit", "abc123def",
                 "--build-type", "Release")
    check(result.returncode == 0, f"exit code {result.returncode} without --strict: {result.stderr}")
    text = open(report).read() if os.path.exists(report) else ""
    for header in ("- commit: abc123def", "- date: ", "- machine: ", "- build type: Release"):
        check(header in text, f"header line '{header}' missing")
    check("11 checks: 7 pass, 4 fail." in text, "summary count line missing or wrong")

    for field in ("n", "uz"):
        for norm in ("L1", "L2", "Linf"):
            row = line_with(text, "| synthetic-1d-space | " + field + " | " + norm + " |")
            check(row.endswith("| PASS |"), f"{field} {norm} should pass: '{row}'")
            fitted = re.search(r"\| (\S+) ± ", row)
            check(fitted is not None and abs(float(fitted.group(1)) - 2.0) < 0.05,
                  f"{field} {norm} fitted order missing: '{row}'")
    t_l1 = line_with(text, "| synthetic-1d-space | T | L1 |")
    check("**FAIL**" in t_l1 and re.search(r"\| 1(\.0+)? ± ", t_l1) is not None,
          f"T L1 must fail showing its measured order 1: '{t_l1}'")
    t_l2 = line_with(text, "| synthetic-1d-space | T | L2 |")
    check("**FAIL**" in t_l2 and "file says pass" in t_l2, f"inconsistent pass not flagged: '{t_l2}'")
    check(line_with(text, "- order synthetic-1d-space / T / Linf: fitted 1") != "",
          "failure list lacks the measured value of T Linf")

    shock = line_with(text, "| base-1d | shock_location |")
    check("PASS" in shock and "FAIL" not in shock, f"GCI row should pass: '{shock}'")
    mach = line_with(text, "| base-1d | max_mach |")
    check("**FAIL**" in mach and "oscillatory" in mach and "| 2.8 |" in mach,
          f"GCI row should fail with ratio 2.8: '{mach}'")
    check(line_with(text, "GCI base-1d / max_mach: asymptotic ratio 2.8") != "",
          "GCI failure missing from the summary")

    two_grid = line_with(text, "| base-3d | shock_location |")
    check("not checked (two grids" in two_grid and "FAIL" not in two_grid,
          f"two-grid row must be shown but not checked: '{two_grid}'")

    errors_header = line_with(text, "| field | norm | h = 0.1 |")
    check("p(0-1)" in errors_header and "p(2-3)" in errors_header, "error table lacks pair orders")
    n_row = line_with(text, "| n | L1 | 0.00505 |")
    check(n_row != "", "error table row of n L1 missing")

    png = os.path.join(out_dir, "convergence-synthetic-1d-space.png")
    check(os.path.exists(png) and open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
          and os.path.getsize(png) > 5000, "PNG plot missing or not a PNG")
    check("![synthetic-1d-space](convergence-synthetic-1d-space.png)" in text, "plot not linked")
    leftovers = [f for f in os.listdir(out_dir) if f.startswith(".partial")]
    check(not leftovers, f"temporary files left: {leftovers}")

    strict = run("--input", inputs, "--output", os.path.join(work, "strict", "c.md"), "--strict")
    check(strict.returncode == 1, f"--strict with failures must exit 1, got {strict.returncode}")

    bad = os.path.join(work, "bad")
    os.makedirs(bad)
    write(os.path.join(bad, "x.errors.csv"), "study,field,norm,h,error", [("s", "n", "L1", 1, 1)])
    bad_report = os.path.join(work, "bad-out", "convergence.md")
    result = run("--input", bad, "--output", bad_report)
    check(result.returncode == 2 and "first line must be" in result.stderr,
          f"bad header: exit {result.returncode}, stderr '{result.stderr.strip()}'")
    check(not os.path.exists(bad_report), "a report was written from bad input")
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(failures)} failures")
sys.exit(1 if failures else 0)
