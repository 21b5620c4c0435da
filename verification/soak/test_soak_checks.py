"""The soak checks (soak.py) on synthetic run files: a clean series passes, and each broken
invariant (an overlap, an open energy budget, an inconsistent queue, a mass drift, a budget
residual, a missing row) is reported at the row where it breaks."""
import os

import h5py
import numpy as np
import pytest

import soak  # beside this file: pytest imports from a test's folder (no __init__.py here)


def write(path, columns, phases):
    with h5py.File(path, "w") as f:
        f.create_group("profiles").create_dataset("phase", data=np.arange(phases) / phases)
        group = f.create_group("timeseries")
        group.attrs["columns"] = ",".join(columns)
        for name, values in columns.items():
            group.create_dataset(name, data=np.asarray(values, dtype=float))


def md_series(rows):
    return {"t": np.arange(rows, dtype=float), "overlaps": np.zeros(rows),
            "energy_budget_relative_residual": np.full(rows, 1e-13),
            "queue_consistent": np.ones(rows),
            "collisions": np.arange(rows) * 100.0}


def continuum_series(rows):
    work = np.linspace(0.0, 50.0, rows)
    return {"t": np.arange(rows, dtype=float), "total_mass": np.full(rows, 9.8),
            "accumulated_drive_work": work, "accumulated_collisional_loss": work * 0.9,
            # zero at the first row by definition (relative to it), round-off after
            "energy_budget_residual": np.concatenate([[0.0], np.full(rows - 1, 1e-14)]),
            "com_z_change_from_previous_cycle": np.full(rows, np.nan)}


def broken(series, column, row, value=None, factor=None):
    """series with one value replaced (or scaled by factor) at a row."""
    if factor is not None:
        series[column][row] *= factor
    else:
        series[column][row] = value
    return series


MD_ROWS, CONTINUUM_ROWS = 9, 8
# label, solver, columns, expected rows, fragment of the expected failure (None: no failure)
CASES = [
    ("md clean", "md", md_series(MD_ROWS), MD_ROWS, None),
    ("md overlap", "md", broken(md_series(MD_ROWS), "overlaps", 5, 1), MD_ROWS,
     "first at row 5"),
    ("md closure", "md",
     broken(md_series(MD_ROWS), "energy_budget_relative_residual", 3, 2e-9), MD_ROWS,
     "energy_budget_relative_residual (allowed <= 1e-09): 1 rows fail, the first at row 3"),
    ("md queue", "md", broken(md_series(MD_ROWS), "queue_consistent", 7, 0), MD_ROWS,
     "queue_consistent (allowed 1): 1 rows fail, the first at row 7"),
    ("md missing row", "md", md_series(MD_ROWS - 1), MD_ROWS, "has 8 rows, expected 9"),
    ("md NaN", "md",
     broken(md_series(MD_ROWS), "energy_budget_relative_residual", 2, np.nan), MD_ROWS,
     "energy_budget_relative_residual (allowed finite)"),
    ("continuum clean", "continuum", continuum_series(CONTINUUM_ROWS), CONTINUUM_ROWS, None),
    ("continuum mass", "continuum",
     broken(continuum_series(CONTINUUM_ROWS), "total_mass", 4, factor=1 + 1e-11), CONTINUUM_ROWS,
     "total_mass relative drift"),
    ("continuum budget", "continuum",
     broken(continuum_series(CONTINUUM_ROWS), "energy_budget_residual", 6, 1e-6), CONTINUUM_ROWS,
     "energy_budget_residual / throughput"),
]


@pytest.mark.parametrize("label, solver, columns, expected_rows, fragment", CASES,
                         ids=[case[0] for case in CASES])
def test_soak_checks(label, solver, columns, expected_rows, fragment, work_dir):
    path = os.path.join(work_dir, "run.h5")
    write(path, columns, 4)
    failures = soak.check_file(path, solver, expected_rows)[0]
    if fragment is None:
        assert not failures, f"{label}: expected no failure, got {failures}"
    else:
        assert [f for f in failures if fragment in f], \
            f"{label}: expected a failure naming '{fragment}', got {failures}"
