"""to_gsd: snapshots written as GSD and read back with the gsd package (Debian python3-gsd)."""
import os

import numpy as np
import pytest

import granular_shaker as gs
import synthetic_files as synthetic

gsd_hoomd = pytest.importorskip("gsd.hoomd", reason="needs python3-gsd (ci/install-deps.sh)")


def _open_for_reading(path):
    try:
        return gsd_hoomd.open(path, mode="r")
    except ValueError:  # gsd before 2.8
        return gsd_hoomd.open(path, mode="rb")


@pytest.mark.parametrize("frame", ["lab", "plate"])
def test_gsd_round_trip(work_dir, frame):
    h5md, path = os.path.join(work_dir, "snapshots.h5"), os.path.join(work_dir, "snapshots.gsd")
    synthetic.write_h5md(h5md)
    snapshots = gs.read_snapshots(h5md, frame=frame)
    gs.to_gsd(snapshots, path)
    frames = snapshots.frames
    with _open_for_reading(path) as trajectory:
        assert len(trajectory) == len(frames["step"]) == 3
        for i, frame_ in enumerate(trajectory):
            assert frame_.configuration.step == frames["step"][i]
            assert frame_.particles.N == synthetic.PARTICLES
            assert list(frame_.particles.types) == ["grain"]
            box = frame_.configuration.box
            assert box[0] == box[1] == synthetic.WIDTH
            shift = frame_.log["granular_shaker/z_shift"][0]
            position = frame_.particles.position.astype(float)
            # float32 in GSD: equal to a few units in the last place of the largest coordinate.
            np.testing.assert_allclose(position + [synthetic.WIDTH / 2, synthetic.WIDTH / 2,
                                                   -shift], frames["position"][i], atol=1e-5)
            np.testing.assert_allclose(frame_.particles.velocity, frames["velocity"][i],
                                       atol=1e-6)
            assert np.all(np.abs(position) <= np.array(box[:3]) / 2)  # inside the GSD box
            assert frame_.log["granular_shaker/plate_position"][0] == \
                frames["plate_position"][i]
            assert frame_.log["granular_shaker/time"][0] == frames["time"][i]
    expected_height = synthetic.CEILING + (frames["plate_position"].max() if frame == "lab" else 0)
    assert box[2] == pytest.approx(expected_height, rel=1e-6)
