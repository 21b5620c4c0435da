"""What a study writes: results.json (the runs, views, claims, diagnoses and metrics the report
generator reads), with the provenance of the runs (the commit of the program that wrote each
run file) and MD's collision rates."""
import datetime
import json
import math
import os
import subprocess
import time

import h5py
import numpy as np

from granular_shaker.validation import phase_sampling
from granular_shaker.validation.views import build_view


def phase_sampling_results(shaker, plan, views, workdir):
    """Per resampled case: its shock quantities at the case's own phases per cycle and at the
    finer sampling, compared by phase_sampling.py."""
    out = []
    for r in plan:
        if not r.get("phases"):
            continue
        coarse = views[(r["case"], "md")]
        fine = build_view(shaker, r["case"], "md", r["record"], workdir)
        entry = dict(case=r["case"], phases=[coarse.config.get("run", {}).get("phases_per_cycle"),
                                             r["phases"]],
                     status=fine.status if coarse.status == "ok" else coarse.status,
                     agreement=phase_sampling.AGREEMENT)
        if entry["status"] == "ok":
            entry["rows"] = phase_sampling.compare(*[
                {k: (v.per_run.get(k), v.per_run_errors.get(k))
                 for k in phase_sampling.SHOCK_QUANTITIES} for v in (coarse, fine)])
        out.append(entry)
    return out


def git(repository, *args):
    """The output of a git command in the repository, or 'unknown' where git fails."""
    result = subprocess.run(["git", "-C", repository] + list(args), capture_output=True,
                            text=True)
    return result.stdout.strip() if result.returncode == 0 else "unknown"


def run_program(record):
    """The commit of the program that wrote a run file (its git_commit attribute): a reused
    run may come from an earlier build than the one making the report."""
    if record.get("status") != "ok" or not record.get("path") or not os.path.exists(record["path"]):
        return None
    with h5py.File(record["path"], "r") as f:
        commit = f.attrs.get("git_commit")
    return commit.decode() if isinstance(commit, bytes) else commit


COLLISION_COUNTS = ("pair_collisions", "plate_collisions", "ceiling_collisions")


def run_collisions(path):
    """Collisions an MD run file records for its own run: its running totals (continued across
    checkpoints) at the last series row minus those at the first, the run's start."""
    with h5py.File(path, "r") as f:
        series = f["timeseries"]
        if any(name not in series for name in COLLISION_COUNTS):
            return None
        return int(sum(series[name][-1] - series[name][0] for name in COLLISION_COUNTS))


def collisions_per_second(view):
    """Collisions per second of wall time of an MD case: the collisions its run files record,
    summed over a pool's runs, over their summed wall time (kept in each run's record, so a
    reused run reports the rate it was run at)."""
    if view.solver != "md" or view.status != "ok" or not view.runs:
        return None
    runs = [r for r in view.runs if r["status"] == "ok"]
    counts = [run_collisions(r["path"]) if r.get("path") and os.path.exists(r["path"]) else None
              for r in runs]
    seconds = sum(r["seconds"] for r in runs)
    if not runs or None in counts or seconds <= 0:
        return None
    return sum(counts) / seconds


def plain(x):
    """JSON-ready copy: NaN -> None, numpy scalars -> Python numbers."""
    if isinstance(x, dict):
        return {str(k): plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return None if math.isnan(x) else float(x)
    if isinstance(x, np.integer):
        return int(x)
    return x


def write_json_atomically(path, data):
    """`data` as JSON (plain: NaN as null) under `path`, renamed into place when complete."""
    with open(path + ".partial", "w") as f:
        json.dump(plain(data), f, indent=1)
    os.replace(path + ".partial", path)


def run_entries(plan):
    """Every planned run as results.json lists it."""
    return [dict(case=r["case"], solver=r["solver"], replicas=r["replicas"],
                 phases_per_cycle=r.get("phases"),
                 status=r["record"]["status"], seconds=r["record"]["seconds"],
                 reused=r["record"].get("reused", False), path=r["record"].get("path"),
                 fallback=r["record"].get("fallback"), program=run_program(r["record"]),
                 stderr=r["record"].get("stderr", "")[-600:]) for r in plan]


def view_entries(views):
    """Every case's view in every solver as results.json lists it."""
    return {f"{c}/{s}": dict(case=c, solver=s, status=v.status, path=v.path,
                             analysis_json=getattr(v, "analysis_json", None),
                             shock_speed=v.shock_speed,
                             shock_speed_error=v.per_run_errors.get("shock_speed"),
                             replicate_kind=v.replicate_kind, replicates=len(v.replicates),
                             switch_e=v.config.get("run", {}).get("switch_e"),
                             continuum_cell_size=v.config.get("continuum", {}).get(
                                 "cell_size") if s == "continuum" else None,
                             protocol=v.config.get("run", {}).get("protocol"),
                             collisions_per_second=collisions_per_second(v),
                             notes=sorted(v.notes))
            for (c, s), v in views.items()}


def study_summary(repository, shaker, plan, views, started, outcome):
    """results.json of a study: its provenance (commit, program, times), the runs and views,
    and `outcome` (quick, cases, metrics, claims, diagnoses, sampling, metric_units,
    undiagnosed)."""
    runs = run_entries(plan)
    provenance = dict(
        commit=git(repository, "rev-parse", "HEAD"),
        # reports/ is where this study writes: its own outputs do not make the commit dirty
        dirty=bool(git(repository, "status", "--porcelain", "--", ".", ":(exclude)reports")),
        date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        quick=outcome["quick"], cases=outcome["cases"], shaker=shaker,
        shaker_version=subprocess.run([shaker, "--version"], capture_output=True,
                                      text=True).stdout.strip(),
        wall_seconds=time.monotonic() - started,
        simulated_seconds=sum(r["seconds"] for r in runs if not r["reused"]))
    return dict(provenance, runs=runs, metrics=outcome["metrics"], claims=outcome["claims"],
                diagnoses=outcome["diagnoses"], sampling=outcome["sampling"],
                metric_units=outcome["metric_units"], undiagnosed=outcome["undiagnosed"],
                views=view_entries(views))
