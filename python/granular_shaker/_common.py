"""What the readers share: the schema check, the frame argument, named arrays with units."""
import tomllib

import h5py
import numpy as np

# Schema versions of the HDF5 files (docs/output-schema.md) this package reads.
KNOWN_SCHEMA_VERSIONS = (1, 2)
FRAMES = ("lab", "plate")


class SchemaError(ValueError):
    """A file this package cannot read: unknown schema version, wrong kind, missing data."""


class Table(dict):
    """Named numpy arrays, with the units of each in `units[name]`."""

    def __init__(self, arrays=(), units=()):
        super().__init__(arrays)
        self.units = dict(units)

    def label(self, name, description=None):
        """An axis label for `name`: "description [units]"."""
        return f"{description or name} [{self.units[name]}]"


def text(value):
    """An HDF5 string attribute as str (h5py gives str or bytes, by how it was written)."""
    return value.decode() if isinstance(value, bytes) else str(value)


def check_frame(frame):
    if frame not in FRAMES:
        raise ValueError(f"frame = {frame!r}: allowed values are {', '.join(map(repr, FRAMES))}")


def check_schema_version(attrs, path):
    """The file's schema version; refuses a file without one this package knows."""
    if "schema_version" not in attrs:
        raise SchemaError(f"{path}: no root attribute 'schema_version'; not a granular-shaker "
                          "output file")
    version = int(np.asarray(attrs["schema_version"]).item())
    if version not in KNOWN_SCHEMA_VERSIONS:
        known = ", ".join(map(str, KNOWN_SCHEMA_VERSIONS))
        raise SchemaError(f"{path}: schema_version {version} is not one this reader knows "
                          f"({known}); update granular_shaker to the version of the shaker "
                          "program that wrote the file")
    return version


def provenance(attrs):
    """Root attributes as Python values, and the configuration parsed (TOML)."""
    attributes = {key: _attribute_value(value) for key, value in attrs.items()}
    configuration = tomllib.loads(attributes.get("configuration", ""))
    return attributes, configuration


def _attribute_value(value):
    if isinstance(value, (str, bytes)):
        return text(value)
    array = np.asarray(value)
    if array.dtype.kind in "OSU":
        return [text(v) for v in array.ravel()]
    return array.item() if array.ndim == 0 else array


def units_of(dataset, path):
    """The dataset's `units` attribute; every dataset of the files carries one."""
    if "units" not in dataset.attrs:
        raise SchemaError(f"{path}: dataset {dataset.name} has no 'units' attribute")
    return text(dataset.attrs["units"])


def read_group(group, path, names=None):
    """The datasets of `group` (all, or those of `names`) as a Table."""
    names = [n for n in group if isinstance(group[n], h5py.Dataset)] if names is None else names
    return Table({n: group[n][()] for n in names}, {n: units_of(group[n], path) for n in names})
