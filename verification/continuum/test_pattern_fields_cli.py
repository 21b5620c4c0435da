"""ctest continuum.Patterns.FieldsAgreeWithNumpy: `shaker analyze --patterns` on the fields file
of a small 3D continuum run, checked against the definitions of docs/analysis.md ("Patterns")
computed here independently with h5py and numpy's FFT.

    python3 -m pytest verification/continuum/test_pattern_fields_cli.py --shaker SHAKER

A 6 x 4 box of cells 1 sigma (its initial layer perturbed by 10 %, so that the columns differ)
writes its fields at two stored phases of two consecutive cycles. For every snapshot the
column mass sum_k n h and the centre-of-mass height sum_k n z_k / sum_k n (z_k the lab-frame
cell centres) of its columns, and from them k*, the wavelength, A2, A4, A6, the order parameter
and the correlation with the previous cycle's snapshot must equal the CSV's to 1e-9.
"""
import csv
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest
from pattern_reference import correlation, half_wavelength_correlation, measure

NX, NY, H = 6, 4, 1.0

# Small and fast, as the MPI tests' boxes: a short, light layer at a high frequency.
CASE = f"""
[layer]
particles = 300
[shaker]
frequency = 0.5
[continuum]
dimension = 3
box_width = {NX * H}
box_depth = {NY * H}
cell_size = {H}
ceiling = 12.0
transport = "paper"
diffusion_integrator = "explicit"
perturbation = 0.1
field_phases = [0.0, 0.4]
field_cycles = [0, 1]
[run]
transient_cycles = 1
sampled_cycles = 1
phases_per_cycle = 5
output = "run.h5"
"""


@pytest.fixture
def analysed(shaker, work_dir):
    Path(work_dir, "case.toml").write_text(CASE)
    subprocess.run([shaker, "continuum", "case.toml", "--quiet"], cwd=work_dir, check=True,
                   capture_output=True)
    printed = subprocess.run([shaker, "analyze", "run.h5", "--patterns", "patterns.csv"],
                             cwd=work_dir, check=True, capture_output=True, text=True).stdout
    with open(Path(work_dir, "patterns.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    with h5py.File(Path(work_dir, "run.fields.h5"), "r") as f:
        names = sorted(k for k in f if k.startswith("snapshot_"))
        attributes = ("cycle", "phase", "time", "plate_z")
        snapshots = [dict(n=f[name]["n"][()], **{a: f[name].attrs[a] for a in attributes})
                     for name in names]
    return rows, snapshots, printed


def column_fields(snapshot):
    n = snapshot["n"]  # [k][j][i]
    z = (np.arange(n.shape[0]) + 0.5) * H + snapshot["plate_z"]
    mass = n.sum(axis=0) * H
    height = np.tensordot(z, n, axes=1) / n.sum(axis=0)
    return mass, height


def test_one_row_per_snapshot(analysed):
    rows, snapshots, printed = analysed
    assert len(rows) == len(snapshots) == 4
    assert [int(r["cycle [1]"]) for r in rows] == [int(s["cycle"]) for s in snapshots]
    assert printed.count("# patterns at phase") == 4  # two phases, two fields


def test_values_equal_the_definitions(analysed):
    rows, snapshots, _ = analysed
    edges = (NX * H, NY * H)
    computed = [column_fields(s) for s in snapshots]
    for f, (mass, height) in enumerate(computed):
        assert mass.std() > 1e-6  # the perturbation left the columns different
        for name, field in (("mass", mass), ("height", height)):
            unit = "1/sigma^2" if name == "mass" else "sigma"
            keys = ["k [1/sigma]", "wavelength [sigma]", "a2 [1]", "a4 [1]", "a6 [1]",
                    f"order_parameter [{unit}]"]
            got = [float(rows[f][f"{name}_{key}"]) for key in keys]
            assert got == pytest.approx(measure(field, edges), rel=1e-9, abs=1e-12), (f, name)
    for f in (2, 3):  # the second cycle's snapshots follow the first's at the same phase
        for index, name in ((0, "mass"), (1, "height")):
            got = float(rows[f][f"{name}_correlation_previous_cycle [1]"])
            a, b = computed[f - 2][index], computed[f][index]
            assert got == pytest.approx(correlation(a, b), rel=1e-9, abs=1e-12)
            shifted = float(rows[f][f"{name}_half_wavelength_correlation [1]"])
            assert shifted == pytest.approx(half_wavelength_correlation(a, b, edges), rel=1e-9,
                                            abs=1e-12)
