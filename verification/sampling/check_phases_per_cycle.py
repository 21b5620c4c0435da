"""The MD base case stored at two phase samplings gives the same shock quantities.

Runs `shaker md CASE` at run.phases_per_cycle = 50 and 100 with the same seed (the same
trajectory: the stored phases only add snapshots), analyses both with `shaker analyze --json`
and checks that every per-run shock quantity agrees within twice the combined standard error
of the two runs. Prints the table. Usage:

    check_phases_per_cycle.py SHAKER CASE.toml [--phases 50 100] [--keep DIR]
"""
import argparse
import json
import math
import os
import subprocess
import sys

import keep_on_failure

QUANTITIES = ["formation_phase", "exit_phase", "lifetime", "shock_speed", "shock_width_mean",
              "width_over_mfp_mean", "max_mach_peak"]


def analysed(shaker, case, phases, work):
    run = os.path.join(work, f"run_{phases}.h5")
    out = os.path.join(work, f"analysis_{phases}.json")
    subprocess.run([shaker, "md", case, "--quiet", "--set", f"run.phases_per_cycle={phases}",
                    "--set", f"run.output={run}"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([shaker, "analyze", run, "--quiet", "--json", out], check=True)
    with open(out) as f:
        return json.load(f)["per_run"]


def number(x):
    return float("nan") if x is None else float(x)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("shaker")
    parser.add_argument("case")
    parser.add_argument("--phases", type=int, nargs=2, default=[50, 100])
    args = parser.parse_args()
    work = keep_on_failure.work_folder("shaker-phases-per-cycle-")
    a, b = (analysed(args.shaker, args.case, p, work) for p in args.phases)
    problems = []
    print(f"{'quantity':>22} {args.phases[0]:>18} {args.phases[1]:>18} {'|diff|/combined':>16}")
    for name in QUANTITIES:
        va, ea = number(a[name]["value"]), number(a[name]["error"])
        vb, eb = number(b[name]["value"]), number(b[name]["error"])
        combined = math.hypot(ea, eb)
        ratio = abs(va - vb) / combined if combined > 0 else float("nan")
        print(f"{name:>22} {va:>10.4g}({ea:.2g}) {vb:>10.4g}({eb:.2g}) {ratio:>16.2f}")
        if not ratio <= 2.0:
            problems.append(f"{name}: {va} +- {ea} against {vb} +- {eb}")
    for p in problems:
        print("differs by more than 2 combined standard errors:", p)
    return keep_on_failure.finish(work, problems, "every shock quantity agrees")


if __name__ == "__main__":
    sys.exit(main())
