#!/usr/bin/python3
"""Checkpoints of one solver through the `shaker` program, read with h5py.

    check_checkpoints.py SHAKER md|continuum

In a fresh temporary directory (removed when every check passes, kept and printed otherwise):
  1. A straight run of N cycles with run.checkpoint and run.checkpoint_every = 1 keeps exactly
     two checkpoint files: the final one and the one after the last cycle (NAME.previous.h5),
     both valid (the previous one continues to N + 1 cycles).
  2. A run of K < N cycles, continued to N cycles with run.restart_from, ends in the straight
     run's final checkpoint bit for bit (every dataset and attribute but the configuration), and
     its time-series rows equal the straight run's rows after the restart point.
  3. The same for a run stopped by a real SIGTERM, sent once the run has written its first
     periodic checkpoint (after cycle 0) and printed its progress line at the second stored
     phase of cycle 1, so that the signal arrives mid-cycle: the program exits with 143
     (128 + 15), its checkpoint lies where the run was at the next stored phase (a stop that
     lands on a cycle's first phase after all is tried again, up to three times), and the
     continued run ends where the straight run does.
Exit code 0 when every check holds.
"""
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import keep_on_failure
import numpy as np

# Small cases that run N cycles in about a second: long enough for the signal to arrive
# before the end, short enough for the default test set.
CASES = {
    "md": dict(case="[layer]\nparticles = 200\n[md]\nbox_width = 6.0\nceiling = 60.0\n",
               cycles=(2, 38), first=(1, 1), phases=10),
    "continuum": dict(case="[continuum]\ncell_size = 0.5\n", cycles=(2, 6), first=(1, 1),
                      phases=10),
}
# Time-series columns that count from the start of each run (docs/output-schema.md), or that
# compare with rows before it: a continued run starts them afresh, so they are not compared.
RUN_RELATIVE = {
    "md": {"energy_budget_residual", "energy_budget_relative_residual", "collisions"},
    "continuum": {"com_z_change_from_previous_cycle", "energy_budget_residual",
                  "energy_budget_relative_residual",
                  "periodicity_last_two_cycles"},
}
RUN_RELATIVE_PREFIXES = ("crossings_z", "particles_z")
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print(f"FAIL: {what}")
    return condition


class Runs:
    def __init__(self, shaker, solver, directory):
        self.shaker, self.solver, self.dir = shaker, solver, directory
        self.spec = CASES[solver]
        (directory / "case.toml").write_text(
            self.spec["case"] + f"[run]\nphases_per_cycle = {self.spec['phases']}\n")

    def arguments(self, output, cycles, settings, progress=False):
        sets = {"run.output": output, "run.transient_cycles": cycles[0],
                "run.sampled_cycles": cycles[1], **settings}
        args = [self.shaker, self.solver, "case.toml"]
        args += ["--progress-interval", "0"] if progress else ["--quiet"]
        for key, value in sets.items():
            args += ["--set", f"{key}={value}"]
        return args

    def run(self, output, cycles, **settings):
        done = subprocess.run(self.arguments(output, cycles, settings), cwd=self.dir,
                              capture_output=True, text=True)
        check(done.returncode == 0,
              f"{self.solver} {output}: exit {done.returncode}\n{done.stderr}")
        return done

    def stopped(self, output, cycles, checkpoint):
        """The run, sent SIGTERM at its progress line of cycle 1's second stored phase (after the
        periodic checkpoint of cycle 0; the run stops at that phase if the signal comes in at
        once, else at a later one); its exit status and output."""
        process = subprocess.Popen(
            self.arguments(output, cycles,
                           {"run.checkpoint": checkpoint, "run.checkpoint_every": 1}, True),
            cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        seen = []
        for line in process.stderr:
            seen.append(line)
            if sum(f": cycle 2 of {sum(cycles)}," in line for line in seen) == 2:
                break
        check((self.dir / checkpoint).exists(),
              f"{self.solver}: no periodic checkpoint before cycle 1")
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate()
        return process.returncode, out + "".join(seen) + err


def position(path):
    with h5py.File(path, "r") as f:
        return (int(f.attrs["schedule_cycle"]), int(f.attrs["schedule_phase"]),
                int(f.attrs["schedule_phases"]), float(f.attrs["time"]))


def datasets(f):
    """The paths of every dataset in an open file, groups included (an MD checkpoint's sums of
    the sampled cycles are in the group cycle_samples)."""
    names = []
    f.visititems(lambda name, item: names.append(name) if isinstance(item, h5py.Dataset) else None)
    return sorted(names)


def same_checkpoints(a, b, what):
    """Every dataset and attribute but the configuration (which names the files) equal."""
    with h5py.File(a, "r") as x, h5py.File(b, "r") as y:
        check(datasets(x) == datasets(y), f"{what}: datasets {datasets(x)} != {datasets(y)}")
        differing = [name for name in datasets(x)
                     if name in y and x[name][()].tobytes() != y[name][()].tobytes()]
        check(not differing, f"{what}: datasets differ: {differing}")
        attributes = set(x.attrs) - {"configuration"}
        check(attributes == set(y.attrs) - {"configuration"}, f"{what}: attributes differ in name")
        differing = [name for name in attributes
                     if np.asarray(x.attrs[name]).tobytes()
                     != np.asarray(y.attrs.get(name)).tobytes()]
        check(not differing, f"{what}: attributes differ: {differing}")
        return len(datasets(x)), len(attributes)


def same_rows_after_restart(solver, straight, continued, what):
    """The continued run's rows equal the straight run's last rows, column by column."""
    with h5py.File(straight, "r") as x, h5py.File(continued, "r") as y:
        a, b = x["timeseries"], y["timeseries"]
        rows = len(b["t"])
        start = len(a["t"]) - rows
        if not check(rows > 0 and start > 0 and a["t"][start] == b["t"][0],
                     f"{what}: the continued run's {rows} rows do not start at a row of the "
                     "straight run"):
            return 0, 0
        columns = [name for name in b.keys() if name not in RUN_RELATIVE[solver]
                   and not name.startswith(RUN_RELATIVE_PREFIXES)]
        differing = [name for name in columns if a[name][start:].tobytes() != b[name][:].tobytes()]
        check(not differing, f"{what}: columns differ after the restart point: {differing}")
        check(sorted(a.keys()) == sorted(b.keys()), f"{what}: other columns")
        return rows, len(columns)


def report(what, checkpoint_counts, row_counts):
    print(f"{what}: final checkpoint equal to the straight run's in {checkpoint_counts[0]} "
          f"datasets and {checkpoint_counts[1]} attributes; {row_counts[0]} rows x "
          f"{row_counts[1]} columns equal")


def kept_two(runs, cycles):
    """Check 1: exactly the final checkpoint and the one before it, both valid."""
    total = sum(cycles)
    files = sorted(p.name for p in runs.dir.glob("straight.ckpt*"))
    check(files == ["straight.ckpt.h5", "straight.ckpt.previous.h5"],
          f"checkpoint files kept: {files}")
    with h5py.File(runs.dir / "straight.run.h5", "r") as f:
        times = f["timeseries"]["t"][:]
    end, last_phase = (times[-1], times[-2]) if runs.solver == "md" else (None, times[-1])
    final = position(runs.dir / "straight.ckpt.h5")
    previous = position(runs.dir / "straight.ckpt.previous.h5")
    with h5py.File(runs.dir / "straight.ckpt.h5", "r") as f:
        without_units = [name for name, item in f.items()
                         if isinstance(item, h5py.Dataset) and not item.attrs.get("units")]
    check(not without_units, f"{runs.solver} checkpoint datasets without units: {without_units}")
    check(final[:3] == (total, 0, runs.spec["phases"]), f"final checkpoint at {final}")
    check(previous == (total, 0, runs.spec["phases"], last_phase),
          f"previous checkpoint at {previous}, expected after the last stored phase "
          f"t = {last_phase}")
    if end is not None:
        check(final[3] == end, f"final checkpoint time {final[3]} != the run's end {end}")
    runs.run("more.run.h5", (cycles[0], cycles[1] + 1),
             **{"run.restart_from": "straight.ckpt.previous.h5"})
    print(f"{runs.solver}: {files} kept after {total} cycles with run.checkpoint_every = 1; "
          f"final at {final[:3]}, previous at t = {previous[3]}, which continues to "
          f"{total + 1} cycles")


def split_run(runs, cycles):
    """Check 2: K cycles, then continued to N."""
    runs.run("first.run.h5", runs.spec["first"], **{"run.checkpoint": "first.ckpt.h5"})
    runs.run("rest.run.h5", cycles,
             **{"run.restart_from": "first.ckpt.h5", "run.checkpoint": "rest.ckpt.h5"})
    first = sum(runs.spec["first"])
    what = f"{runs.solver}: {first} cycles + {sum(cycles) - first} after a restart"
    report(what, same_checkpoints(runs.dir / "straight.ckpt.h5", runs.dir / "rest.ckpt.h5", what),
           same_rows_after_restart(runs.solver, runs.dir / "straight.run.h5",
                                   runs.dir / "rest.run.h5", what))


def stopped_run(runs, cycles):
    """Check 3: stopped by SIGTERM mid-cycle, then continued to N."""
    phases = runs.spec["phases"]
    for attempt in range(3):
        checkpoint = f"stop{attempt}.ckpt.h5"
        status, output = runs.stopped(f"stop{attempt}.run.h5", cycles, checkpoint)
        if not check(status == 143 and "stopped by signal 15 (SIGTERM)" in output
                     and f"run.restart_from={checkpoint}" in output,
                     f"{runs.solver}: SIGTERM gave exit {status}; expected 143 and the "
                     f"message:\n{output}"):
            return
        check(not (runs.dir / f"stop{attempt}.run.h5").exists(), "a stopped run wrote its run file")
        cycle, phase, _, t = position(runs.dir / checkpoint)
        reached = phase - 1 if phase > 0 else phases - 1  # the stored phase the run stopped at
        if reached != 0:
            break
        print(f"{runs.solver}: attempt {attempt} stopped at a cycle's first phase; again")
    check(reached != 0, f"{runs.solver}: three stops in a row on a cycle's first phase")
    runs.run("resumed.run.h5", cycles,
             **{"run.restart_from": checkpoint, "run.checkpoint": "resumed.ckpt.h5"})
    what = (f"{runs.solver}: stopped by SIGTERM at t = {t!r} (stored phase {reached} of {phases}, "
            f"continued at cycle {cycle} phase {phase}), continued to {sum(cycles)} cycles")
    report(what,
           same_checkpoints(runs.dir / "straight.ckpt.h5", runs.dir / "resumed.ckpt.h5", what),
           same_rows_after_restart(runs.solver, runs.dir / "straight.run.h5",
                                   runs.dir / "resumed.run.h5", what))


def main():
    shaker, solver = sys.argv[1], sys.argv[2]
    directory = Path(keep_on_failure.work_folder(f"shaker-checkpoints-{solver}-"))
    runs = Runs(shaker, solver, directory)
    cycles = CASES[solver]["cycles"]
    start = time.monotonic()
    runs.run("straight.run.h5", cycles,
             **{"run.checkpoint": "straight.ckpt.h5", "run.checkpoint_every": 1})
    print(f"{solver}: straight run of {sum(cycles)} cycles took {time.monotonic() - start:.2f} s")
    if not failures:
        kept_two(runs, cycles)
        split_run(runs, cycles)
        stopped_run(runs, cycles)
    left = [p.name for p in directory.iterdir() if ".partial-" in p.name]
    check(not left, f"temporary files left: {left}")
    return keep_on_failure.finish(directory, failures)


if __name__ == "__main__":
    sys.exit(main())
