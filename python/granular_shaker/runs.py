"""The run file of `shaker md` and `shaker continuum` (docs/output-schema.md, "The run file")."""
from dataclasses import dataclass, field

import h5py
import numpy as np

from ._common import (SchemaError, Table, check_frame, check_schema_version, provenance,
                      read_group, text)

# Profile datasets that are undefined in a bin where the MD found no particle.
# n_se is defined there: a density of 0 in every sample has no spread (the solver writes 0).
_UNDEFINED_WHEN_EMPTY = ("uz", "T", "uz_se", "T_se")


@dataclass
class Run:
    """A run file read into numpy arrays.

    profiles: K x B arrays (`z`, `n`, `nu`, `uz`, `T`; MD also `samples`, `n_se`, `uz_se`,
    `T_se`) and the per-phase arrays of length K (`time`, `phase`, `plate_z`, `plate_v`,
    `bin_height`); timeseries: one array per column; cycle_samples (MD only, else None): the sums
    behind the MD profiles; replica_timeseries: the series of replicas 1 .. R-1 of an MD
    ensemble (empty for a single run). Each Table has the units of its arrays in `.units`.

    In the plate frame heights are measured from the plate and vertical velocities relative to
    it; `plate_z` and `plate_v` stay the plate's lab-frame motion, which the frame subtracts.
    """
    path: str
    frame: str
    attributes: dict
    configuration: dict
    profiles: Table
    timeseries: Table
    cycle_samples: Table = None
    replica_timeseries: list = field(default_factory=list)

    @property
    def solver(self):
        return self.attributes["solver"]

    def plate_height(self):
        """Height of the plate at each stored phase in this frame (0 in the plate frame)."""
        plate = self.profiles["plate_z"]
        return plate if self.frame == "lab" else np.zeros_like(plate)


def read_run(path, frame="lab"):
    """Read a run file; `frame` "lab" (as stored) or "plate"."""
    check_frame(frame)
    with h5py.File(path, "r") as f:
        version = check_schema_version(f.attrs, path)
        if "kind" in f.attrs:
            raise SchemaError(f"{path}: a '{text(f.attrs['kind'])}' file, not a run file "
                              "(read_fields reads fields files, read_snapshots particle files)")
        for group in ("profiles", "timeseries"):
            if group not in f:
                raise SchemaError(f"{path}: no group /{group}; not a complete run file")
        attributes, configuration = provenance(f.attrs)
        profiles = read_group(f["profiles"], path)
        timeseries = _read_series(f["timeseries"], path, version)
        cycle_samples = None
        if "cycle_samples" in f:
            cycle_samples = read_group(f["cycle_samples"], path)
            cycle_samples.units["bin_volume"] = "sigma^3"
            cycle_samples["bin_volume"] = float(f["cycle_samples"].attrs["bin_volume"])
        replicas = []
        if "replica_timeseries" in f:
            g = f["replica_timeseries"]
            replicas = [_read_series(g[f"replica_{r:05d}"], path, version)
                        for r in range(1, int(g.attrs["replicas"]))]
    _mask_empty_bins(profiles)
    if frame == "plate":
        _to_plate_frame(profiles, timeseries, cycle_samples, replicas)
    return Run(str(path), frame, attributes, configuration, profiles, timeseries, cycle_samples,
               replicas)


# Time-series columns schema version 1 named otherwise (docs/output-schema.md, "Time series").
_VERSION_1_COLUMNS = {"kinetic": "kinetic_energy", "potential": "potential_energy",
                      "plate_work": "accumulated_drive_work",
                      "accumulated_body_work": "accumulated_drive_work",
                      "collisional_loss": "accumulated_collisional_loss",
                      "energy_closure": "energy_budget_relative_residual"}


def _read_series(group, path, version):
    columns = [c.strip() for c in text(group.attrs["columns"]).split(",")]
    series = read_group(group, path, columns)
    if version == 1:
        series = Table({_VERSION_1_COLUMNS.get(name, name): values
                        for name, values in series.items()},
                       {_VERSION_1_COLUMNS.get(name, name): units
                        for name, units in series.units.items()})
    return series


def _mask_empty_bins(profiles):
    """MD bins no particle was found in: n and nu 0, the mean velocity, the temperature and
    their standard errors NaN, whether the file stores them as 0 or NaN."""
    if "samples" not in profiles:
        return
    empty = profiles["samples"] == 0
    for name in ("n", "nu"):
        profiles[name] = np.where(empty, 0.0, profiles[name])
    for name in _UNDEFINED_WHEN_EMPTY:
        if name in profiles:
            profiles[name] = np.where(empty, np.nan, profiles[name])


def _to_plate_frame(profiles, timeseries, cycle_samples, replicas):
    plate_z, plate_v = profiles["plate_z"][:, None], profiles["plate_v"][:, None]
    profiles["z"] = profiles["z"] - plate_z
    profiles["uz"] = profiles["uz"] - plate_v
    for series in [timeseries, *replicas]:
        series["com_z"] = series["com_z"] - series["plate_z"]
    if cycle_samples is not None:
        # Rows are phase-major: row k S + s is sample s at phase k.
        samples_per_phase = cycle_samples["count"].shape[0] // len(plate_v)
        v = np.repeat(plate_v, samples_per_phase, axis=0)
        count, vz = cycle_samples["count"], cycle_samples["vz"]
        cycle_samples["v2"] = cycle_samples["v2"] - 2 * v * vz + v * v * count
        cycle_samples["vz"] = vz - v * count
