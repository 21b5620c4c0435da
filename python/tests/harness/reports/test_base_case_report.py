"""ctest reports.base_case_report: granular_shaker.reports.make_base_case_report on synthetic run
files of ci/base-case.sh (an MD run file, its `shaker analyze --csv` table and log; the continuum
unavailable).

Checks the status table and the per-phase analysis table: their units in the headers
(wall-clock seconds, the units of each analysis column), the values of a row, and that a
column without declared units is an error rather than a blank.
"""
import os
import subprocess

import h5py
import numpy as np
import pytest

from granular_shaker.reports import report_common

from .. import harness_command, package_environment
PHASES = 10
ANALYSIS_COLUMNS = ("phase", "plate_z", "layer_bottom", "layer_top", "center_of_mass",
                    "shock_location", "shock_width", "width_over_mfp", "max_mach")


def write_md_run(runs):
    """md.h5 with the attributes and profiles the report reads, and its analysis table: row k
    holds phase k / PHASES and the value 10 k + (column index) in every other column."""
    z = np.tile(np.arange(0.5, 40.0, 1.0), (PHASES, 1))
    with h5py.File(os.path.join(runs, "md.h5"), "w") as f:
        f.attrs["solver"] = "md"
        f.attrs["model_variant"] = "synthetic"
        f.attrs["git_commit"] = "c" * 40
        f.attrs["configuration"] = "[md]\nbin_height = 1.0\n"
        profiles = f.create_group("profiles")
        profiles["phase"] = np.arange(PHASES) / PHASES
        profiles["plate_z"] = np.zeros(PHASES)
        profiles["z"] = z
        nu, T = 0.3 * np.exp(-z / 10.0), 0.1 + 0.01 * z
        profiles["nu"], profiles["T"], profiles["n"] = nu, T, nu * 6 / np.pi
        # The MD run file's standard errors (docs/output-schema.md).
        profiles["n_se"], profiles["T_se"] = 0.02 * nu * 6 / np.pi, 0.02 * T
    with open(os.path.join(runs, "md-analysis.csv"), "w") as f:
        # As `shaker analyze --csv` writes it: the values, then an _error column for each.
        f.write(",".join(ANALYSIS_COLUMNS + tuple(c + "_error" for c in ANALYSIS_COLUMNS))
                + "\n")
        for k in range(PHASES):
            values = [k / PHASES] + [10 * k + c for c in range(1, len(ANALYSIS_COLUMNS))]
            f.write(",".join(str(x) for x in values + [0.1] * len(values)) + "\n")
    with open(os.path.join(runs, "md.log"), "w") as f:
        f.write("# shaker (synthetic)\n# ---- configuration ----\n[layer]\nparticles = 3937\n"
                "# ---- terminal ----\nsynthetic MD run\n")


def test_units_in_the_headers(work_dir):
    runs = os.path.join(work_dir, "runs")
    os.makedirs(runs)
    write_md_run(runs)
    report = os.path.join(runs, "base-case.md")
    result = subprocess.run(harness_command("reports.make_base_case_report", "--runs", runs,
                                            "--output", report, "--status", "md=ok:6600",
                                            "continuum=unavailable:0", repository=False),
                            capture_output=True, text=True, env=package_environment())
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr}"
    lines = open(report).read().splitlines()
    assert "| solver | status | wall time [s] | model variant | resolution |" in lines, \
        "status table header lacks the units of the wall time"
    assert "| md | ran | 6.6 | synthetic | bins 1 sigma |" in lines, "status row of md"
    header = ("| f t [1] | plate [sigma] | layer bottom [sigma] | layer top [sigma] | "
              "centre of mass [sigma] | shock [sigma] | d [sigma] | d/xi [1] | max Ma [1] |")
    assert header in lines, "per-phase table header lacks the units of its columns"
    # Every fifth stored phase: the row of phase 0.5 holds 51 .. 58.
    row = "| 0.500 | " + " | ".join(f"{50 + c:.3f}" for c in range(1, 9)) + " |"
    assert row in lines, f"per-phase row of f t = 0.5 missing: {row}"


def test_a_column_without_declared_units_is_an_error():
    assert report_common.analysis_header("shock", "shock_location") == "shock [sigma]"
    with pytest.raises(report_common.UnknownUnits, match="'shock_strength'"):
        report_common.analysis_header("strength", "shock_strength")
