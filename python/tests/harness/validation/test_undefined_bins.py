"""ctest validation.undefined_bins: an MD-like run file with empty bins (NaN u_z and T, as
the MD writes them) and the plate raised to z = 2.3 through its lab-frame bins, analysed by
the real `shaker analyze` as the validation runner calls it.

Checks: the layer bottom and the 1 % mass bottom are at the plate, not below it (the bin
[2, 3] straddles the plate; unclipped, both would be below it), the gaps are 0, the layer
temperature is the n-weighted mean of the defined T (nothing undefined leaks into it), the
per-phase values reach the runner's view as numbers, and the profiles CSV writes `nan` where
u_z, T and Ma are undefined and numbers everywhere else (read as the reports read it).

    python3 -m pytest python/tests/harness/validation/test_undefined_bins.py --shaker SHAKER
"""
import math
import os
import subprocess

import h5py
import numpy as np

from granular_shaker.reports import report_common
from granular_shaker.validation import views as runner

PLATE_Z = 2.3
BINS = 40
Z = np.arange(BINS) + 0.5


def raised_plate_profile():
    """nu, u_z, T on bins of height 1 from z = 0: empty below the plate, the straddling bin
    [2, 3] at nu 0.3, a layer of nu 0.5 up to z = 16, a thin gas to z = 26, empty above."""
    nu = np.where(Z < 2, 0.0, np.where(Z < 3, 0.3, np.where(Z < 16, 0.5,
                                                            np.where(Z < 26, 0.005, 0.0))))
    T = np.where(nu > 0, 0.5 + 0.1 * Z, np.nan)
    uz = np.where(nu > 0, -0.2, np.nan)
    return nu, uz, T


def write_run_file(path, configuration):
    nu, uz, T = raised_plate_profile()
    rows = {"z": [Z, Z], "nu": [nu, nu], "uz": [uz, uz], "T": [T, T]}
    rows["n"] = [x * 6 / math.pi for x in rows["nu"]]
    with h5py.File(path, "w") as h:
        for key, value in (("program_version", "synthetic"), ("git_commit", "synthetic"),
                           ("created", "2000-01-01T00:00:00Z"), ("solver", "synthetic"),
                           ("model_variant", "MD-like bins with a raised plate"),
                           ("configuration", configuration)):
            h.attrs[key] = value
        h.attrs["schema_version"] = np.int64(1)
        h.attrs["restitution_for_analysis"] = 0.9
        g = h.create_group("profiles")
        for name, values in (("time", [0.0, 5.0]), ("phase", [0.0, 0.5]),
                             ("plate_z", [PLATE_Z, PLATE_Z]), ("plate_v", [0.0, 0.0]),
                             ("bin_height", [1.0, 1.0])):
            g.create_dataset(name, data=np.asarray(values, dtype=float))
        for name, values in rows.items():
            g.create_dataset(name, data=np.array(values, dtype=float))
        s = h.create_group("timeseries")
        s.attrs["columns"] = "t,phase,plate_z,com_z"
        for name, values in (("t", [0.0, 5.0]), ("phase", [0.0, 0.5]),
                             ("plate_z", [PLATE_Z, PLATE_Z]), ("com_z", [9.0, 9.0])):
            s.create_dataset(name, data=np.asarray(values, dtype=float))


def test_undefined_bins_and_the_plate(shaker, work_dir):
    configuration = subprocess.run([shaker, "config"], capture_output=True, text=True,
                                   check=True).stdout
    path = os.path.join(work_dir, "raised.h5")
    write_run_file(path, configuration)
    data = runner.analyze(shaker, path, os.path.join(work_dir, "raised.json"))
    view = runner.RunView("raised", "md", "ok", path)
    runner.fill_view(view, data)
    a = view.analysis

    nu, uz, T = raised_plate_profile()
    n = nu * 6 / math.pi
    unclipped_crossing = 1.5 + 0.026 / 0.3
    unclipped_mass = 2.0 + 0.01 * n.sum() / n[2]
    assert unclipped_crossing < PLATE_Z and unclipped_mass < PLATE_Z, "the case tests nothing"
    for k in range(2):
        assert a["layer_bottom"][k] == PLATE_Z, \
            f"layer bottom {a['layer_bottom'][k]} at phase {k}, the plate at {PLATE_Z}"
        assert a["mass_bottom"][k] == PLATE_Z, \
            f"1 % mass bottom {a['mass_bottom'][k]} at phase {k}, the plate at {PLATE_Z}"
        assert a["layer_gap"][k] == 0.0 and a["mass_gap"][k] == 0.0
        assert abs(a["layer_top"][k] - (15.5 + (0.5 - 0.026) / (0.5 - 0.005))) < 1e-9

    # The layer temperature: n-weighted over the bins inside the layer, all of them defined.
    inside = (Z >= a["layer_bottom"][0]) & (Z <= a["layer_top"][0])
    expected = np.nansum(n[inside] * T[inside]) / n[inside & np.isfinite(T)].sum()
    assert abs(a["layer_temperature"][0] - expected) < 1e-12 * expected, \
        f"layer temperature {a['layer_temperature'][0]} against {expected}"
    for name in ("center_of_mass", "max_mach", "knudsen_mass_fraction",
                 "temperature_slope_above_layer"):
        assert np.all(np.isfinite(a[name])), f"{name} = {a[name]}: undefined bins leaked in"
    assert abs(a["temperature_slope_above_layer"][0] - 0.1) < 1e-12

    profiles, units = report_common.read_shaker_csv(path + ".profiles.csv")
    assert units["T"] == "g sigma"
    empty = profiles["n"] == 0
    assert empty.sum() == 2 * (2 + 14), "two phases of 2 bins below the plate, 14 above the gas"
    for column in ("uz", "T", "mach"):
        assert np.all(np.isnan(profiles[column][empty])), f"{column} of an empty bin is not nan"
        assert np.all(np.isfinite(profiles[column][~empty])), f"{column} is nan in a full bin"
