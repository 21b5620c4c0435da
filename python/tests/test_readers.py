"""The readers of granular_shaker on files written here with h5py from known numbers: values,
units, the lab and plate frames, empty MD bins, and the files they refuse."""
import os

import h5py
import numpy as np
import pytest

import granular_shaker as gs
import synthetic_files as synthetic


@pytest.mark.parametrize("empty_value", [np.nan, 0.0], ids=["empty_nan", "empty_zero"])
def test_md_run_lab_frame_values_units_and_empty_bins(work_dir, empty_value):
    path = os.path.join(work_dir, "md.h5")
    profiles, series = synthetic.write_md_run(path, empty_value)
    run = gs.read_run(path)
    assert run.solver == "md" and run.frame == "lab"
    assert run.configuration["shaker"]["gamma"] == 3.0
    assert run.attributes["schema_version"] == 1
    assert run.profiles.units == synthetic.PROFILE_UNITS
    assert run.timeseries.units == {k: synthetic.SERIES_UNITS[k] for k in series}
    assert list(run.timeseries) == list(series)
    for name in ("z", "n", "plate_z", "samples"):
        np.testing.assert_array_equal(run.profiles[name], profiles[name])
    empty = run.profiles["samples"] == 0
    assert empty[:, synthetic.EMPTY_BIN].all() and empty.sum() == synthetic.PHASES
    # Empty bins: no particle, so n = nu = 0; the rest is undefined, whatever was stored.
    for name in ("n", "nu"):
        assert np.all(run.profiles[name][empty] == 0)
    for name in ("uz", "T", "uz_se", "T_se"):
        assert np.all(np.isnan(run.profiles[name][empty])), name
        assert np.all(np.isfinite(run.profiles[name][~empty])), name
    np.testing.assert_array_equal(run.profiles["n_se"], profiles["n_se"])  # defined everywhere
    np.testing.assert_array_equal(run.profiles["T"][~empty], profiles["T"][~empty])
    assert len(run.replica_timeseries) == 1
    np.testing.assert_array_equal(run.replica_timeseries[0]["com_z"], series["com_z"] + 0.5)
    assert run.cycle_samples["bin_volume"] == synthetic.WIDTH ** 2 * synthetic.BIN_HEIGHT
    assert run.cycle_samples.units["vz"] == "sqrt(g sigma)"


def _pooled_velocity_and_temperature(samples):
    """u_z and T of the pooled /cycle_samples (output-schema.md), phase by phase."""
    K, S = synthetic.PHASES, synthetic.SAMPLES
    pool = {name: samples[name].reshape(K, S, -1).sum(axis=1)
            for name in ("count", "vx", "vy", "vz", "v2")}
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = [pool[c] / pool["count"] for c in ("vx", "vy", "vz")]
        return mean[2], (pool["v2"] / pool["count"] - sum(m * m for m in mean)) / 3


def test_md_run_plate_frame(work_dir):
    path = os.path.join(work_dir, "md.h5")
    synthetic.write_md_run(path)
    lab, plate = gs.read_run(path), gs.read_run(path, frame="plate")
    assert plate.frame == "plate"
    z_p, v_p = lab.profiles["plate_z"][:, None], lab.profiles["plate_v"][:, None]
    assert np.ptp(z_p) > 10 and np.ptp(v_p) > 3  # so the shift is seen
    np.testing.assert_array_equal(plate.profiles["z"], lab.profiles["z"] - z_p)
    np.testing.assert_array_equal(plate.profiles["uz"], lab.profiles["uz"] - v_p)
    np.testing.assert_array_equal(plate.profiles["T"], lab.profiles["T"])
    np.testing.assert_array_equal(plate.profiles["plate_z"], lab.profiles["plate_z"])
    np.testing.assert_array_equal(plate.plate_height(), 0 * lab.plate_height())
    np.testing.assert_allclose(plate.timeseries["com_z"], 2.0 + 0.1 * np.arange(9), rtol=1e-14)
    np.testing.assert_allclose(plate.replica_timeseries[0]["com_z"], 2.5 + 0.1 * np.arange(9),
                               rtol=1e-14)
    # The cycle sums in the plate frame pool to the plate-frame u_z and to the same T.
    uz_lab, T_lab = _pooled_velocity_and_temperature(lab.cycle_samples)
    uz_plate, T_plate = _pooled_velocity_and_temperature(plate.cycle_samples)
    filled = lab.profiles["samples"] > 0
    np.testing.assert_allclose(uz_lab[filled], lab.profiles["uz"][filled], rtol=1e-13)
    np.testing.assert_allclose(uz_plate[filled], plate.profiles["uz"][filled], rtol=1e-12,
                               atol=1e-12)
    np.testing.assert_allclose(T_plate[filled], T_lab[filled], rtol=1e-11)


def test_continuum_run_plate_frame_puts_every_row_on_the_same_cells(work_dir):
    path = os.path.join(work_dir, "continuum.h5")
    profiles, series = synthetic.write_continuum_run(path)
    lab, plate = gs.read_run(path), gs.read_run(path, frame="plate")
    assert lab.solver == "continuum" and lab.cycle_samples is None
    assert lab.replica_timeseries == []
    np.testing.assert_array_equal(lab.profiles["z"], profiles["z"])
    cells = (np.arange(synthetic.BINS) + 0.5) * synthetic.BIN_HEIGHT
    np.testing.assert_allclose(plate.profiles["z"], np.tile(cells, (synthetic.PHASES, 1)),
                               atol=1e-13)
    np.testing.assert_allclose(plate.profiles["uz"], np.tile(0.3 * cells, (synthetic.PHASES, 1)),
                               atol=1e-13)
    np.testing.assert_allclose(plate.timeseries["com_z"], 3.0, rtol=1e-14)
    assert lab.timeseries.units["total_mass"] == "m / sigma^2"


def with_columns(path, columns):
    """Adds time-series columns to a run file, in /timeseries and every replica's series."""
    with h5py.File(path, "r+") as f:
        groups = [f["timeseries"], *f["replica_timeseries"].values()]
        for group in groups:
            for name, value in columns.items():
                group.create_dataset(name, data=np.full(group["t"].shape, value))
                group[name].attrs["units"] = "1"
            group.attrs["columns"] = group.attrs["columns"] + "," + ",".join(columns)


@pytest.mark.parametrize("version", [1, 2])
def test_version_1_series_columns_get_their_present_names(work_dir, version):
    path = os.path.join(work_dir, "run.h5")
    synthetic.write_md_run(path, schema_version=version)
    old = {"kinetic": 1.0, "potential": 2.0, "plate_work": 3.0, "collisional_loss": 4.0,
           "energy_closure": 5.0}
    with_columns(path, old)
    run = gs.read_run(path)
    present = {"kinetic_energy": 1.0, "potential_energy": 2.0, "accumulated_drive_work": 3.0,
               "accumulated_collisional_loss": 4.0, "energy_budget_relative_residual": 5.0}
    expected = present if version == 1 else old
    for series in (run.timeseries, run.replica_timeseries[0]):
        for name, value in expected.items():
            np.testing.assert_array_equal(series[name], value)
            assert series.units[name] == "1"
        assert not set(old if version == 1 else present) & set(series)


def test_run_refusals(work_dir):
    path = os.path.join(work_dir, "run.h5")
    synthetic.write_md_run(path, schema_version=3)
    with pytest.raises(gs.SchemaError, match=r"schema_version 3 is not one this reader knows"):
        gs.read_run(path)
    synthetic.write_md_run(path, units=False)
    with pytest.raises(gs.SchemaError, match=r"/profiles/\S+ has no 'units' attribute"):
        gs.read_run(path)
    with h5py.File(path, "w") as f:
        f.attrs["solver"] = "md"
    with pytest.raises(gs.SchemaError, match="no root attribute 'schema_version'"):
        gs.read_run(path)
    fields = os.path.join(work_dir, "run.fields.h5")
    synthetic.write_fields(fields)
    with pytest.raises(gs.SchemaError, match="'shaker continuum fields' file, not a run file"):
        gs.read_run(fields)
    synthetic.write_md_run(path)
    with pytest.raises(ValueError, match="frame = 'container': allowed values are 'lab', 'plate'"):
        gs.read_run(path, frame="container")


def test_fields_read_only_the_datasets_named(work_dir):
    path = os.path.join(work_dir, "run.fields.h5")
    written = synthetic.write_fields(path)
    for frame in ("lab", "plate"):
        density = gs.read_fields(path, frame=frame, names=("n",))
        assert {"n", "z", "phase", "cycle"} <= set(density.snapshots)
        assert not {"points", "ux", "uz", "T", "velocity"} & set(density.snapshots)
        whole = gs.read_fields(path, frame=frame)
        np.testing.assert_array_equal(density.snapshots["z"], whole.snapshots["z"])
        for s, w in enumerate(written):
            np.testing.assert_array_equal(density.snapshots["n"][s], w["n"])
    with pytest.raises(ValueError, match="unknown datasets \\['rho'\\]"):
        gs.read_fields(path, names=("rho",))


def test_fields_frames_and_horizontal_averages(work_dir):
    path = os.path.join(work_dir, "run.fields.h5")
    written = synthetic.write_fields(path)
    lab, plate = gs.read_fields(path), gs.read_fields(path, frame="plate")
    nz = synthetic.NZ
    assert lab.shape == (synthetic.NX, synthetic.NY, nz) and lab.cell_size == synthetic.CELL
    assert lab.snapshots["n"].shape == (2, nz, synthetic.NY, synthetic.NX)
    assert lab.snapshots.units["uz"] == "sqrt(g sigma)" and lab.snapshots.units["z"] == "sigma"
    assert lab.snapshots.units["plate_v"] == "sqrt(g sigma)"
    cells = (np.arange(nz) + 0.5) * synthetic.CELL
    for s, w in enumerate(written):
        np.testing.assert_array_equal(lab.snapshots["points"][s], w["points"])
        np.testing.assert_array_equal(lab.snapshots["z"][s], cells + w["plate_z"])
        np.testing.assert_allclose(plate.snapshots["z"][s], cells, atol=1e-13)
        np.testing.assert_allclose(plate.snapshots["points"][s][:, 2],
                                   w["points"][:, 2] - w["plate_z"], atol=1e-13)
        np.testing.assert_array_equal(plate.snapshots["uz"][s], w["uz"] - w["plate_v"])
        np.testing.assert_array_equal(plate.snapshots["T"][s], w["T"])
        np.testing.assert_array_equal(lab.snapshots["velocity"][s], w["velocity"])
        np.testing.assert_array_equal(plate.snapshots["velocity"][s][..., 2],
                                      w["uz"] - w["plate_v"])
        assert lab.snapshots["cycle"][s] == 10
        averages = lab.horizontal_averages()
        n = w["n"].reshape(nz, -1)
        np.testing.assert_allclose(averages["n"][s], n.mean(axis=1), rtol=1e-14)
        np.testing.assert_allclose(averages["T"][s], (n * w["T"].reshape(nz, -1)).sum(axis=1)
                                   / n.sum(axis=1), rtol=1e-14)
    assert averages.units["T"] == "g sigma"
    run_path = os.path.join(work_dir, "run.h5")
    synthetic.write_continuum_run(run_path)
    with pytest.raises(gs.SchemaError, match="kind is '\\(none\\)', not 'shaker continuum fields'"):
        gs.read_fields(run_path)


def test_snapshots_frames_units_and_observables_at_the_particle_steps(work_dir):
    path = os.path.join(work_dir, "snapshots.h5")
    written = synthetic.write_h5md(path)
    lab, plate = gs.read_snapshots(path), gs.read_snapshots(path, frame="plate")
    np.testing.assert_array_equal(lab.box_edges, [synthetic.WIDTH, synthetic.WIDTH,
                                                  synthetic.CEILING])
    assert lab.boundary == ["periodic", "periodic", "none"]
    np.testing.assert_array_equal(lab.frames["step"], synthetic.PARTICLE_STEPS)
    for name in ("position", "velocity", "plate_position", "plate_velocity", "time"):
        np.testing.assert_array_equal(lab.frames[name], written[name])
    assert lab.frames.units == {"step": "1", "time": "sqrt(sigma/g)", "position": "sigma",
                                "velocity": "sqrt(g sigma)", "plate_position": "sigma",
                                "plate_velocity": "sqrt(g sigma)", "phase": "1", "cycle": "1"}
    assert np.ptp(written["plate_position"]) > 1
    np.testing.assert_array_equal(plate.frames["position"][:, :, :2],
                                  written["position"][:, :, :2])
    np.testing.assert_array_equal(plate.frames["position"][:, :, 2], written["position"][:, :, 2]
                                  - written["plate_position"][:, None])
    np.testing.assert_array_equal(plate.frames["velocity"][:, :, 2], written["velocity"][:, :, 2]
                                  - written["plate_velocity"][:, None])
    assert plate.frames["position"][:, :, 2].min() >= 0.5  # every centre a radius above
    assert lab.configuration["md"]["box_width"] == synthetic.WIDTH


def test_snapshot_refusals(work_dir):
    path = os.path.join(work_dir, "snapshots.h5")
    synthetic.write_h5md(path, schema_version=3)
    with pytest.raises(gs.SchemaError, match="schema_version 3 is not one this reader knows"):
        gs.read_snapshots(path)
    synthetic.write_h5md(path, observable_steps=np.array([0, 20], dtype=np.int64))
    with pytest.raises(gs.SchemaError,
                       match=r"/observables/plate_position has no value at the .* steps \[30\]"):
        gs.read_snapshots(path)
    synthetic.write_md_run(path)
    with pytest.raises(gs.SchemaError, match="no group /h5md"):
        gs.read_snapshots(path)
    synthetic.write_h5md(path)
    with h5py.File(path, "a") as f:
        f.attrs["kind"] = "shaker md checkpoint"
    with pytest.raises(gs.SchemaError,
                       match="kind is 'shaker md checkpoint', not 'shaker md particles'"):
        gs.read_snapshots(path)


def test_analysis_json_from_text_and_path_in_both_frames(work_dir):
    text = synthetic.analysis_json()
    path = os.path.join(work_dir, "analysis.json")
    with open(path, "w") as f:
        f.write(text)
    lab, plate = gs.read_analysis_json(path), gs.read_analysis_json(text, frame="plate")
    assert lab.attributes["solver"] == "md" and lab.configuration["run"]["phases_per_cycle"] == 4
    plate_z = synthetic.plate(np.arange(synthetic.PHASES) / synthetic.PHASES)[0]
    np.testing.assert_allclose(lab.plate_z, plate_z, rtol=1e-15)
    com = lab.per_phase["center_of_mass"]
    assert com.unit == "sigma" and com.resolution is None
    np.testing.assert_allclose(com.value, plate_z + 5, rtol=1e-15)
    np.testing.assert_allclose(plate.per_phase["center_of_mass"].value, 5, rtol=1e-14)
    np.testing.assert_allclose(plate.per_phase["center_of_mass"].replicates,
                               [[4.9] * 4, [5] * 4, [5.1] * 4], rtol=1e-14)
    shock = plate.per_phase["shock_location"]
    np.testing.assert_allclose(shock.value, [np.nan, 2, 4, np.nan], rtol=1e-14)
    assert np.isnan(shock.error[0]) and shock.error[1] == 0.1
    # Already measured from the plate: the same in both frames.
    np.testing.assert_array_equal(plate.per_phase["layer_gap"].value, [1, 2, 3, 4])
    lifetime = plate.per_run["lifetime"]
    assert (lifetime.value, lifetime.error, lifetime.unit, lifetime.resolution) == \
        (0.2, 0.05, "1/f", 0.05)
    assert np.isnan(lifetime.replicates[2])
    assert plate.crossings["crossings_z80"]["value"] == 1.5


def test_analysis_json_refusals():
    with pytest.raises(gs.SchemaError, match="schema_version 2 is not one this reader knows"):
        gs.read_analysis_json(synthetic.analysis_json(schema_version=2))
    with pytest.raises(gs.SchemaError, match="schema 'shaker-compare': not 'shaker-analysis'"):
        gs.read_analysis_json(synthetic.analysis_json(schema="shaker-compare"))
