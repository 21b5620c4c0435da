"""ctest unit.RunFile.ReadableWithH5py: reads a run file with h5py (not with the project's
reader) and checks its fields.

    python3 -m pytest verification/unit/test_run_file_h5py.py --sample-writer WRITE_SAMPLE_RUN_FILE

The helper program writes the sample run of sample_run.hpp into the test's temporary
directory; this test checks the layout of docs/output-schema.md and every value (all dyadic
rationals, so compared exactly).
"""
import os
import re
import subprocess
import tomllib
from pathlib import Path

import h5py
import numpy as np
import pytest

PHASES, BINS = 3, 5


@pytest.fixture
def sample_writer(request):
    path = request.config.getoption("--sample-writer")
    if not path:
        pytest.skip("needs --sample-writer PROGRAM (write_sample_run_file, built by cmake)")
    return os.path.abspath(path)


def expected_profiles():
    k = np.arange(PHASES, dtype=float)[:, None]
    i = np.arange(BINS, dtype=float)[None, :]
    ones = np.ones((PHASES, BINS))
    return {
        "z": (0.5 * i + 0.25) * ones,
        "n": 0.125 * (i + 1) + k,
        "nu": 0.0625 * (i + 1) + 0.125 * k,
        "uz": -0.75 * i + k,
        "T": 0.0625 * (i + 1) * (k + 1),
        "samples": 16.0 * i + k,
        "n_se": 0.03125 * (i + 1) * ones,
        "uz_se": 0.015625 * (i + k),
        "T_se": 0.25 * i * ones,
    }


def test_run_file_read_by_h5py(sample_writer, work_dir):
    helper, directory = sample_writer, work_dir
    path = Path(directory) / "sample.h5"
    subprocess.run([helper, str(path)], check=True)
    assert sorted(p.name for p in Path(directory).iterdir()) == ["sample.h5"], \
        "only the final file exists after the write"
    with h5py.File(path, "r") as f:
        a = f.attrs
        assert int(a["schema_version"]) == 2, f"schema_version {a['schema_version']}"
        for name in ("program_version", "git_commit", "created", "solver", "model_variant",
                     "configuration"):
            assert isinstance(a[name], str) and a[name] != "", f"attribute {name} is text"
        assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", a["created"]) is not None, \
            f"created is ISO 8601 UTC: {a['created']}"
        assert a["solver"] == "synthetic", f"solver {a['solver']}"
        assert a["model_variant"] == "constant e; paper transport", "model_variant"
        assert float(a["restitution_for_analysis"]) == 0.8, "restitution_for_analysis"
        configuration = tomllib.loads(a["configuration"])
        assert configuration["material"]["e"] == 0.8, "configuration material.e"
        assert configuration["case"]["name"] == "sample run", "configuration case.name"
        assert configuration["layer"]["particles"] == 3937, "configuration layer.particles"
        assert configuration["shaker"]["gamma"] == 3.0, "configuration shaker.gamma"

        profiles = f["profiles"]
        k = np.arange(PHASES, dtype=float)
        for name, values in {"time": 10.0 + 0.25 * k, "phase": 0.25 * k,
                             "plate_z": 1.5 * k, "plate_v": -0.5 * k,
                             "bin_height": 0.5 * np.ones(PHASES)}.items():
            data = profiles[name][()]
            assert data.shape == (PHASES,) and np.array_equal(data, values), \
                f"profiles/{name} = {data}"
        for name, values in expected_profiles().items():
            data = profiles[name][()]
            assert data.dtype == np.float64, f"profiles/{name} dtype {data.dtype}"
            assert data.shape == (PHASES, BINS), f"profiles/{name} shape {data.shape}"
            assert data.shape == values.shape and np.array_equal(data, values), \
                f"profiles/{name} values"

        series = f["timeseries"]
        columns = series.attrs["columns"].split(",")
        assert columns == ["t", "phase", "plate_z", "com_z"], f"timeseries columns {columns}"
        expected = {"t": [0.0, 0.5, 1.0, 1.5], "phase": [0.0, 0.0475, 0.095, 0.1425],
                    "plate_z": [0.0, -0.25, 0.5, 0.125], "com_z": [4.5, 4.75, 5.0, 5.25]}
        for name, values in expected.items():
            assert np.array_equal(series[name][()], np.array(values)), \
                f"timeseries/{name} = {series[name][()]}"

        # Every dataset states its units (docs/output-schema.md, docs/units.md).
        units = {}
        f.visititems(lambda name, item: units.__setitem__(name, item.attrs.get("units"))
                     if isinstance(item, h5py.Dataset) else None)
        expected_units = {"profiles/z": "sigma", "profiles/n": "1/sigma^3", "profiles/nu": "1",
                          "profiles/uz": "sqrt(g sigma)", "profiles/T": "g sigma",
                          "profiles/time": "sqrt(sigma/g)", "profiles/phase": "1",
                          "timeseries/t": "sqrt(sigma/g)", "timeseries/com_z": "sigma"}
        for name, unit in expected_units.items():
            assert units.get(name) == unit, f"{name} units {units.get(name)!r}, expected {unit!r}"
        missing = sorted(name for name, unit in units.items() if not unit)
        assert not missing, f"datasets without units: {missing}"
