#!/usr/bin/python3
"""The soak checks (soak.py) on synthetic run files: a clean series passes, and each broken
invariant (an overlap, an open energy budget, an inconsistent queue, a mass drift, a budget
residual, a missing row) is reported at the row where it breaks."""
import os
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import soak  # noqa: E402


def write(path, columns, phases):
    with h5py.File(path, "w") as f:
        f.create_group("profiles").create_dataset("phase", data=np.arange(phases) / phases)
        group = f.create_group("timeseries")
        group.attrs["columns"] = ",".join(columns)
        for name, values in columns.items():
            group.create_dataset(name, data=np.asarray(values, dtype=float))


def md_series(rows):
    return {"t": np.arange(rows, dtype=float), "overlaps": np.zeros(rows),
            "energy_closure": np.full(rows, 1e-13), "queue_consistent": np.ones(rows),
            "collisions": np.arange(rows) * 100.0}


def continuum_series(rows):
    work = np.linspace(0.0, 50.0, rows)
    return {"time": np.arange(rows, dtype=float), "total_mass": np.full(rows, 9.8),
            "accumulated_body_work": work, "accumulated_collisional_loss": work * 0.9,
            # zero at the first row by definition (relative to it), round-off after
            "energy_budget_residual": np.concatenate([[0.0], np.full(rows - 1, 1e-14)]),
            "center_of_mass_change_from_previous_cycle": np.full(rows, np.nan)}


def failures_of(solver, columns, expected_rows):
    with tempfile.TemporaryDirectory(prefix="shaker-soak-check-") as directory:
        path = os.path.join(directory, "run.h5")
        write(path, columns, 4)
        return soak.check_file(path, solver, expected_rows)[0]


def main():
    problems = []

    def expect(label, failures, fragment):
        found = [f for f in failures if fragment in f] if fragment else failures
        if fragment is None and failures:
            problems.append(f"{label}: expected no failure, got {failures}")
        elif fragment is not None and not found:
            problems.append(f"{label}: expected a failure naming '{fragment}', got {failures}")
        print(f"{label}: {failures if failures else 'passes'}")

    rows = 9
    expect("md clean", failures_of("md", md_series(rows), rows), None)
    broken = md_series(rows)
    broken["overlaps"][5] = 1
    expect("md overlap", failures_of("md", broken, rows), "first at row 5")
    broken = md_series(rows)
    broken["energy_closure"][3] = 2e-9
    expect("md closure", failures_of("md", broken, rows), "energy_closure (allowed <= 1e-09): 1 rows fail, the first at row 3")
    broken = md_series(rows)
    broken["queue_consistent"][7] = 0
    expect("md queue", failures_of("md", broken, rows), "queue_consistent (allowed 1): 1 rows fail, the first at row 7")
    expect("md missing row", failures_of("md", md_series(rows - 1), rows), "has 8 rows, expected 9")
    broken = md_series(rows)
    broken["energy_closure"][2] = np.nan
    expect("md NaN", failures_of("md", broken, rows), "energy_closure (allowed finite)")

    rows = 8
    expect("continuum clean", failures_of("continuum", continuum_series(rows), rows), None)
    broken = continuum_series(rows)
    broken["total_mass"][4] *= 1 + 1e-11
    expect("continuum mass", failures_of("continuum", broken, rows), "total_mass relative drift")
    broken = continuum_series(rows)
    broken["energy_budget_residual"][6] = 1e-6
    expect("continuum budget", failures_of("continuum", broken, rows), "energy_budget_residual / throughput")

    for problem in problems:
        print(f"FAILED: {problem}", file=sys.stderr)
    print(f"{9 - len(problems)} passed, {len(problems)} failed")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
