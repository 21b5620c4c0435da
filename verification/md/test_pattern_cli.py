"""ctest md.Patterns.AnalyzeAgreesWithNumpy: `shaker analyze --patterns` on the particle file of
a small MD run, checked against the definitions of docs/analysis.md ("Patterns") computed
here independently with h5py and numpy's FFT.

    python3 -m pytest verification/md/test_pattern_cli.py --shaker SHAKER

A run writes frames at two stored phases of three consecutive cycles. For every frame the
column-mass and centre-of-mass-height fields are binned on the grid, and k*, the wavelength,
A2, A4, A6, the order parameter and the correlation with the previous cycle's frame must
equal the CSV's to 1e-9 (relative, or absolute for values near 0).
"""
import csv
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest
from pattern_reference import correlation, half_wavelength_correlation, measure

WIDTH, PARTICLES, CELL = 16.0, 300, 2.0

CASE = f"""
[layer]
particles = {PARTICLES}
[md]
box_width = {WIDTH}
ceiling = 60.0
snapshot_phases = [0.0, 0.4]
snapshot_cycles = [0, 1, 2]
[run]
transient_cycles = 1
sampled_cycles = 2
phases_per_cycle = 5
output = "run.h5"
"""


def fields(position, edges, n):
    """Column mass (particles per cell area) and centre-of-mass height on n x n cells, [j, i]."""
    x, y, z = position[:, 0], position[:, 1], position[:, 2]
    i = np.minimum((np.mod(x, edges[0]) / edges[0] * n).astype(int), n - 1)
    j = np.minimum((np.mod(y, edges[1]) / edges[1] * n).astype(int), n - 1)
    count = np.zeros((n, n))
    height = np.zeros((n, n))
    np.add.at(count, (j, i), 1.0)
    np.add.at(height, (j, i), z)
    mean_height = np.where(count > 0, height / np.maximum(count, 1.0), z.mean())
    return count / (edges[0] * edges[1] / n**2), mean_height


def analyse(shaker, directory):
    """Runs the MD and `shaker analyze --patterns`: the CSV rows, the frames, the printed text."""
    Path(directory, "case.toml").write_text(CASE)
    subprocess.run([shaker, "md", "case.toml", "--quiet"], cwd=directory, check=True,
                   capture_output=True)
    printed = subprocess.run([shaker, "analyze", "run.h5", "--patterns", "patterns.csv",
                              "--pattern-cell", str(CELL)], cwd=directory, check=True,
                             capture_output=True, text=True).stdout
    with open(Path(directory, "patterns.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    with h5py.File(Path(directory, "run.particles.h5"), "r") as f:
        frames = {
            "position": f["particles/all/position/value"][()],
            "edges": f["particles/all/box/edges"][()],
            "cycle": f["observables/cycle/value"][()],
            "phase": f["observables/phase/value"][()],
        }
    return rows, frames, printed


def test_one_row_per_frame_with_units(shaker, work_dir):
    rows, frames, printed = analyse(shaker, work_dir)
    assert len(rows) == len(frames["cycle"]) == 6
    assert "mass_k [1/sigma]" in rows[0] and "height_order_parameter [sigma]" in rows[0]
    assert [int(r["cycle [1]"]) for r in rows] == list(frames["cycle"])
    # one summary line per stored phase and field
    assert printed.count("# patterns at phase") == 4


def test_values_equal_the_definitions(shaker, work_dir):
    rows, frames, _ = analyse(shaker, work_dir)
    n = int(round(WIDTH / CELL))
    computed = []
    for f in range(len(rows)):
        mass, height = fields(frames["position"][f], frames["edges"], n)
        computed.append((mass, height))
        for name, field in (("mass", mass), ("height", height)):
            expected = measure(field, frames["edges"])
            keys = ["k [1/sigma]", "wavelength [sigma]", "a2 [1]", "a4 [1]", "a6 [1]"]
            unit = "1/sigma^2" if name == "mass" else "sigma"
            keys.append(f"order_parameter [{unit}]")
            got = [float(rows[f][f"{name}_{key}"]) for key in keys]
            assert got == pytest.approx(expected, rel=1e-9, abs=1e-12), (f, name)
    for f in range(len(rows)):
        before = [g for g in range(len(rows)) if frames["cycle"][g] + 1 == frames["cycle"][f]
                  and frames["phase"][g] == frames["phase"][f]]
        for index, name in ((0, "mass"), (1, "height")):
            got = float(rows[f][f"{name}_correlation_previous_cycle [1]"])
            shifted = float(rows[f][f"{name}_half_wavelength_correlation [1]"])
            if not before:
                assert np.isnan(got) and np.isnan(shifted)
            else:
                a, b = computed[before[0]][index], computed[f][index]
                assert got == pytest.approx(correlation(a, b), rel=1e-9, abs=1e-12)
                assert shifted == pytest.approx(
                    half_wavelength_correlation(a, b, frames["edges"]), rel=1e-9, abs=1e-12)


def test_a_cell_wider_than_half_the_box_is_refused(shaker, work_dir):
    analyse(shaker, work_dir)
    refused = subprocess.run([shaker, "analyze", "run.h5", "--patterns", "coarse.csv",
                              "--pattern-cell", "11"], cwd=work_dir, capture_output=True, text=True)
    assert refused.returncode == 2
    assert "--pattern-cell = 11 gives 1 x 1 cells" in refused.stderr
    assert "allowed: at most half the box width" in refused.stderr
    assert not Path(work_dir, "coarse.csv").exists()


def stripes_in_a_rectangular_box(shaker, directory, width, depth, along):
    """A short MD run in a width x depth box, whose particle file then gets synthetic frames
    of its 288 particles: heights 5 + 2 cos(2 pi s / 8), s = x or y (`along`), a stripe
    pattern of wavelength 8. Returns the CSV rows and the file's box edges."""
    case = CASE.replace(f"box_width = {WIDTH}", f"box_width = {width}\nbox_depth = {depth}")
    case = case.replace(f"particles = {PARTICLES}", "particles = 288")
    Path(directory, "case.toml").write_text(case)
    subprocess.run([shaker, "md", "case.toml", "--quiet"], cwd=directory, check=True,
                   capture_output=True)
    # Along the stripes' wavevector the particles sit on a regular grid, 12 to the wavelength;
    # across it at random (uneven counts, so the column mass is not uniform). The height
    # is the cosine at the centre of the particle's cell, so the height field is one mode.
    rng = np.random.default_rng(0)
    length, across = (width, depth) if along == "x" else (depth, width)
    s = np.repeat((np.arange(36) + 0.5) * length / 36, 8)
    t = rng.uniform(0, across, s.size)
    centre = (np.floor(s / CELL) + 0.5) * CELL
    z = 5 + 2 * np.cos(2 * np.pi * centre / 8)
    x, y = (s, t) if along == "x" else (t, s)
    synthetic = np.stack([x, y, z], 1)
    with h5py.File(Path(directory, "run.particles.h5"), "r+") as f:
        position = f["particles/all/position/value"]
        position[...] = np.broadcast_to(synthetic, position.shape)
        edges = f["particles/all/box/edges"][()]
    subprocess.run([shaker, "analyze", "run.h5", "--patterns", "patterns.csv",
                    "--pattern-cell", str(CELL)], cwd=directory, check=True, capture_output=True)
    with open(Path(directory, "patterns.csv"), newline="") as f:
        return list(csv.DictReader(f)), edges


@pytest.mark.parametrize("width, depth, along", [(24.0, 8.0, "x"), (8.0, 24.0, "y")])
def test_stripes_in_a_rectangular_box(shaker, work_dir, width, depth, along):
    """The particle file holds the box's real x and y lengths, and the analysis bins and
    transforms on them: stripes of wavelength 8 across the long side of a 24 x 8 (or 8 x 24)
    box, three to the box, come out at wavelength 8 with the stripes' symmetry. Taking one
    length for both sides would put them at 8/3 or 24."""
    rows, edges = stripes_in_a_rectangular_box(shaker, work_dir, width, depth, along)
    assert list(edges[:2]) == [width, depth]
    assert len(rows) == 6
    for row in rows:
        assert float(row["height_wavelength [sigma]"]) == pytest.approx(8.0, rel=1e-9)
        assert float(row["height_a2 [1]"]) == pytest.approx(1.0, rel=1e-9)
        assert row["height_symmetry"] == "stripes"
