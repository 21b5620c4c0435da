"""read_snapshots and to_gsd on the particle file `shaker md` writes (md.snapshot_phases and
md.snapshot_cycles; skipped with a shaker that has no such keys): each frame is the snapshot
the run file's time series row `step` was computed from, so the particles' mean height is that
row's com_z, in the lab and in the plate frame."""
import os
import subprocess

import numpy as np
import pytest

import granular_shaker as gs

PARTICLES, PHASES = 200, 4


def run_with_snapshots(shaker, folder):
    described = subprocess.run([shaker, "config", "--describe"], capture_output=True, text=True)
    if "md.snapshot_phases" not in described.stdout:
        pytest.skip("this shaker writes no particle snapshots (no key md.snapshot_phases)")
    case = os.path.join(folder, "case.toml")
    with open(case, "w") as f:
        f.write("# the base case, shortened by the settings below\n")
    settings = {"layer.particles": PARTICLES, "run.transient_cycles": 1,
                "run.sampled_cycles": 1, "run.phases_per_cycle": PHASES,
                "md.snapshot_phases": "[0.0, 0.5]", "md.snapshot_cycles": "[0, 1]",
                "run.output": os.path.join(folder, "run.h5")}
    command = [shaker, "md", case, "--quiet"]
    for key, value in settings.items():
        command += ["--set", f"{key}={value}"]
    result = subprocess.run(command, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return os.path.join(folder, "run.h5"), os.path.join(folder, "run.particles.h5")


def test_frames_are_the_run_files_rows_and_survive_gsd(shaker, work_dir):
    run_path, particles_path = run_with_snapshots(shaker, work_dir)
    for frame in ("lab", "plate"):
        run = gs.read_run(run_path, frame=frame)
        snapshots = gs.read_snapshots(particles_path, frame=frame)
        frames = snapshots.frames
        assert frames["position"].shape == (4, PARTICLES, 3)
        np.testing.assert_array_equal(frames["step"], [0, 2, 4, 6])
        np.testing.assert_array_equal(frames["phase"], [0.0, 0.5, 0.0, 0.5])
        np.testing.assert_array_equal(frames["cycle"], [0, 0, 1, 1])
        rows = frames["step"]
        np.testing.assert_array_equal(frames["time"], run.timeseries["t"][rows])
        np.testing.assert_array_equal(frames["plate_position"], run.timeseries["plate_z"][rows])
        mean_height = frames["position"][:, :, 2].mean(axis=1)
        print(f"{frame} frame: mean heights {mean_height}, com_z {run.timeseries['com_z'][rows]}")
        np.testing.assert_allclose(mean_height, run.timeseries["com_z"][rows], rtol=1e-12)
        assert snapshots.configuration["layer"]["particles"] == PARTICLES
    assert frames["position"][:, :, 2].min() >= 0.5 - 1e-9  # plate frame: a radius above it
    gsd_hoomd = pytest.importorskip("gsd.hoomd")
    path = os.path.join(work_dir, "run.gsd")
    gs.to_gsd(gs.read_snapshots(particles_path), path)
    try:
        trajectory = gsd_hoomd.open(path, mode="r")
    except ValueError:  # gsd before 2.8
        trajectory = gsd_hoomd.open(path, mode="rb")
    with trajectory:
        assert len(trajectory) == 4
        for snapshot in trajectory:
            box = np.array(snapshot.configuration.box[:3])
            assert np.all(np.abs(snapshot.particles.position) <= box / 2)
