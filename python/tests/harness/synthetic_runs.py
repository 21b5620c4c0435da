"""Writes synthetic run files (docs/output-schema.md, solver attribute "synthetic") for the
runs that the validation study (granular_shaker.validation) plans, under the names it reuses,
so that the whole validation pipeline (shaker analyze, shaker compare, pooling, claims, report)
can be tested without the solvers.

The fields are a cartoon of a shaken layer, not physics: a block of material that flies
ballistically above the plate, lands at f t = 0.12 and carries a temperature shock (a tanh
drop of T) from the plate to the top of the layer between f t = 0.12 and about 0.33. Depth,
restitution and solver shift it a little so that the claims get definite, varied values.

    PYTHONPATH=python:python/tests python3 -m harness.synthetic_runs --shaker SHAKER \
        --workdir DIR --cases a,b [--quick]
"""
import argparse
import json
import math
import os
import tomllib

import h5py
import numpy as np

from granular_shaker.validation.plan import load_studies, plan_runs, resampled_runs, run_key

from . import REPOSITORY


# Collisions each synthetic MD run records in its running totals (see write_run).
SYNTHETIC_COLLISIONS = 200000.0


def plate(config, t):
    gamma, f = config["shaker"]["gamma"], config["shaker"]["frequency"]
    omega = 2 * math.pi * f
    amplitude = gamma / omega ** 2
    return amplitude * (1 - np.cos(omega * t)), amplitude * omega * np.sin(omega * t)


def fields_at(config, solver, phase, z_lab, plate_z, plate_v, rng):
    """nu, u_z, T of the cartoon at one phase on lab heights z_lab."""
    particles = config["layer"]["particles"]
    depth = particles / 3937 * 9.0
    e = config["run"]["switch_e"] if config["run"]["protocol"] == "single_shock" \
        else config["material"]["e"]
    land, leave = 0.12 - 0.01 * (depth - 9) / 4.5, 0.40
    exit_ = 0.34 + (0.01 if solver == "md" else 0.0)
    thickness = depth * 1.3
    apex = 6.0 + 20.0 * (e - 0.8) + 2.0 * (9 - depth) / 4.5
    if land <= phase < leave:
        gap = 0.0
    else:
        s = (phase - leave) % 1.0 / (1.0 - (leave - land))
        gap = apex * math.sin(math.pi * min(s, 1.0))
    bottom = plate_z + gap
    top = bottom + thickness
    z = z_lab
    inside = 0.5 * (np.tanh((z - bottom) / 0.6) - np.tanh((z - top) / 0.8))
    nu = 0.02 * np.exp(-np.maximum(z - top, 0) / 6.0) * (z > bottom) + 0.4 * inside
    uz = np.full_like(z, plate_v - 3.0 if phase < land else plate_v)
    T = 0.01 + 0.02 * np.maximum(z - top, 0)
    if land <= phase < exit_ + 0.06:
        progress = (phase - land) / (exit_ - land)
        shock = bottom + 0.3 + progress * thickness
        width = 2.0 if phase < 0.17 else 0.9
        below = z < shock
        nu = np.where(below & (z > bottom), 0.55 * inside, 0.3 * inside) + nu * (1 - inside)
        uz = np.where(below, plate_v, plate_v - (4.0 + 2.0 * (e - 0.9)) * (1 - 0.5 * progress))
        hot = 1.0 + 0.1 * (z - bottom)
        drop = 0.5 * (1 - np.tanh((z - shock) / (0.5 * width)))
        T = hot * drop + (0.02 + 0.03 * np.maximum(z - shock, 0)) * (1 - drop)
    elif phase < land:
        uz = np.where(z > bottom, plate_v - 3.0 - 8.0 * phase, plate_v)
    if solver == "md":
        nu = nu * (1 + 0.01 * rng.standard_normal(z.shape))
        T = T * (1 + 0.01 * rng.standard_normal(z.shape))
    return np.clip(nu, 0, 0.6), uz, np.maximum(T, 1e-6)


def write_cycle_samples(h, config, out, rng):
    """Per-cycle sums (docs/output-schema.md, cycle_samples) that pool to the profiles within
    1 % noise per cycle: count n V, momentum count u_z, energy count (3 T + u_z^2)."""
    # One sample per sampled cycle of each replica (md.replicas, docs/parallel.md).
    per_replica = (1 if config["run"]["protocol"] == "single_shock"
                   else config["run"]["sampled_cycles"])
    cycles = per_replica * config["md"]["replicas"]
    volume = config["md"]["box_width"] ** 2 * config["md"]["bin_height"]
    n, uz, T = (np.array(out[k], dtype=float) for k in ("n", "uz", "T"))
    count = n[:, None, :] * volume * (1 + 0.01 * rng.standard_normal((n.shape[0], cycles,
                                                                      n.shape[1])))
    sums = {"count": count, "vx": 0 * count, "vy": 0 * count, "vz": count * uz[:, None, :],
            "v2": count * (3 * T + uz ** 2)[:, None, :]}
    g = h.create_group("cycle_samples")
    g.attrs["bin_volume"] = float(volume)
    g.create_dataset("cycles", data=np.ones((n.shape[0], cycles)))
    for name, values in sums.items():
        g.create_dataset(name, data=values.reshape(n.shape[0] * cycles, n.shape[1]))


def write_run(path, config_text, solver, seed):
    config = tomllib.loads(config_text)
    rng = np.random.default_rng(seed)
    K = config["run"]["phases_per_cycle"]
    f = config["shaker"]["frequency"]
    first_cycle = config["run"]["transient_cycles"]
    if solver == "md":
        bin_height, ceiling = config["md"]["bin_height"], config["md"]["ceiling"]
        base = np.arange(bin_height / 2, ceiling, bin_height)
    else:
        bin_height, ceiling = config["continuum"]["cell_size"], config["continuum"]["ceiling"]
        base = np.arange(bin_height / 2, ceiling, bin_height)
    phases = np.arange(K) / K
    times = (first_cycle + phases) / f
    pz, pv = plate(config, times)
    out = {k: [] for k in ("z", "n", "nu", "uz", "T", "n_se", "uz_se", "T_se", "samples")}
    for k, phase in enumerate(phases):
        z = base if solver == "md" else base + pz[k]
        nu, uz, T = fields_at(config, solver, phase, z, pz[k], pv[k], rng)
        n = nu * 6 / math.pi
        out["z"].append(z), out["n"].append(n), out["nu"].append(nu)
        out["uz"].append(uz), out["T"].append(T)
        out["n_se"].append(0.01 * n + 1e-4), out["uz_se"].append(0.02 + 0 * n)
        out["T_se"].append(0.01 * T + 1e-4)
        out["samples"].append(np.round(n * 400 * bin_height * config["run"]["sampled_cycles"]))
    tmp = path + ".partial"
    with h5py.File(tmp, "w") as h:
        h.attrs["schema_version"] = np.int64(1)
        h.attrs["program_version"] = "synthetic"
        h.attrs["git_commit"] = "synthetic"
        h.attrs["created"] = "2000-01-01T00:00:00Z"
        h.attrs["solver"] = "synthetic"
        h.attrs["model_variant"] = f"synthetic {solver}-like cartoon"
        h.attrs["configuration"] = config_text
        h.attrs["restitution_for_analysis"] = float(config["material"]["e"])
        g = h.create_group("profiles")
        for name, values in (("time", times), ("phase", phases), ("plate_z", pz),
                             ("plate_v", pv), ("bin_height", np.full(K, bin_height))):
            g.create_dataset(name, data=np.asarray(values, dtype=float))
        keep = ("z", "n", "nu", "uz", "T") + (("n_se", "uz_se", "T_se", "samples")
                                              if solver == "md" else ())
        for name in keep:
            g.create_dataset(name, data=np.array(out[name], dtype=float))
        if solver == "md":
            write_cycle_samples(h, config, out, rng)
        s = h.create_group("timeseries")
        # One row per stored phase and one at the end of the cycle, as the solvers write them.
        com = [float(np.sum(n * z) / np.sum(n)) for n, z in zip(out["n"], out["z"])]
        columns = ["t", "phase", "plate_z", "com_z"]
        data = {"t": np.append(times, times[0] + 1 / f), "phase": np.append(phases, 0.0),
                "plate_z": np.append(pz, pz[0]), "com_z": com + com[:1]}
        times = data["t"]
        if solver == "md":
            per_cycle = 0.3 if config["layer"]["particles"] > 3000 else 5.0
            data["crossings_z80"] = per_cycle * (times - times[0]) * f
            data["particles_z80"] = 0.8 * per_cycle * (times - times[0]) * f
            data["collisions"] = 240000.0 * (times - times[0]) * f
            # Running totals as a continued run has them (not starting at 0): SYNTHETIC_COLLISIONS
            # collisions in the run, pair + plate.
            data["pair_collisions"] = np.linspace(5000.0, 5000.0 + SYNTHETIC_COLLISIONS - 20000.0,
                                                  len(times))
            data["plate_collisions"] = np.linspace(700.0, 700.0 + 20000.0, len(times))
            data["ceiling_collisions"] = np.full(len(times), 3.0)
            columns += ["crossings_z80", "particles_z80", "collisions", "pair_collisions",
                        "plate_collisions", "ceiling_collisions"]
        s.attrs["columns"] = ",".join(columns)
        for name in columns:
            s.create_dataset(name, data=np.asarray(data[name], dtype=float))
    os.replace(tmp, path)


def write_runs(shaker, workdir, cases, quick):
    """The synthetic run files of `cases` (comma-separated) under workdir/runs."""
    studies = load_studies(os.path.join(REPOSITORY, "validation", "studies.toml"))
    plan = plan_runs(REPOSITORY, studies, cases.split(","), quick)
    if not quick:
        plan += resampled_runs(studies, plan)
    write_plan(shaker, workdir, plan)


def write_plan(shaker, workdir, plan):
    """A synthetic run file for every run of a plan (granular_shaker.validation.plan.plan_runs'
    dicts), under the name the runner reuses."""
    shaker = os.path.abspath(shaker)
    os.makedirs(os.path.join(workdir, "runs"), exist_ok=True)
    for i, run in enumerate(plan):
        text, key = run_key(shaker, run)
        stem = os.path.join(workdir, "runs", f"{run['solver']}-{key[:20]}")
        record = dict(key=key, config=text, seconds=1.0 + i, returncode=0, command="synthetic",
                      stdout="", stderr="")
        if run["expect_failure"]:
            record.update(status="collapse", path=None, returncode=1,
                          stderr="shaker: failed: inelastic collapse at t = 12.5 (synthetic)")
        else:
            write_run(stem + ".h5", text, run["solver"], seed=i)
            record.update(status="ok", path=stem + ".h5")
        with open(stem + ".json", "w") as f:
            json.dump(record, f)
    print(f"wrote {len(plan)} synthetic runs into {workdir}/runs")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--shaker", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--cases", required=True)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    write_runs(args.shaker, args.workdir, args.cases, args.quick)


if __name__ == "__main__":
    main()
