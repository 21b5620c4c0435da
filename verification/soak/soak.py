#!/usr/bin/python3
"""Soak run: one solver on a case for many cycles, then its invariants checked at every row of
the run file's time series (every stored phase of every cycle, transient included).

    soak.py --shaker PROGRAM --solver md|continuum --case FILE --cycles N [--set KEY=VALUE ...]
    soak.py --check-only RUN.h5 --solver md|continuum

The run goes in a fresh temporary directory, removed when every check passes and kept (its
path printed) when one fails. The cycles are run.transient_cycles = N - sampled and
run.sampled_cycles = sampled (at most 10: the sampled cycles' sums are kept in memory and in
the file, the time series covers every cycle either way).

MD invariants, each at every row:
  overlaps == 0          no pair closer than 1 - 1e-9 (the solver's own overlap count)
  energy_budget_relative_residual <= 1e-9
                         |energy change + loss - work| / max(|work|, |loss|, |energy|): the
                         bound `shaker md` applies at the end of a run (exit 1 above it). The
                         event-driven dynamics is exact between collisions, so the budget closes
                         to round-off of the running sums (measured 1e-13 .. 1e-12).
  queue_consistent == 1  the event queue's order and index, one entry per particle, nothing
                         scheduled before the row's time
Continuum invariants, each at every row:
  |total_mass - m0| / m0 <= 1e-12   the finite-volume scheme conserves mass to round-off;
                         the bound of the 1D multi-cycle continuum test (verification/
                         continuum/test_runs.cpp).
  |energy_budget_residual| <= 1e-10 * throughput   throughput: the total variation of the
                         accumulated drive work plus the accumulated collisional loss up to the
                         row (the residual is zero at the first row by definition); the bound
                         of verification/continuum/test_budget_protocol.cpp, there applied to
                         the largest residual against the whole run's throughput.
Both: the program exits 0, the time series has one row per phase of every cycle plus the end
row (MD) and holds only finite values where the solver defines them.
"""
import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ENERGY_CLOSURE_BOUND = 1e-9
MASS_DRIFT_BOUND = 1e-12
BUDGET_RESIDUAL_BOUND = 1e-10
MAX_SAMPLED_CYCLES = 10


def first_failure(name, values, ok):
    """A message naming the first row where `ok` is false, or None."""
    bad = np.flatnonzero(~ok)
    if bad.size == 0:
        return None
    row = int(bad[0])
    return f"{name}: {bad.size} rows fail, the first at row {row} (value {values[row]!r})"


def check_md(series):
    failures = []
    overlaps = series["overlaps"]
    closure = series["energy_budget_relative_residual"]
    consistent = series["queue_consistent"]
    failures.append(first_failure("overlaps (allowed 0)", overlaps, overlaps == 0))
    failures.append(first_failure(
        f"energy_budget_relative_residual (allowed <= {ENERGY_CLOSURE_BOUND:g})", closure,
        closure <= ENERGY_CLOSURE_BOUND))
    failures.append(first_failure("queue_consistent (allowed 1)", consistent, consistent == 1))
    worst = float(np.max(closure)) if closure.size else math.nan
    summary = (f"{closure.size} rows; overlaps max {float(np.max(overlaps)):g}; "
               f"energy_budget_relative_residual max {worst:.3g}; "
               f"queue_consistent min {float(np.min(consistent)):g}; "
               f"pair collisions {float(series['collisions'][-1]):.0f}")
    return [f for f in failures if f], summary


def check_continuum(series):
    failures = []
    mass = series["total_mass"]
    drift = np.abs(mass - mass[0]) / mass[0]
    failures.append(first_failure(f"total_mass relative drift (allowed <= {MASS_DRIFT_BOUND:g})",
                                  drift, drift <= MASS_DRIFT_BOUND))
    work = series["accumulated_drive_work"]
    loss = series["accumulated_collisional_loss"]
    throughput = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(work)))]) + (loss - loss[0])
    residual = np.abs(series["energy_budget_residual"])
    ratio = residual / np.maximum(throughput, np.finfo(float).tiny)
    failures.append(first_failure(
        f"energy_budget_residual / throughput (allowed <= {BUDGET_RESIDUAL_BOUND:g})", ratio,
        residual <= BUDGET_RESIDUAL_BOUND * throughput))
    summary = (f"{mass.size} rows; mass drift max {float(np.max(drift)):.3g}; budget residual max "
               f"{float(np.max(residual)):.3g} of throughput {float(throughput[-1]):.6g} "
               f"(ratio max {float(np.max(ratio)):.3g})")
    return [f for f in failures if f], summary


# Columns that may be NaN by definition (docs/output-schema.md).
MAY_BE_NAN = {"com_z_change_from_previous_cycle", "periodicity_last_two_cycles"}


def check_file(path, solver, expected_rows=None):
    """(failures, summary) for the run file at `path`."""
    with h5py.File(path, "r") as f:
        group = f["timeseries"]
        names = group.attrs["columns"]
        names = (names.decode() if isinstance(names, bytes) else names).split(",")
        series = {name: np.asarray(group[name][()], dtype=float) for name in names}
    failures = []
    lengths = {len(v) for v in series.values()}
    if len(lengths) != 1:
        return [f"time-series columns differ in length: {sorted(lengths)}"], ""
    rows = lengths.pop()
    if expected_rows is not None and rows != expected_rows:
        failures.append(f"time series has {rows} rows, expected {expected_rows} (one per phase of "
                        f"every cycle{' and the end' if solver == 'md' else ''})")
    for name, values in series.items():
        if name not in MAY_BE_NAN:
            failures.append(first_failure(f"{name} (allowed finite)", values, np.isfinite(values)))
    time = series["t"]
    failures.append(first_failure("time (allowed increasing)", time[1:], np.diff(time) > 0))
    invariant_failures, summary = (check_md if solver == "md" else check_continuum)(series)
    return [f for f in failures if f] + invariant_failures, summary


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--solver", choices=["md", "continuum"], required=True)
    parser.add_argument("--shaker", help="the shaker program")
    parser.add_argument("--case", help="case file (TOML)")
    parser.add_argument("--cycles", type=int, help="cycles to run (transient + sampled)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="further configuration overrides")
    parser.add_argument("--check-only", metavar="RUN.h5",
                        help="check an existing run file instead of running")
    args = parser.parse_args()

    if args.check_only:
        failures, summary = check_file(args.check_only, args.solver)
        print(f"soak check of {args.check_only}: {summary}")
        for failure in failures:
            print(f"FAILED: {failure}", file=sys.stderr)
        return 1 if failures else 0

    if not (args.shaker and args.case and args.cycles and args.cycles > 0):
        parser.error("a run needs --shaker, --case and --cycles > 0")
    sampled = min(MAX_SAMPLED_CYCLES, args.cycles)
    workdir = tempfile.mkdtemp(prefix=f"shaker-soak-{args.solver}-")
    run_file = os.path.join(workdir, "run.h5")
    command = [os.path.abspath(args.shaker), args.solver, os.path.abspath(args.case),
               "--set", f"run.transient_cycles={args.cycles - sampled}",
               "--set", f"run.sampled_cycles={sampled}",
               "--set", f"run.output={run_file}"]
    for override in args.set:
        command += ["--set", override]
    print("running:", " ".join(command), flush=True)
    status = subprocess.run(command, cwd=workdir).returncode
    failures = []
    summary = ""
    if status != 0:
        failures.append(f"shaker {args.solver} exited {status}, expected 0")
    if os.path.exists(run_file):
        with h5py.File(run_file, "r") as f:
            phases = int(f["profiles/phase"].shape[0])
        expected = args.cycles * phases + (1 if args.solver == "md" else 0)
        file_failures, summary = check_file(run_file, args.solver, expected)
        failures += file_failures
    elif status == 0:
        failures.append(f"shaker {args.solver} exited 0 but wrote no {run_file}")
    print(f"soak {args.solver}, {args.cycles} cycles: {summary}")
    if failures:
        for failure in failures:
            print(f"FAILED: {failure}", file=sys.stderr)
        print(f"kept {workdir} for inspection", file=sys.stderr)
        return 1
    shutil.rmtree(workdir)
    print("soak passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
