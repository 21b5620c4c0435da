#!/usr/bin/python3
"""The 3D fields file as a visualisation tool reads it (docs/output-schema.md, "3D continuum
fields"): a small 3D run of `shaker continuum` (a 2 x 2 x 10 box at cell 0.5, two cycles,
the fields at all four stored phases of both, continuum.field_cycles), then its XDMF sidecar
read by an XDMF reader and every field of every snapshot compared with the HDF5 file read by
h5py, value for value.

    check_fields_xdmf.py --shaker SHAKER --reader meshio      (ctest default set)
    pvbatch check_fields_xdmf.py --shaker SHAKER --reader paraview      (nightly)

meshio: meshio.xdmf.TimeSeriesReader, pointed at each snapshot's grid in turn for its corners
(it reads one mesh per series otherwise). paraview: each of ParaView's three XDMF readers
(XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT) through paraview.simple, the data fetched with
servermanager.Fetch; no rendering, so no display is needed (pvbatch, pvpython or a python3
that imports paraview.simple).

Besides the readers' values: the file's root attributes are the run file's, every dataset has
its units, the frame is the lab frame (corners at k h + plate_z with plate_z = A (1 - cos 2 pi
f t) from the configuration; the horizontal means of n, n uz and n T are the run file's
profiles at the snapshot's phase, one sampled cycle), and `shaker analyze` refuses the fields
file as what it is. The run's directory is removed when every check passes.
"""
import argparse
import math
import os
import subprocess
import sys
import tomllib

import h5py
import keep_on_failure
import numpy as np

FIELDS = ("n", "nu", "ux", "uy", "uz", "T", "velocity")
UNITS = {"n": "1/sigma^3", "nu": "1", "ux": "sqrt(g sigma)", "uy": "sqrt(g sigma)",
         "uz": "sqrt(g sigma)", "T": "g sigma", "velocity": "sqrt(g sigma)", "points": "sigma",
         "hexahedra": "1"}
PHASES = 4
CYCLES = 2  # a transient cycle and the sampled one, both written (a movie of the run)
# The phases listed out of order: the snapshots come in time order, each once.
CASE = f"""[continuum]
dimension = 3
cell_size = 0.5
box_width = 2.0
ceiling = 10.0
field_phases = [0.75, 0.0, 0.5, 0.25]
field_cycles = [1, 0]
[layer]
particles = 1000
[run]
transient_cycles = 1
sampled_cycles = 1
phases_per_cycle = {PHASES}
"""
problems = []


def expect(condition, message):
    if not condition:
        problems.append(message)
        print("PROBLEM: " + message)


def without_launcher(**extra):
    """This process's environment less an MPI launcher's variables, and `extra`. pvbatch starts
    MPI as a singleton, which sets PMIX_RANK and OMPI_* for its children; `shaker` would read
    them as an mpirun launch (common/ranks.cpp) and join pvbatch's MPI job rather than run alone
    as under python3."""
    launcher = ("OMPI_", "PMIX_", "PMI_")
    return {**{k: v for k, v in os.environ.items() if not k.startswith(launcher)}, **extra}


def h5_snapshots(path):
    """Every snapshot as h5py reads it: attributes, corners, fields (flattened, cell order)."""
    with h5py.File(path, "r") as f:
        names = sorted(k for k in f if k.startswith("snapshot_"))
        hexahedra = f["hexahedra"][()]
        snapshots = []
        for name in names:
            g = f[name]
            s = {key: float(g.attrs[key])
                 for key in ("time", "phase", "plate_z", "plate_v", "cycle")}
            s["name"] = name
            s["points"] = g["points"][()]
            for field in FIELDS:
                s[field] = g[field][()].ravel()
            snapshots.append(s)
        return hexahedra, snapshots


def check_file(fields_path, run_path, shaker):
    """The HDF5 file on its own: metadata, units, layout, lab frame."""
    with h5py.File(fields_path, "r") as f, h5py.File(run_path, "r") as run:
        for name in ("schema_version", "program_version", "git_commit", "solver", "model_variant",
                     "configuration", "restitution_for_analysis"):
            expect(name in f.attrs and f.attrs[name] == run.attrs[name],
                   f"root attribute {name} is the run file's: {f.attrs.get(name)!r}")
        expect(f.attrs.get("created", "") != "", "root attribute created")
        expect(f.attrs.get("kind") == "shaker continuum fields", f"kind {f.attrs.get('kind')!r}")
        datasets = []
        f.visititems(lambda name, obj: datasets.append((name, obj))
                     if isinstance(obj, h5py.Dataset) else None)
        expect(len(datasets) == 1 + CYCLES * PHASES * (1 + len(FIELDS)),
               f"{len(datasets)} datasets")
        for name, data in datasets:
            expect(data.attrs.get("units") == UNITS[name.split("/")[-1]],
                   f"{name} units {data.attrs.get('units')!r}")
        nx, ny, nz = (int(f.attrs[k]) for k in ("nx", "ny", "nz"))
        h = float(f.attrs["cell_size"])
        expect((nx, ny, nz, h) == (4, 4, 20, 0.5), f"grid {nx} x {ny} x {nz} at {h}")
        configuration = tomllib.loads(f.attrs["configuration"])
        gamma, frequency = configuration["shaker"]["gamma"], configuration["shaker"]["frequency"]
        amplitude = gamma / (2 * math.pi * frequency) ** 2  # Gamma g / omega^2, g = 1
        profiles = run["profiles"]
        hexahedra, snapshots = h5_snapshots(fields_path)
        # f t at the snapshot's time: the stored phase k / K to round-off.
        expect(np.allclose([s["phase"] for s in snapshots],
                           np.tile(np.arange(PHASES) / PHASES, CYCLES), rtol=0, atol=1e-12),
               f"phases in time order, each once a cycle: {[s['phase'] for s in snapshots]}")
        expect([s["cycle"] for s in snapshots] == [c for c in range(CYCLES) for _ in range(PHASES)],
               f"cycles {[s['cycle'] for s in snapshots]}")
        expect(all(a["time"] < b["time"] for a, b in zip(snapshots, snapshots[1:])),
               "snapshots in time order")
        # The corners of cell 0 and of the last cell, independently of the writer's loops.
        expect(list(hexahedra[0]) == [0, 1, 6, 5, 25, 26, 31, 30], f"cell 0: {hexahedra[0]}")
        last = (19 * 5 + 3) * 5 + 3  # corner (3, 3, 19)
        expect(hexahedra[-1][0] == last and hexahedra.shape == (nx * ny * nz, 8),
               f"last cell {hexahedra[-1]}, shape {hexahedra.shape}")
        k, j, i = np.meshgrid(np.arange(nz + 1), np.arange(ny + 1), np.arange(nx + 1),
                              indexing="ij")
        for s in snapshots:
            # nu and the velocity vector are n and (ux, uy, uz) as other readers want them.
            expect(np.array_equal(s["nu"], math.pi / 6 * s["n"]), f"{s['name']}: nu = pi/6 n")
            expect(np.array_equal(s["velocity"].reshape(-1, 3),
                                  np.stack([s["ux"], s["uy"], s["uz"]], axis=1)),
                   f"{s['name']}: velocity = (ux, uy, uz)")
            t = s["time"]
            plate_z = amplitude * (1 - math.cos(2 * math.pi * frequency * t))
            expect(abs(s["plate_z"] - plate_z) <= 1e-12 * amplitude,
                   f"{s['name']}: plate_z {s['plate_z']} against A (1 - cos 2 pi f t) = {plate_z}")
            expected = np.stack([i.ravel() * h, j.ravel() * h, k.ravel() * h + s["plate_z"]],
                                axis=1)
            expect(np.array_equal(s["points"], expected), f"{s['name']}: lab-frame corners")
            if s["cycle"] != CYCLES - 1:
                continue  # the profiles are of the sampled cycle
            row = profiles["phase"][()].tolist().index(s["phase"])
            expect(profiles["time"][row] == t and profiles["plate_v"][row] == s["plate_v"],
                   f"{s['name']}: the time and plate velocity of profile row {row}")
            n = s["n"].reshape(nz, ny * nx)
            mean_n = n.mean(axis=1)
            centres = (np.arange(nz) + 0.5) * h + s["plate_z"]
            for label, mine, theirs in (
                    ("z", centres, profiles["z"][row]), ("n", mean_n, profiles["n"][row]),
                    ("uz", (n * s["uz"].reshape(nz, -1)).mean(axis=1) / mean_n,
                     profiles["uz"][row]),
                    ("T", (n * s["T"].reshape(nz, -1)).mean(axis=1) / mean_n, profiles["T"][row])):
                # Relative to the profile's largest value (at t = 0 the layer is at rest: uz = 0).
                error = np.max(np.abs(mine - theirs))
                expect(error <= 1e-12 * np.max(np.abs(theirs)),
                       f"{s['name']}: horizontal mean of {label} against the run file's "
                       f"profile at phase {s['phase']}: differs by {error:.2e}")
        for field in FIELDS:  # so that the readers' values are compared on something
            expect(np.ptp(np.concatenate([s[field] for s in snapshots])) > 0,
                   f"{field} is the same in every cell of every snapshot")
    result = subprocess.run([shaker, "analyze", fields_path], capture_output=True, text=True,
                            env=without_launcher())
    expect(result.returncode == 2 and "'shaker continuum fields' file" in result.stderr,
           f"shaker analyze on the fields file: exit {result.returncode}, {result.stderr.strip()}")
    return hexahedra, snapshots


def compare(reader, times, hexahedra, snapshots, cells, points_of, fields_of):
    """One reader's view against h5py's: times, cells, corners, every field at every time."""
    expect(list(times) == [s["time"] for s in snapshots],
           f"{reader}: times {list(times)} against {[s['time'] for s in snapshots]}")
    expect(np.array_equal(np.asarray(cells).reshape(-1, 8), hexahedra), f"{reader}: hexahedra")
    for step, s in enumerate(snapshots[:len(times)]):
        before = len(problems)
        expect(np.array_equal(points_of(step), s["points"]), f"{reader}: corners of {s['name']}")
        values = fields_of(step)
        for field in FIELDS:
            got = values.get(field)
            expect(got is not None and np.array_equal(np.asarray(got).ravel(), s[field]),
                   f"{reader}: {field} of {s['name']} (t = {s['time']})")
        if len(problems) == before:
            print(f"{reader}: t = {s['time']!r}: corners and {', '.join(FIELDS)} equal")


def read_meshio(xdmf, hexahedra, snapshots):
    import meshio
    with meshio.xdmf.TimeSeriesReader(xdmf) as r:
        _, blocks = r.read_points_cells()
        expect(len(blocks) == 1 and blocks[0].type == "hexahedron", f"meshio cells {blocks}")
        times, corners, fields = [], [], []
        for step in range(r.num_steps):
            t, _, cell_data = r.read_data(step)
            times.append(t)
            fields.append({name: blocks_[0] for name, blocks_ in cell_data.items()})
            r.mesh_grid = r.collection[step]
            corners.append(r.read_points_cells()[0])
    compare("meshio", times, hexahedra, snapshots, blocks[0].data,
            lambda step: corners[step], lambda step: fields[step])


def read_paraview(xdmf, hexahedra, snapshots):
    try:
        from paraview import servermanager, simple
        from vtkmodules.util.numpy_support import vtk_to_numpy
    except ImportError as error:
        print(f"PROBLEM: ParaView's Python modules are missing ({error}): install the Debian "
              "packages paraview and python3-paraview (ci/install-deps.sh --nightly)")
        return False
    for name, make in (("XDMFReader", lambda: simple.XDMFReader(FileNames=[xdmf])),
                       ("Xdmf3ReaderS", lambda: simple.Xdmf3ReaderS(FileName=[xdmf])),
                       ("Xdmf3ReaderT", lambda: simple.Xdmf3ReaderT(FileName=[xdmf]))):
        reader = make()
        times = list(reader.TimestepValues)
        cells, corners, fields = None, [], []
        for t in times:
            reader.UpdatePipeline(t)
            grid = servermanager.Fetch(reader)
            if not grid.IsA("vtkUnstructuredGrid"):
                expect(False, f"ParaView {name}: t = {t}: {grid.GetClassName()}")
                break
            # Copies taken now: a fetched grid's arrays may be the reader's, reused at the next
            # time.
            types = vtk_to_numpy(grid.GetCellTypesArray())
            expect(np.all(types == 12),  # hexahedra
                   f"ParaView {name}: cell types {set(types.tolist())}")
            if cells is None:
                cells = np.array(vtk_to_numpy(grid.GetCells().GetConnectivityArray()))
            corners.append(np.array(vtk_to_numpy(grid.GetPoints().GetData())))
            data = grid.GetCellData()
            fields.append({f: np.array(vtk_to_numpy(data.GetArray(f))) for f in FIELDS
                           if data.HasArray(f)})
        simple.Delete(reader)
        if len(corners) != len(times) or not times:
            expect(False, f"ParaView {name}: read {len(corners)} of {len(times)} time steps")
            continue
        compare(f"ParaView {name}", times, hexahedra, snapshots, cells,
                lambda step: corners[step], lambda step: fields[step])
    return True


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--shaker", required=True)
    parser.add_argument("--reader", choices=("meshio", "paraview"), required=True)
    args = parser.parse_args()
    work = keep_on_failure.work_folder(f"shaker-continuum-fields-xdmf-{args.reader}-")
    run_path = os.path.join(work, "box.h5")
    with open(os.path.join(work, "box.toml"), "w") as f:
        f.write(CASE)
    command = [os.path.abspath(args.shaker), "continuum", os.path.join(work, "box.toml"), "--quiet",
               "--set", f"run.output={run_path}"]
    result = subprocess.run(command, capture_output=True, text=True,
                            env=without_launcher(OMP_NUM_THREADS="1"))
    if result.returncode != 0:
        print(f"PROBLEM: {' '.join(command)} exited {result.returncode}:\n"
              f"{result.stdout}{result.stderr}")
        return 1
    fields_path = os.path.join(work, "box.fields.h5")
    hexahedra, snapshots = check_file(fields_path, run_path, args.shaker)
    # An absolute path: ParaView's Xdmf3 readers mislocate the HDF5 file of a bare file name.
    xdmf = os.path.join(work, "box.fields.xdmf")
    if args.reader == "meshio":
        read_meshio(xdmf, hexahedra, snapshots)
    elif not read_paraview(xdmf, hexahedra, snapshots):
        return 1
    return keep_on_failure.finish(
        work, problems,
        f"every field of {len(snapshots)} snapshots read through {args.reader} equals h5py's")


if __name__ == "__main__":
    sys.exit(main())
