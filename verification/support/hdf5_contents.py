"""Every dataset and attribute of an HDF5 file as arrays keyed by path, for the check scripts
that compare files written by different runs (ranks, launchers, restarts) value by value.

ctest puts this folder on PYTHONPATH for every script test (cmake/ShakerTests.cmake)."""
import h5py
import numpy as np


def contents(path, ignored_attributes=(), groups=None):
    """Datasets by path, attributes as PATH@NAME (root attributes as @NAME), leaving out the
    attributes named in `ignored_attributes`; `groups` limits it to the datasets and
    attributes under those top-level groups (and leaves out the root's)."""
    found = {}
    with h5py.File(path, "r") as f:
        def visit(name, item):
            if groups and name.split("/")[0] not in groups:
                return
            if isinstance(item, h5py.Dataset):
                found[name] = np.asarray(item[()])
            for key, value in item.attrs.items():
                if key not in ignored_attributes:
                    found[f"{name}@{key}"] = np.asarray(value)
        f.visititems(visit)
        if not groups:
            for key, value in f.attrs.items():
                if key not in ignored_attributes:
                    found[f"@{key}"] = np.asarray(value)
    return found
