"""ctest md.Particles.ReadByH5pyAseGsd: the particle files of `shaker md` read by other programs'
libraries, not by the project's reader.

    python3 -m pytest verification/md/test_particle_files.py --shaker SHAKER

A small run writes RUN.particles.h5 and RUN.particles.xyz at two stored phases of two cycles.
h5py checks the H5MD layout of docs/output-schema.md; ASE reads the extended XYZ back and must
get the H5MD file's positions, velocities, times and cell; one frame converted to GSD (HOOMD's
format) and read back with gsd keeps the positions and the box.
"""
import subprocess
import tomllib
from pathlib import Path

import ase.io
import gsd
import gsd.hoomd
import h5py
import numpy as np

WIDTH, CEILING, PARTICLES, PHASES = 6.0, 60.0, 200, 10

CASE = f"""
[layer]
particles = {PARTICLES}
[md]
box_width = {WIDTH}
ceiling = {CEILING}
snapshot_phases = [0.5, 0.0]
snapshot_cycles = [0, -1]
[run]
transient_cycles = 1
sampled_cycles = 1
phases_per_cycle = {PHASES}
output = "run.h5"
"""


def run_with_snapshots(shaker, directory):
    Path(directory, "case.toml").write_text(CASE)
    subprocess.run([shaker, "md", "case.toml", "--quiet"], cwd=directory, check=True,
                   capture_output=True)
    return Path(directory, "run.particles.h5"), Path(directory, "run.particles.xyz")


def h5md_frames(path):
    with h5py.File(path, "r") as f:
        return {
            "time": f["particles/all/position/time"][()],
            "position": f["particles/all/position/value"][()],
            "velocity": f["particles/all/velocity/value"][()],
            "edges": f["particles/all/box/edges"][()],
            "cycle": f["observables/cycle/value"][()],
            "phase": f["observables/phase/value"][()],
            "plate_z": f["observables/plate_position/value"][()],
        }


def test_h5md_layout(shaker, work_dir):
    h5, _ = run_with_snapshots(shaker, work_dir)
    with h5py.File(h5, "r") as f:
        assert list(f["h5md"].attrs["version"]) == [1, 1]
        assert f["h5md/creator"].attrs["name"] == "granular-shaker"
        assert f["h5md/creator"].attrs["version"] == f.attrs["program_version"]
        assert f["h5md/author"].attrs["name"] != ""
        box = f["particles/all/box"]
        assert box.attrs["dimension"] == 3
        assert list(box.attrs["boundary"]) == ["periodic", "periodic", "none"]
        assert list(box["edges"][()]) == [WIDTH, WIDTH, CEILING]
        # Provenance as the run file has it.
        assert f.attrs["solver"] == "md" and f.attrs["kind"] == "shaker md particles"
        assert int(f.attrs["schema_version"]) == 2
        configuration = tomllib.loads(f.attrs["configuration"])
        assert configuration["md"]["snapshot_cycles"] == [0.0, -1.0]
        for element, units in [("particles/all/position", "sigma"),
                               ("particles/all/velocity", "sqrt(g sigma)"),
                               ("observables/plate_position", "sigma"),
                               ("observables/plate_velocity", "sqrt(g sigma)"),
                               ("observables/phase", "1"), ("observables/cycle", "1")]:
            group = f[element]
            assert group["step"].dtype == np.int64 and group["time"].dtype == np.float64
            assert group["value"].attrs["units"] == units, element
            assert group["time"].attrs["units"] == "sqrt(sigma/g)", element
            assert group["value"].maxshape[0] is None, f"{element}/value is extendable"
            assert list(group["step"][()]) == [0, 5, PHASES, PHASES + 5], element
        assert f["particles/all/position/value"].shape == (4, PARTICLES, 3)
        assert list(f["observables/cycle/value"][()]) == [0, 0, 1, 1]
        assert list(f["observables/phase/value"][()]) == [0.0, 0.5, 0.0, 0.5]
    with h5py.File(Path(work_dir, "run.h5"), "r") as run:
        t = run["timeseries/t"][()]
    assert list(h5md_frames(h5)["time"]) == [t[0], t[5], t[PHASES], t[PHASES + 5]]


def test_ase_reads_the_h5md_frames_from_the_xyz(shaker, work_dir):
    h5, xyz = run_with_snapshots(shaker, work_dir)
    frames = h5md_frames(h5)
    atoms = ase.io.read(xyz, index=":")
    assert len(atoms) == 4
    for k, a in enumerate(atoms):
        # Shortest round-trip numbers: the very doubles of the H5MD file.
        np.testing.assert_array_equal(a.positions, frames["position"][k])
        np.testing.assert_array_equal(a.arrays["vel"], frames["velocity"][k])
        assert a.info["Time"] == frames["time"][k]
        assert a.info["cycle"] == frames["cycle"][k] and a.info["phase"] == frames["phase"][k]
        assert a.info["plate_z"] == frames["plate_z"][k]
        np.testing.assert_array_equal(a.cell.array, np.diag(frames["edges"]))
        assert list(a.pbc) == [True, True, False]


def to_gsd(path, position, velocity, edges):
    """One frame as a GSD file. HOOMD's box is centred on the origin and periodic in every
    direction: the lab frame is shifted by half the box, and the ceiling bounds z."""
    frame = (gsd.hoomd.Frame if hasattr(gsd.hoomd, "Frame") else gsd.hoomd.Snapshot)()
    frame.configuration.box = [edges[0], edges[1], edges[2], 0.0, 0.0, 0.0]
    frame.particles.N = len(position)
    frame.particles.position = position - 0.5 * edges
    frame.particles.velocity = velocity
    frame.particles.types = ["X"]
    modern = int(gsd.__version__.split(".")[0]) >= 3
    with gsd.hoomd.open(str(path), "w" if modern else "wb") as f:
        f.append(frame)
    return "r" if modern else "rb"


def test_a_frame_converted_to_gsd_keeps_positions_and_box(shaker, work_dir):
    h5, _ = run_with_snapshots(shaker, work_dir)
    frames = h5md_frames(h5)
    path = Path(work_dir, "frame.gsd")
    read_mode = to_gsd(path, frames["position"][-1], frames["velocity"][-1], frames["edges"])
    with gsd.hoomd.open(str(path), read_mode) as f:
        assert len(f) == 1
        back = f[0]
    assert back.particles.N == PARTICLES
    assert list(back.configuration.box[:3]) == [WIDTH, WIDTH, CEILING]
    # GSD keeps positions and velocities as float32: half an ulp of the largest coordinate.
    positions = back.particles.position.astype(float) + 0.5 * frames["edges"]
    np.testing.assert_allclose(positions, frames["position"][-1], rtol=0, atol=CEILING * 2.0**-24)
    np.testing.assert_allclose(back.particles.velocity, frames["velocity"][-1], rtol=2.0**-24)
