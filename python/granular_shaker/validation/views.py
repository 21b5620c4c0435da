"""The views of finished runs: what `shaker analyze --json` gives for a case in one solver,
with the jackknife replicates over its samples, and `shaker compare` of a pair of runs."""
import csv
import hashlib
import json
import math
import os
import subprocess
import tomllib

import h5py
import numpy as np

from granular_shaker.validation import quantities


class RunView:
    """One solver's result for a case (a run, a pool of runs, or a jackknife replicate of
    either) as the quantities see it: what `shaker analyze --json` printed for it."""

    def __init__(self, case, solver, status, path=None, config=None):
        self.case, self.solver, self.status, self.path = case, solver, status, path
        self.config = config or {}
        self.analysis, self.errors = None, {}      # per-phase columns and their errors
        self.per_run, self.per_run_errors = {}, {}  # per-run quantities and their errors
        self.resolution, self.per_run_resolution = {}, {}  # grid steps of quantised values
        self.crossings = {}                       # column -> (per cycle, error)
        self.replicates, self.replicate_kind = [], None
        self.parent, self.replicate_index = None, None
        self.notes, self.runs = set(), []
        self.stderr_tail = ""
        self._profiles = None

    @property
    def shock_speed(self):
        return self.per_run.get("shock_speed", math.nan)

    @property
    def switch_e(self):
        return float(self.config["run"]["switch_e"])

    def profiles(self):
        if self._profiles is None:
            with h5py.File(self.path, "r") as f:
                self._profiles = {k: np.array(f["profiles"][k]) for k in f["profiles"]}
        return self._profiles

    def per_cycle_count(self, column):
        """A count per cycle that the solver records (time-series column crossings_z<h>:
        upward crossings of z = h; particles_z<h>: distinct particles at or above h), averaged
        over the cycles by `shaker analyze`: (mean, between-cycle standard error)."""
        if column not in self.crossings:
            raise quantities.NotMeasured(f"the run has no time-series column {column}")
        return self.crossings[column]


def _number(x):
    return math.nan if x is None else float(x)


def _array(values):
    return np.array([_number(v) for v in values], dtype=float)


def analyze(shaker, run_file, json_path):
    """`shaker analyze RUN --json`: the analysis of docs/analysis.md of one run, with jackknife
    errors and replicates over its samples (and its profiles as CSV beside it): the parsed
    JSON."""
    cmd = [shaker, "analyze", run_file, "--json", json_path, "--quiet",
           "--profiles-csv", run_file + ".profiles.csv"]
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"shaker analyze {run_file}: {result.stderr.strip()}")
    with open(json_path) as f:
        data = json.load(f)
    return data


def fill_view(view, data):
    """Puts `shaker analyze --json` output into a view and builds its jackknife replicates."""
    view.analysis = {k: _array(v["value"]) for k, v in data["per_phase"].items()}
    view.errors = {k: _array(v["error"]) for k, v in data["per_phase"].items()}
    view.per_run = {k: _number(v["value"]) for k, v in data["per_run"].items()}
    view.per_run_errors = {k: _number(v["error"]) for k, v in data["per_run"].items()}
    view.resolution = {k: v["resolution"] for k, v in data["per_phase"].items()
                       if v.get("resolution") is not None}
    view.per_run_resolution = {k: v["resolution"] for k, v in data["per_run"].items()
                               if v.get("resolution") is not None}
    view.crossings = {k: (_number(v["value"]), _number(v["error"]))
                      for k, v in data["crossings"].items()}
    count = data["samples"] if data["samples"] >= 2 else 0
    view.replicate_kind = "jackknife" if count else None
    view.replicates = []
    for i in range(count):
        rep = RunView(view.case, view.solver, "ok", None, view.config)
        rep.parent, rep.replicate_index = view, i
        rep.analysis = {k: _array(v["replicates"][i]) for k, v in data["per_phase"].items()}
        rep.per_run = {k: _number(v["replicates"][i]) for k, v in data["per_run"].items()}
        rep.resolution, rep.per_run_resolution = view.resolution, view.per_run_resolution
        rep.crossings = {k: (_number(v["replicates"][i]) if len(v.get("replicates", [])) == count
                             else math.nan, math.nan) for k, v in data["crossings"].items()}
        view.replicates.append(rep)


class Comparer:
    """`shaker compare --csv A B`, cached per pair of files; a replicate view gets the
    matching jackknife replicate of the comparison; `units` collects each metric's units as
    the CSV gives them."""

    def __init__(self, shaker, directory):
        self.shaker, self.directory, self.cache, self.units = shaker, directory, {}, {}

    def __call__(self, a, b):
        index = a.replicate_index if a.replicate_index is not None else b.replicate_index
        a, b = a.parent or a, b.parent or b
        key = (a.path, b.path)
        if key not in self.cache:
            name = hashlib.sha256(f"{a.path}|{b.path}".encode()).hexdigest()[:16]
            out = os.path.join(self.directory, f"compare-{name}.csv")
            result = subprocess.run([self.shaker, "compare", a.path, b.path, "--csv", out],
                                    capture_output=True, text=True)
            if result.returncode != 0:
                raise quantities.NotMeasured(f"shaker compare failed: {result.stderr.strip()}")
            with open(out) as f:
                self.cache[key] = list(csv.DictReader(f))
            self.units.update({r["metric"]: r["units"] for r in self.cache[key]})
        rows = self.cache[key]
        if index is None:
            return {r["metric"]: float(r["value"]) for r in rows}
        replicates = {r["metric"]: r["replicates"].split(";") for r in rows}
        if any(index >= len(v) for v in replicates.values()):
            raise quantities.NotMeasured("no such replicate of the comparison")
        return {m: float(v[index]) for m, v in replicates.items()}


def build_view(shaker, case, solver, record, workdir):
    """The view of one case in one solver, as `shaker analyze` sees its run file; MD views
    carry the jackknife replicates over their samples (sampled cycles of a run, or the
    replicas of an ensemble)."""
    config = tomllib.loads(record["config"]) if record.get("config") else {}
    if record["status"] != "ok":
        view = RunView(case, solver, record["status"], config=config)
        view.runs = [record]
        view.stderr_tail = record.get("stderr", "").strip()[-300:]
        return view
    derived = os.path.join(workdir, "derived")
    os.makedirs(derived, exist_ok=True)
    view = RunView(case, solver, "ok", record["path"], config)
    view.analysis_json = os.path.join(derived, f"analysis-{solver}-{record['key'][:20]}.json")
    fill_view(view, analyze(shaker, record["path"], view.analysis_json))
    if record.get("fallback"):
        view.notes.add("the MD run stopped by inelastic collapse and was rerun with "
                       + ", ".join(record["fallback"]))
    view.runs = [record]
    return view
