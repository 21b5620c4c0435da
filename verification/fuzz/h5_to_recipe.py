#!/usr/bin/python3
"""Writes the recipe (hdf5_recipe.hpp) of an HDF5 file: the seed of a fuzz target from a real
checkpoint or run file.

    h5_to_recipe.py FILE.h5 RECIPE

Attributes and datasets of float, integer and string type, up to rank 3, in the order h5py
lists them (root attributes first, then each object followed by its attributes).
"""
import struct
import sys

import h5py
import numpy as np


def record(name, value):
    """Bytes of one record, or None for a value the recipe cannot hold."""
    array = np.asarray(value)
    if array.dtype.kind in "SUO":
        kind = 2
    elif array.dtype.kind == "f":
        kind = 0
    elif array.dtype.kind in "iub":
        kind = 1
    else:
        return None
    encoded_name = name.encode()
    if len(encoded_name) > 255 or array.ndim > 3 or any(d > 0xFFFF for d in array.shape):
        return None
    out = bytearray([len(encoded_name)]) + encoded_name + bytes([kind, array.ndim])
    for d in array.shape:
        out += struct.pack("<H", d)
    for x in array.reshape(-1):
        if kind == 2:
            text = x if isinstance(x, bytes) else str(x).encode()
            out += struct.pack("<H", len(text)) + text
        elif kind == 0:
            out += struct.pack("<d", float(x))
        else:
            out += struct.pack("<q", int(x))
    return bytes(out)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    records = []
    with h5py.File(sys.argv[1], "r") as f:
        def attributes(path, obj):
            for key, value in obj.attrs.items():
                records.append(record(f"{path}@{key}", value))

        attributes("", f)

        def visit(path, obj):
            if isinstance(obj, h5py.Dataset):
                records.append(record(path, obj[()]))
            attributes(path, obj)

        f.visititems(visit)
    skipped = sum(r is None for r in records)
    if skipped:
        sys.exit(f"h5_to_recipe.py: {skipped} objects of {sys.argv[1]} cannot be written as a "
                 "recipe")
    with open(sys.argv[2], "wb") as out:
        out.write(b"".join(records))


if __name__ == "__main__":
    main()
