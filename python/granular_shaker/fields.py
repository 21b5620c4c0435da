"""The 3D fields file of `shaker continuum` (docs/output-schema.md, "3D continuum fields")."""
from dataclasses import dataclass

import h5py
import numpy as np

from ._common import (SchemaError, Table, check_frame, check_schema_version, provenance, text,
                      units_of)

KIND = "shaker continuum fields"
FIELD_NAMES = ("n", "ux", "uy", "uz", "T")
# Written by newer versions of shaker (nu, the velocity vector nz x ny x nx x 3, the cycle).
OPTIONAL_FIELD_NAMES = ("nu", "velocity")
# The snapshot groups' attributes and their units (output-schema.md).
_SNAPSHOT_ATTRIBUTES = {"time": "sqrt(sigma/g)", "phase": "1", "plate_z": "sigma",
                        "plate_v": "sqrt(g sigma)"}


@dataclass
class Fields:
    """A fields file read into numpy arrays, one leading axis over its S snapshots.

    snapshots: `time`, `phase`, `plate_z`, `plate_v` (S; the plate's lab-frame motion), `z`
    (S x nz, the cell centres' heights in this frame), `points` (S x P x 3, cell corners in this
    frame), and the fields `n`, `ux`, `uy`, `uz`, `T` (S x nz x ny x nx, z slowest), with `nu`,
    `velocity` (S x nz x ny x nx x 3) and `cycle` where the file has them. hexahedra:
    the corners of each cell (N x 8, VTK order). shape: (nx, ny, nz).
    """
    path: str
    frame: str
    attributes: dict
    configuration: dict
    cell_size: float
    shape: tuple
    hexahedra: np.ndarray
    snapshots: Table

    def horizontal_averages(self):
        """The run file's profile at each snapshot's phase: the mean of n over each horizontal
        layer of cells, and the n-weighted means of uz and T (S x nz each), with z."""
        s = self.snapshots
        n = s["n"].mean(axis=(2, 3))
        averages = Table({"z": s["z"], "n": n}, {"z": s.units["z"], "n": s.units["n"]})
        for name in ("uz", "T"):
            averages[name] = (s["n"] * s[name]).mean(axis=(2, 3)) / n
            averages.units[name] = s.units[name]
        return averages


def read_fields(path, frame="lab", names=None):
    """Read a fields file (`RUN.fields.h5`); `frame` "lab" (as stored) or "plate". `names`, if
    given, the datasets of each snapshot to read (of "points", FIELD_NAMES and
    OPTIONAL_FIELD_NAMES; the snapshots' attributes always): a reader of one field need not
    hold the others of a long run in memory."""
    check_frame(frame)
    every = ("points", *FIELD_NAMES, *OPTIONAL_FIELD_NAMES)
    wanted = every if names is None else tuple(names)
    unknown = sorted(set(wanted) - set(every))
    if unknown:
        raise ValueError(f"read_fields: unknown datasets {unknown}; allowed: {', '.join(every)}")
    with h5py.File(path, "r") as f:
        check_schema_version(f.attrs, path)
        kind = text(f.attrs.get("kind", "(none)"))
        if kind != KIND:
            raise SchemaError(f"{path}: root attribute kind is '{kind}', not '{KIND}'; not a "
                              "fields file (read run files with read_run)")
        attributes, configuration = provenance(f.attrs)
        nx, ny, nz = (int(f.attrs[k]) for k in ("nx", "ny", "nz"))
        h = float(f.attrs["cell_size"])
        names = sorted(k for k in f if k.startswith("snapshot_"))
        if not names:
            raise SchemaError(f"{path}: no snapshot_SSS groups")
        groups = [f[name] for name in names]
        snapshots = Table(
            {key: np.array([float(g.attrs[key]) for g in groups]) for key in _SNAPSHOT_ATTRIBUTES},
            _SNAPSHOT_ATTRIBUTES)
        for name in wanted:
            if name in OPTIONAL_FIELD_NAMES and name not in groups[0]:
                continue
            snapshots[name] = np.stack([g[name][()] for g in groups])
            snapshots.units[name] = units_of(groups[0][name], path)
        if "cycle" in groups[0].attrs:
            snapshots["cycle"] = np.array([int(g.attrs["cycle"]) for g in groups])
            snapshots.units["cycle"] = "1"
        hexahedra = f["hexahedra"][()]
    plate_z = snapshots["plate_z"]
    snapshots["z"] = (np.arange(nz) + 0.5) * h + plate_z[:, None]
    snapshots.units["z"] = _SNAPSHOT_ATTRIBUTES["plate_z"]
    if frame == "plate":
        snapshots["z"] = snapshots["z"] - plate_z[:, None]
        if "points" in snapshots:
            snapshots["points"] = snapshots["points"].copy()
            snapshots["points"][:, :, 2] -= plate_z[:, None]
        if "uz" in snapshots:
            snapshots["uz"] = snapshots["uz"] - snapshots["plate_v"][:, None, None, None]
        if "velocity" in snapshots:
            snapshots["velocity"] = snapshots["velocity"].copy()
            snapshots["velocity"][..., 2] -= snapshots["plate_v"][:, None, None, None]
    return Fields(str(path), frame, attributes, configuration, h, (nx, ny, nz), hexahedra,
                  snapshots)
