"""Small files of the layouts granular_shaker reads, written with h5py and numpy from known
numbers (explicit seeds), so the tests can compare what the readers return with the truth."""
import json
import math

import h5py
import numpy as np

PHASES, BINS, SAMPLES, BIN_HEIGHT, WIDTH = 4, 6, 2, 1.0, 5.0
AMPLITUDE, FREQUENCY = 3.0 / (2 * math.pi * 0.095) ** 2, 0.095
CONFIGURATION = f"""[shaker]
gamma = 3.0
frequency = {FREQUENCY}
[layer]
particles = 40
[run]
phases_per_cycle = {PHASES}
sampled_cycles = {SAMPLES}
[md]
box_width = {WIDTH}
"""
PROFILE_UNITS = {"time": "sqrt(sigma/g)", "phase": "1", "plate_z": "sigma",
                 "plate_v": "sqrt(g sigma)", "bin_height": "sigma", "z": "sigma",
                 "n": "1/sigma^3", "nu": "1", "uz": "sqrt(g sigma)", "T": "g sigma",
                 "samples": "1", "n_se": "1/sigma^3", "uz_se": "sqrt(g sigma)", "T_se": "g sigma"}
SERIES_UNITS = {"t": "sqrt(sigma/g)", "phase": "1", "plate_z": "sigma", "com_z": "sigma",
                "total_mass": "m / sigma^2"}
# The MD bin no particle reaches, in every phase.
EMPTY_BIN = BINS - 1


def plate(phase):
    """Plate position and velocity at f t = phase (docs/units.md; g = 1)."""
    omega = 2 * math.pi * FREQUENCY
    return AMPLITUDE * (1 - np.cos(2 * math.pi * phase)), AMPLITUDE * omega * np.sin(
        2 * math.pi * phase)


def write_attributes(f, solver="md", schema_version=1):
    f.attrs["schema_version"] = np.int64(schema_version)
    f.attrs["program_version"] = "0.1.0"
    f.attrs["git_commit"] = "synthetic"
    f.attrs["created"] = "2026-01-01T00:00:00Z"
    f.attrs["solver"] = solver
    f.attrs["model_variant"] = "synthetic"
    f.attrs["configuration"] = CONFIGURATION
    f.attrs["restitution_for_analysis"] = 0.9


def _dataset(group, name, data, units):
    group.create_dataset(name, data=data).attrs["units"] = units


def md_samples(seed=1):
    """Particle velocities per (phase, sample, bin), and the sums of /cycle_samples."""
    rng = np.random.default_rng(seed)
    count = rng.integers(1, 5, size=(PHASES * SAMPLES, BINS)).astype(float)
    count[:, EMPTY_BIN] = 0
    sums = {name: np.zeros_like(count) for name in ("vx", "vy", "vz", "v2")}
    for row in range(PHASES * SAMPLES):
        for b in range(BINS):
            v = rng.normal([0.1, -0.2, 0.5], 1.0, size=(int(count[row, b]), 3))
            sums["vx"][row, b], sums["vy"][row, b], sums["vz"][row, b] = v.sum(axis=0)
            sums["v2"][row, b] = (v * v).sum()
    return count, sums


def write_md_run(path, empty_value=np.nan, schema_version=1, units=True):
    """An MD run file whose profiles are the pooled /cycle_samples; the empty bin stores
    `empty_value` as its u_z, T and standard errors (0 in older files, NaN in newer)."""
    count, sums = md_samples()
    phase = np.arange(PHASES) / PHASES
    plate_z, plate_v = plate(phase)
    bin_volume = WIDTH * WIDTH * BIN_HEIGHT
    pooled = {name: x.reshape(PHASES, SAMPLES, BINS).sum(axis=1)
              for name, x in {"count": count, **sums}.items()}
    with np.errstate(invalid="ignore", divide="ignore"):
        n = pooled["count"] / (SAMPLES * bin_volume)
        mean = [pooled[c] / pooled["count"] for c in ("vx", "vy", "vz")]
        T = (pooled["v2"] / pooled["count"] - sum(m * m for m in mean)) / 3
    empty = pooled["count"] == 0
    profiles = {
        "time": (10 + phase) / FREQUENCY, "phase": phase, "plate_z": plate_z, "plate_v": plate_v,
        "bin_height": np.full(PHASES, BIN_HEIGHT),
        "z": np.tile((np.arange(BINS) + 0.5) * BIN_HEIGHT, (PHASES, 1)),
        "n": n, "nu": math.pi / 6 * n, "uz": np.where(empty, empty_value, mean[2]),
        "T": np.where(empty, empty_value, T), "samples": pooled["count"],
        "n_se": np.where(empty, empty_value, 0.1 * n + 0.01),
        "uz_se": np.where(empty, empty_value, 0.2), "T_se": np.where(empty, empty_value, 0.3)}
    rows = 2 * PHASES + 1
    t = np.arange(rows) / (PHASES * FREQUENCY)
    series_plate = plate(t * FREQUENCY % 1.0)[0]
    series = {"t": t, "phase": t * FREQUENCY % 1.0, "plate_z": series_plate,
              "com_z": series_plate + 2.0 + 0.1 * np.arange(rows)}
    with h5py.File(path, "w") as f:
        write_attributes(f, "md", schema_version)
        g = f.create_group("profiles")
        for name, data in profiles.items():
            g.create_dataset(name, data=data)
            if units:
                g[name].attrs["units"] = PROFILE_UNITS[name]
        _write_series(f.create_group("timeseries"), series)
        c = f.create_group("cycle_samples")
        c.attrs["bin_volume"] = bin_volume
        _dataset(c, "cycles", np.ones((PHASES, SAMPLES)), "1")
        _dataset(c, "count", count, "1")
        for name in ("vx", "vy", "vz"):
            _dataset(c, name, sums[name], "sqrt(g sigma)")
        _dataset(c, "v2", sums["v2"], "g sigma")
        replicas = f.create_group("replica_timeseries")
        replicas.attrs["replicas"] = np.int64(2)
        _write_series(replicas.create_group("replica_00001"),
                      {**series, "com_z": series["com_z"] + 0.5})
    return profiles, series


def _write_series(group, series):
    group.attrs["columns"] = ",".join(series)
    for name, data in series.items():
        _dataset(group, name, data, SERIES_UNITS[name])


def write_continuum_run(path):
    """A continuum run file: cells that move with the plate, so each row of z is shifted by
    that phase's plate_z."""
    phase = np.arange(PHASES) / PHASES
    plate_z, plate_v = plate(phase)
    cells = (np.arange(BINS) + 0.5) * BIN_HEIGHT
    n = np.exp(-cells / 2)[None, :] * (1 + 0.1 * phase[:, None])
    profiles = {"time": (10 + phase) / FREQUENCY, "phase": phase, "plate_z": plate_z,
                "plate_v": plate_v, "bin_height": np.full(PHASES, BIN_HEIGHT),
                "z": cells[None, :] + plate_z[:, None], "n": n, "nu": math.pi / 6 * n,
                "uz": plate_v[:, None] + 0.3 * cells[None, :],
                "T": 1 + 0.5 * cells[None, :] + phase[:, None]}
    t = np.arange(2 * PHASES) / (PHASES * FREQUENCY)
    series_plate = plate(t * FREQUENCY % 1.0)[0]
    series = {"t": t, "phase": t * FREQUENCY % 1.0, "plate_z": series_plate,
              "com_z": series_plate + 3.0, "total_mass": np.full(len(t), 1.6)}
    with h5py.File(path, "w") as f:
        write_attributes(f, "continuum")
        g = f.create_group("profiles")
        for name, data in profiles.items():
            _dataset(g, name, data, PROFILE_UNITS[name])
        _write_series(f.create_group("timeseries"), series)
    return profiles, series


FIELD_UNITS = {"n": "1/sigma^3", "ux": "sqrt(g sigma)", "uy": "sqrt(g sigma)",
               "uz": "sqrt(g sigma)", "T": "g sigma"}
NX, NY, NZ, CELL = 2, 3, 4, 0.5


def write_fields(path, seed=2):
    """A fields file of two snapshots with random fields; returns them as written."""
    rng = np.random.default_rng(seed)
    phases = np.array([0.25, 0.5])
    snapshots = []
    k, j, i = np.meshgrid(np.arange(NZ + 1), np.arange(NY + 1), np.arange(NX + 1), indexing="ij")
    with h5py.File(path, "w") as f:
        write_attributes(f, "continuum")
        f.attrs["kind"] = "shaker continuum fields"
        f.attrs["cell_size"] = CELL
        for key, value in (("nx", NX), ("ny", NY), ("nz", NZ)):
            f.attrs[key] = np.int64(value)
        _dataset(f, "hexahedra", np.zeros((NX * NY * NZ, 8), dtype=np.int64), "1")
        for s, phase in enumerate(phases):
            plate_z, plate_v = plate(phase)
            g = f.create_group(f"snapshot_{s:03d}")
            g.attrs.update({"time": (10 + phase) / FREQUENCY, "phase": phase,
                            "plate_z": plate_z, "plate_v": plate_v})
            points = np.stack([i.ravel() * CELL, j.ravel() * CELL,
                               k.ravel() * CELL + plate_z], axis=1)
            _dataset(g, "points", points, "sigma")
            fields = {name: rng.uniform(0.1, 1.0, size=(NZ, NY, NX)) for name in FIELD_UNITS}
            for name, data in fields.items():
                _dataset(g, name, data, FIELD_UNITS[name])
            fields["velocity"] = np.stack([fields["ux"], fields["uy"], fields["uz"]], axis=-1)
            _dataset(g, "velocity", fields["velocity"], "sqrt(g sigma)")
            g.attrs["cycle"] = np.int64(10)
            snapshots.append({"plate_z": plate_z, "plate_v": plate_v, "points": points,
                              **fields})
    return snapshots


PARTICLE_STEPS = np.array([0, 20, 30], dtype=np.int64)
OBSERVABLE_STEPS = np.array([0, 10, 20, 30], dtype=np.int64)
PARTICLES, CEILING = 5, 40.0


def write_h5md(path, seed=3, schema_version=1, observable_steps=OBSERVABLE_STEPS):
    """An H5MD 1.1 snapshot file of the layout `shaker md` writes: particles at
    PARTICLE_STEPS, observables at `observable_steps`."""
    rng = np.random.default_rng(seed)
    frames = len(PARTICLE_STEPS)
    time = PARTICLE_STEPS * 0.1
    observable_time = observable_steps * 0.1
    plate_z, plate_v = plate(observable_time * FREQUENCY % 1.0)
    particle_plate_z, particle_plate_v = plate(time * FREQUENCY % 1.0)
    position = rng.uniform([0, 0, 0.5], [WIDTH, WIDTH, 20], size=(frames, PARTICLES, 3))
    position[:, :, 2] += particle_plate_z[:, None]
    velocity = rng.normal(0, 1, size=(frames, PARTICLES, 3))
    observables = {"plate_position": (plate_z, "sigma"),
                   "plate_velocity": (plate_v, "sqrt(g sigma)"),
                   "phase": (observable_time * FREQUENCY % 1.0, "1"),
                   "cycle": (np.floor(observable_time * FREQUENCY), "1")}
    write_particle_file(path, PARTICLE_STEPS, time, position, velocity, [WIDTH, WIDTH, CEILING],
                        observable_steps, observable_time, observables, schema_version)
    return {"position": position, "velocity": velocity, "plate_position": particle_plate_z,
            "plate_velocity": particle_plate_v, "time": time}


def write_particle_file(path, steps, time, position, velocity, edges, observable_steps,
                        observable_time, observables, schema_version=1):
    """The H5MD layout of `shaker md`'s particle file from given frames; `observables` maps
    plate_position, plate_velocity, phase and cycle to (values, units) at observable_steps."""
    with h5py.File(path, "w") as f:
        write_attributes(f, "md", schema_version)
        f.attrs["kind"] = "shaker md particles"
        h5md = f.create_group("h5md")
        h5md.attrs["version"] = np.array([1, 1], dtype=np.int32)
        h5md.create_group("author").attrs["name"] = "granular-shaker"
        particles = f.create_group("particles/all")
        box = particles.create_group("box")
        box.attrs["dimension"] = np.int32(3)
        box.attrs["boundary"] = np.array([b"periodic", b"periodic", b"none"])
        _dataset(box, "edges", np.asarray(edges, float), "sigma")
        for name, value, units in (("position", position, "sigma"),
                                   ("velocity", velocity, "sqrt(g sigma)")):
            _time_element(particles.create_group(name), steps, time, value, units)
        for name, (value, units) in observables.items():
            _time_element(f.create_group(f"observables/{name}"), observable_steps,
                          observable_time, value, units)


def write_pattern_fields(path, frames, nx=64, cell=2.0, ny=4, nz=10):
    """A continuum fields file of the schema (docs/output-schema.md; its density only) whose
    column mass carries mode 6 growing by e^0.1 and mode 3 decaying by e^-0.3 per cycle;
    `frames` are (cycle, phase) pairs."""
    x = np.arange(nx)
    with h5py.File(path, "w") as f:
        write_attributes(f, "continuum")
        f.attrs["kind"], f.attrs["cell_size"] = "shaker continuum fields", cell
        for key, value in (("nx", nx), ("ny", ny), ("nz", nz)):
            f.attrs[key] = np.int64(value)
        _dataset(f, "hexahedra", np.zeros((nx * ny * nz, 8), dtype=np.int64), "1")
        for index, (cycle, phase) in enumerate(frames):
            column = 1.0 + 1e-4 * np.exp(0.1 * cycle) * np.cos(2 * np.pi * 6 * x / nx) \
                + 1e-3 * np.exp(-0.3 * cycle) * np.sin(2 * np.pi * 3 * x / nx)
            group = f.create_group(f"snapshot_{index:03d}")
            _dataset(group, "n", np.broadcast_to(column / nz, (nz, ny, nx)), "1/sigma^3")
            group.attrs.update({"time": cycle + phase, "phase": phase, "plate_z": 0.0,
                                "plate_v": 0.0, "cycle": np.int64(cycle)})


def _time_element(group, step, time, value, units):
    group.create_dataset("step", data=step)
    t = group.create_dataset("time", data=time)
    t.attrs["units"] = "sqrt(sigma/g)"
    _dataset(group, "value", value, units)


def analysis_json(schema="shaker-analysis", schema_version=1):
    """`shaker analyze --json` text of an MD run of PHASES phases and 3 samples."""
    phase = np.arange(PHASES) / PHASES
    plate_z = plate(phase)[0]

    def per_phase(values, unit, error=0.1):
        values = [None if v is None else float(v) for v in values]
        return {"unit": unit, "value": values,
                "error": [None if v is None else error for v in values], "resolution": None,
                "replicates": [[None if v is None else v + d for v in values]
                               for d in (-0.1, 0.0, 0.1)]}

    document = {
        "schema": schema, "schema_version": schema_version, "program_version": "0.1.0",
        "git_commit": "synthetic", "inputs": ["run.h5"], "solver": "md",
        "model_variant": "synthetic", "restitution_for_analysis": 0.9, "samples": 3,
        "error_method": "jackknife over 3 samples", "configuration": CONFIGURATION,
        "per_phase": {
            "phase": per_phase(phase, "1", 0), "plate_z": per_phase(plate_z, "sigma", 0),
            "center_of_mass": per_phase(plate_z + 5, "sigma"),
            "shock_location": per_phase([None, plate_z[1] + 2, plate_z[2] + 4, None], "sigma"),
            "layer_gap": per_phase([1, 2, 3, 4], "sigma")},
        "per_run": {"lifetime": {"unit": "1/f", "value": 0.2, "error": 0.05,
                                 "resolution": 0.05, "replicates": [0.15, 0.2, None]}},
        "crossings": {"crossings_z80": {"unit": "particles per cycle", "value": 1.5,
                                        "error": 0.5, "per_cycle": [1, 2, 1.5],
                                        "replicates": [1.75, 1.25, 1.5]}}}
    return json.dumps(document, indent=2)
