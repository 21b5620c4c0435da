"""MD particle snapshots (H5MD 1.1), and their export to GSD for HOOMD-blue tools and OVITO.

Layout: root group `h5md`; `/particles/all/box` (attributes dimension, boundary; dataset
`edges` = [W, W, ceiling]); `/particles/all/position` and `/velocity`, each with `step`, `time`
and `value` (F x N x 3, lab frame); `/observables/plate_position`, `plate_velocity`, `phase`
and `cycle`, each with `step`, `time` and `value`; a `units` attribute on every `value`; the
run file's provenance as root attributes, and `kind` = "shaker md particles". `shaker md`
writes it as RUN.particles.h5 when `md.snapshot_phases` is set.
"""
from collections import namedtuple
from dataclasses import dataclass

import h5py
import numpy as np

from ._common import (SchemaError, Table, check_frame, check_schema_version, provenance, text)

KIND = "shaker md particles"
OBSERVABLES = ("plate_position", "plate_velocity", "phase", "cycle")
_TIME_UNITS = "sqrt(sigma/g)"
_Element = namedtuple("_Element", "step time time_units value units")


@dataclass
class Snapshots:
    """Particle snapshots read into numpy arrays, one leading axis over the F frames.

    frames: `step`, `time` (F), `position`, `velocity` (F x N x 3, in this frame), and the
    observables at the same steps, `plate_position`, `plate_velocity` (the plate's lab-frame
    motion), `phase`, `cycle` (F). box_edges: [W, W, ceiling]; boundary: per axis, "periodic"
    or "none". In the plate frame heights are measured from the plate and the vertical velocity
    is relative to it.
    """
    path: str
    frame: str
    attributes: dict
    configuration: dict
    box_edges: np.ndarray
    boundary: list
    frames: Table


def read_snapshots(path, frame="lab"):
    """Read an H5MD snapshot file of `shaker md`; `frame` "lab" (as stored) or "plate"."""
    check_frame(frame)
    with h5py.File(path, "r") as f:
        if "h5md" not in f:
            raise SchemaError(f"{path}: no group /h5md; not an H5MD file")
        version = f["h5md"].attrs.get("version")
        if version is not None and int(np.asarray(version).ravel()[0]) != 1:
            raise SchemaError(f"{path}: H5MD version {list(np.asarray(version))}; this reader "
                              "knows H5MD 1.x")
        check_schema_version(f.attrs, path)
        kind = text(f.attrs.get("kind", KIND))
        if kind != KIND:
            raise SchemaError(f"{path}: root attribute kind is '{kind}', not '{KIND}'")
        attributes, configuration = provenance(f.attrs)
        particles = _required(f, "particles/all", path)
        box = _required(particles, "box", path)
        edges = _required(box, "edges", path)[()]
        boundary = [text(b) for b in box.attrs["boundary"]]
        position = _element(particles, "position", path)
        velocity = _element(particles, "velocity", path)
        if not np.array_equal(position.step, velocity.step):
            raise SchemaError(f"{path}: position and velocity are stored at different steps")
        frames = Table({"step": position.step, "time": position.time,
                        "position": position.value, "velocity": velocity.value},
                       {"step": "1", "time": position.time_units, "position": position.units,
                        "velocity": velocity.units})
        observables = _required(f, "observables", path)
        for name in OBSERVABLES:
            element = _element(observables, name, path)
            row_of_step = {int(s): row for row, s in enumerate(element.step)}
            missing = [int(s) for s in frames["step"] if int(s) not in row_of_step]
            if missing:
                raise SchemaError(f"{path}: /observables/{name} has no value at the snapshots' "
                                  f"steps {missing[:5]}")
            frames[name] = element.value[[row_of_step[int(s)] for s in frames["step"]]]
            frames.units[name] = element.units
    if frame == "plate":
        for name, plate in (("position", "plate_position"), ("velocity", "plate_velocity")):
            frames[name] = frames[name].copy()
            frames[name][:, :, 2] -= frames[plate][:, None]
    return Snapshots(str(path), frame, attributes, configuration, np.asarray(edges, float),
                     boundary, frames)


def to_gsd(snapshots, path):
    """Write `snapshots` as a GSD trajectory (HOOMD schema), one frame per snapshot.

    GSD boxes are centred on the origin: x and y are shifted by -W/2, and z so that the box
    spans every height the snapshots' frame can hold (the ceiling above the plate's lowest and
    highest position). The shift and the plate's position and velocity are in each frame's log
    (`granular_shaker/z_shift`, `granular_shaker/plate_position`, `.../plate_velocity`).
    Positions are stored as float32, as GSD does.
    """
    import gsd.hoomd

    frames = snapshots.frames
    width_x, width_y, ceiling = (float(e) for e in snapshots.box_edges)
    plate = frames["plate_position"] if snapshots.frame == "lab" else np.zeros(len(frames["step"]))
    bottom, top = min(0.0, plate.min()), ceiling + max(0.0, plate.max())
    height = top - bottom
    shift = np.array([-width_x / 2, -width_y / 2, -bottom - height / 2])
    make_frame = getattr(gsd.hoomd, "Frame", None) or gsd.hoomd.Snapshot
    with _open_for_writing(gsd.hoomd, path) as trajectory:
        for i, step in enumerate(frames["step"]):
            frame = make_frame()
            frame.configuration.step = int(step)
            frame.configuration.dimensions = 3
            frame.configuration.box = [width_x, width_y, height, 0, 0, 0]
            count = frames["position"].shape[1]
            frame.particles.N = count
            frame.particles.types = ["grain"]
            frame.particles.typeid = np.zeros(count, dtype=np.uint32)
            frame.particles.diameter = np.ones(count, dtype=np.float32)
            frame.particles.position = (frames["position"][i] + shift).astype(np.float32)
            frame.particles.velocity = frames["velocity"][i].astype(np.float32)
            frame.log = {"granular_shaker/z_shift": np.array([shift[2]]),
                         "granular_shaker/time": np.array([frames["time"][i]]),
                         "granular_shaker/plate_position": np.array([frames["plate_position"][i]]),
                         "granular_shaker/plate_velocity": np.array([frames["plate_velocity"][i]])}
            trajectory.append(frame)


def _open_for_writing(hoomd, path):
    # gsd before 2.8 names the write mode "wb", later versions "w".
    try:
        return hoomd.open(str(path), mode="w")
    except ValueError:
        return hoomd.open(str(path), mode="wb")


def _required(group, name, path):
    if name not in group:
        raise SchemaError(f"{path}: no {group.name.rstrip('/')}/{name}")
    return group[name]


def _units(dataset, path):
    # The project writes `units`; H5MD's own name is `unit`.
    for key in ("units", "unit"):
        if key in dataset.attrs:
            return text(dataset.attrs[key])
    raise SchemaError(f"{path}: dataset {dataset.name} has no 'units' attribute")


def _element(group, name, path):
    """An H5MD time-dependent element: its `step`, `time` and `value` with their units."""
    element = _required(group, name, path)
    for part in ("step", "time", "value"):
        _required(element, part, path)
    time = element["time"]
    time_units = _units(time, path) if {"units", "unit"} & set(time.attrs) else _TIME_UNITS
    return _Element(element["step"][()], time[()], time_units, element["value"][()],
                    _units(element["value"], path))
