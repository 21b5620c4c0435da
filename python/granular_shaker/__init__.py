"""Read the outputs of granular-shaker (`shaker md`, `shaker continuum`, `shaker analyze`)
into numpy arrays with their units, and plot them (granular_shaker.plotting).

    import granular_shaker as gs
    run = gs.read_run("run.h5", frame="plate")
    run.profiles["n"], run.profiles.units["n"]   # K x B number density, "1/sigma^3"

The file layouts are those of docs/output-schema.md and docs/analysis.md in the repository.
The project's own harness lives in the subpackages granular_shaker.validation (the validation
study against the paper) and granular_shaker.reports (the report generators), which importing
this package does not load; their commands are shaker-validation, shaker-sensitivity and
shaker-*-report.
"""
from ._common import KNOWN_SCHEMA_VERSIONS, SchemaError, Table
from .analysis import Analysis, Quantity, read_analysis_json
from .fields import Fields, read_fields
from .runs import Run, read_run
from .snapshots import Snapshots, read_snapshots, to_gsd

__version__ = "0.1.0"
__all__ = ["KNOWN_SCHEMA_VERSIONS", "SchemaError", "Table", "Analysis", "Quantity",
           "read_analysis_json", "Fields", "read_fields", "Run", "read_run", "Snapshots",
           "read_snapshots", "to_gsd"]
