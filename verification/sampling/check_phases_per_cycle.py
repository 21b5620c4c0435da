"""The MD base case stored at two phase samplings gives the same shock quantities.

Runs `shaker md CASE` at run.phases_per_cycle = 50 and 100 with the same seed (the same
trajectory: the stored phases only add snapshots), analyses both with `shaker analyze --json`
and checks that every per-run shock quantity agrees as granular_shaker.validation.phase_sampling
judges it (within two combined standard errors of the two runs). Prints the table. Usage:

    check_phases_per_cycle.py SHAKER CASE.toml [--phases 50 100] [--keep DIR]
"""
import argparse
import json
import os
import subprocess
import sys

import keep_on_failure
from granular_shaker.validation import phase_sampling


def analysed(shaker, case, phases, work):
    run = os.path.join(work, f"run_{phases}.h5")
    out = os.path.join(work, f"analysis_{phases}.json")
    subprocess.run([shaker, "md", case, "--quiet", "--set", f"run.phases_per_cycle={phases}",
                    "--set", f"run.output={run}"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([shaker, "analyze", run, "--quiet", "--json", out], check=True)
    with open(out) as f:
        return json.load(f)["per_run"]


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
    pairs = [{k: (v["value"], v["error"]) for k, v in run.items()} for run in (a, b)]
    for row in phase_sampling.compare(*pairs):
        (va, ea), (vb, eb) = row["coarse"], row["fine"]
        print(f"{row['quantity']:>22} {va:>10.4g}({ea:.2g}) {vb:>10.4g}({eb:.2g}) "
              f"{row['ratio']:>16.2f}")
        if not row["agrees"]:
            problems.append(f"{row['quantity']}: {va} +- {ea} against {vb} +- {eb}")
    for p in problems:
        print(f"differs by more than {phase_sampling.AGREEMENT} combined standard errors:", p)
    return keep_on_failure.finish(work, problems, "every shock quantity agrees")


if __name__ == "__main__":
    sys.exit(main())
