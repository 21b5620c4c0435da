"""What `shaker analyze RUN.h5 --json FILE` writes (docs/analysis.md)."""
import json
import math
import os
import tomllib
from dataclasses import dataclass

import numpy as np

from ._common import SchemaError, check_frame

SCHEMA = "shaker-analysis"
KNOWN_VERSIONS = (1,)
# Per-phase quantities that are lab-frame heights (docs/analysis.md, "Per phase").
LAB_FRAME_HEIGHTS = ("layer_bottom", "layer_top", "mass_bottom", "center_of_mass",
                     "shock_location", "shock_compressed_top", "shock_undisturbed_bottom")


@dataclass
class Quantity:
    """One analysis quantity: value and standard error (arrays over the stored phases for
    per-phase quantities, floats for per-run ones; NaN where undefined), its unit, the
    rounding error of a quantised value (`resolution`, or None) and the jackknife replicates
    (one row per left-out sample)."""
    value: object
    error: object
    unit: str
    resolution: object
    replicates: np.ndarray


@dataclass
class Analysis:
    """per_phase and per_run map the JSON names to Quantity; crossings maps a crossing column
    to its dict as written (mean per cycle `value`, `error`, `per_cycle`, `replicates`).
    `phase` is f t of each stored phase and `plate_z` the plate's lab-frame height there (also
    in per_phase). In the plate frame the per-phase heights of LAB_FRAME_HEIGHTS are measured
    from the plate; per-run quantities keep their definitions (docs/analysis.md)."""
    frame: str
    attributes: dict
    configuration: dict
    phase: np.ndarray
    plate_z: np.ndarray
    per_phase: dict
    per_run: dict
    crossings: dict


def read_analysis_json(source, frame="lab"):
    """Read `shaker analyze --json` output from a path or from the JSON text itself."""
    check_frame(frame)
    text = str(source)
    if not text.lstrip().startswith("{"):
        with open(os.fspath(source)) as f:
            text = f.read()
    document = json.loads(text)
    if document.get("schema") != SCHEMA:
        raise SchemaError(f"schema {document.get('schema')!r}: not '{SCHEMA}' output of "
                          "shaker analyze --json")
    if document.get("schema_version") not in KNOWN_VERSIONS:
        raise SchemaError(f"shaker-analysis schema_version {document.get('schema_version')!r} "
                          f"is not one this reader knows ({', '.join(map(str, KNOWN_VERSIONS))})")
    configuration = tomllib.loads(document["configuration"])
    per_phase = {name: _quantity(q) for name, q in document["per_phase"].items()}
    per_run = {name: _quantity(q) for name, q in document["per_run"].items()}
    phase, plate_z = per_phase["phase"].value, per_phase["plate_z"].value
    if frame == "plate":
        for name in LAB_FRAME_HEIGHTS:
            if name in per_phase:
                q = per_phase[name]
                q.value = q.value - plate_z
                q.replicates = q.replicates - plate_z if q.replicates.size else q.replicates
    attributes = {k: v for k, v in document.items()
                  if k not in ("configuration", "per_phase", "per_run", "crossings")}
    return Analysis(frame, attributes, configuration, phase, plate_z, per_phase, per_run,
                    document.get("crossings", {}))


def _numbers(x):
    if x is None:
        return math.nan
    if isinstance(x, list):
        return np.array([_numbers(v) for v in x], dtype=float)
    return float(x)


def _quantity(q):
    resolution = q.get("resolution")
    return Quantity(_numbers(q["value"]), _numbers(q["error"]), q["unit"],
                    None if resolution is None else _numbers(resolution),
                    np.asarray(_numbers(q.get("replicates", [])), dtype=float))
