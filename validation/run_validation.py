#!/usr/bin/python3
"""Runs the validation study (MD, continuum, the paper's claims) and writes reports/validation.md.

    validation/run_validation.py --shaker build/release/solvers/app/shaker [--quick]
        [--cases base,depth_h4p5] [--workdir DIR] [--report reports/validation.md]
        [--jobs 2] [--launcher "mpirun -np 8"] [--require C1,C4,C10] [--reuse-only] [--rerun]

Steps (data flows one way: case file -> solver -> run file -> analysis -> claims -> report):
1. every case of validation/studies.toml (or the --cases / --quick subset) is run with each
   solver that the paper used for it. A run is keyed by the SHA-256 of its effective
   configuration (`shaker config CASE --set ...`), so a finished run is reused, never
   re-simulated; --rerun forces new runs. An MD single-shock case is one ensemble of md_pool
   replicas started from consecutive cycles of the periodic state (md.replicas; replica k
   has run.transient_cycles + k), through --launcher (e.g. "mpirun -np 8") if given.
2. every finished run is analysed by `shaker analyze --csv` (the project's one analysis
   implementation), which gives every MD number a jackknife error over the independent
   samples (the replicas of an ensemble, or the sampled cycles of a periodic run).
3. `shaker compare --csv` gives the agreement metrics of every case run by both solvers.
4. every claim of reference-data/claims.toml is evaluated per solver against its band
   (validation/quantities.py), and reports/make_validation_report.py writes the report.

Exit status: 0 when the report is written and every claim named by --require passes in every
solver it applies to; 1 otherwise (a missing solver makes its claims "not measured", which
fails --require). Uses /usr/bin/python3 with numpy, matplotlib and h5py only.
"""
import argparse
import concurrent.futures
import csv
import datetime
import hashlib
import json
import math
import os
import shlex
import subprocess
import sys
import time
import tomllib

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
if __package__:
    from . import phase_sampling, quantities
else:  # run as a script: its folder, validation/, is first on sys.path
    import phase_sampling
    import quantities

SOLVERS = ("md", "continuum")
SOLVER_UNAVAILABLE = 3  # exit code of a solver that is not built yet (README)
PROFILE_FIELDS = ("n", "nu", "uz", "T")


def log(message):
    print(f"[validation] {message}", flush=True)


# ---- configuration files --------------------------------------------------------------------

def load_toml(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def load_studies(path):
    studies = load_toml(path)
    studies["by_name"] = {c["name"]: c for c in studies["case"]}
    return studies


def case_file(name):
    return os.path.join(HERE, "cases", f"{name}.toml")


def effective_config(shaker, name, overrides):
    """`shaker config` text of a case with overrides (exit status 2 -> ValueError)."""
    cmd = [shaker, "config", case_file(name)] + [a for o in overrides for a in ("--set", o)]
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise ValueError(f"{' '.join(cmd)} failed ({result.returncode}): {result.stderr.strip()}")
    return result.stdout


# ---- one run and its views ------------------------------------------------------------------

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


# ---- running the solvers --------------------------------------------------------------------

def plan_runs(shaker, studies, case_names, quick):
    """The list of solver runs: dicts with case, solver, replicas, overrides, timeout,
    fallback and expect_failure. An MD single-shock case is one ensemble of md_pool replicas
    (md.replicas: replica r starts r cycles later in the periodic state, docs/parallel.md)."""
    quick_overrides = studies["quick"]["overrides"] if quick else []
    plan = []
    for name in case_names:
        case = studies["by_name"][name]
        for solver in case["solvers"]:
            pool = case.get("md_pool", 1) if solver == "md" else 1
            if quick:
                pool = min(pool, studies["quick"]["md_pool"])
            overrides = list(quick_overrides) + ([f"md.replicas={pool}"] if pool > 1 else [])
            plan.append(dict(case=name, solver=solver, replicas=pool, overrides=overrides,
                             timeout=case.get("timeout", studies["quick" if quick else
                                                                 "defaults"]["timeout"]),
                             fallback=case.get("md_fallback", []) if solver == "md" else [],
                             expect_failure=case.get("expect_failure", False)))
    return plan


def resampled_runs(studies, plan):
    """The MD runs of studies.toml [sampling], again at its phases per cycle: copies of the
    plan's MD runs of those cases with one more override (marked by `phases`)."""
    sampling = studies.get("sampling", {})
    phases = sampling.get("phases_per_cycle")
    return [dict(r, overrides=r["overrides"] + [f"run.phases_per_cycle={phases}"], phases=phases)
            for r in plan if r["solver"] == "md" and r["case"] in sampling.get("cases", [])]


def phase_sampling_results(shaker, plan, views, workdir):
    """Per resampled case: its shock quantities at the case's own phases per cycle and at the
    finer sampling, compared by validation/phase_sampling.py."""
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


def run_key(shaker, run):
    """The effective configuration and its key: the hash of the values that can change the
    solver's result (not of the text, so that comments and formatting in `shaker config` do
    not invalidate finished runs; and not the other solver's section, so that a key added
    there does not either: the continuum reads only md.box_width of [md])."""
    text = effective_config(shaker, run["case"], run["overrides"])
    values = tomllib.loads(text)
    if run["solver"] == "continuum":
        values["md"] = {"box_width": values["md"]["box_width"]}
    else:
        values.pop("continuum", None)
    canonical = json.dumps(values, sort_keys=True)
    return text, hashlib.sha256(canonical.encode()).hexdigest()


def solver_environment(jobs):
    """The environment of a solver run when `jobs` run at once: the cores are shared out
    (OMP_NUM_THREADS = cores // jobs, at least 1) and idle OpenMP threads sleep instead of
    spinning (OMP_WAIT_POLICY=passive), because spinning threads of one run steal the cores of
    the other (measured: two spinning threads made a 3D cycle slower than one). Values the
    caller set in the environment are kept."""
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", str(max(1, (os.cpu_count() or 1) // max(1, jobs))))
    env.setdefault("OMP_WAIT_POLICY", "passive")
    return env


def execute(shaker, workdir, run, rerun, reuse_only, env=None, launcher=()):
    """Runs (or reuses) one solver run; returns its record (status, path, seconds, ...). An
    ensemble (replicas > 1) is started through `launcher` (e.g. mpirun -np 8) if one is given."""
    text, key = run_key(shaker, run)
    stem = os.path.join(workdir, "runs", f"{run['solver']}-{key[:20]}")
    record_path, output = stem + ".json", stem + ".h5"
    if not rerun and os.path.exists(record_path):
        with open(record_path) as f:
            record = json.load(f)
        if record["status"] in ("ok", "collapse") and (record["status"] != "ok"
                                                       or os.path.exists(output)):
            # The workdir may have moved since: the run file is where the key puts it.
            record.update(reused=True, path=output if record["status"] == "ok" else None)
            return record
    if reuse_only:
        status = "ok" if os.path.exists(output) else "not run"
        return dict(status=status, path=output if status == "ok" else None, seconds=0.0,
                    key=key, config=text, reused=status == "ok", returncode=None,
                    stderr="--reuse-only: no finished run", command="")
    cmd = list(launcher) if run["replicas"] > 1 else []
    cmd += [shaker, run["solver"], case_file(run["case"])]
    cmd += [a for o in run["overrides"] for a in ("--set", o)]
    cmd += ["--set", f"run.output={output}"]
    log(f"run {run['solver']} {run['case']}" + (f" [{run['replicas']} replicas]"
                                                if run["replicas"] > 1 else "")
        + f" -> {os.path.basename(output)}")
    start = time.monotonic()
    try:
        result = subprocess.run(cmd, capture_output=True, text=True, timeout=run["timeout"],
                                env=env)
        rc, stdout, stderr = result.returncode, result.stdout, result.stderr
    except subprocess.TimeoutExpired as expired:
        rc, stdout, stderr = None, str(expired.stdout or ""), str(expired.stderr or "")
    seconds = time.monotonic() - start
    if rc == 0 and os.path.exists(output):
        status = "ok"
    elif rc is None:
        status = f"timed out after {run['timeout']:.0f} s"
    elif rc == SOLVER_UNAVAILABLE:
        status = "unavailable"
    elif rc == 1 and "collapse" in stderr.lower():
        status = "collapse"
    else:
        status = "failed"
    record = dict(status=status, path=output if status == "ok" else None, seconds=seconds,
                  key=key, config=text, returncode=rc, command=" ".join(cmd),
                  stdout=stdout[-3000:], stderr=stderr[-3000:], reused=False)
    if status in ("ok", "collapse"):
        tmp = record_path + ".partial"
        with open(tmp, "w") as f:
            json.dump(record, f, indent=1)
        os.replace(tmp, record_path)
    return record


def execute_all(shaker, workdir, plan, jobs, rerun, reuse_only, launcher=()):
    env = solver_environment(jobs)

    def one(run):
        record = execute(shaker, workdir, run, rerun, reuse_only, env, launcher)
        if record["status"] == "collapse" and run["fallback"] and not run["expect_failure"]:
            guarded = dict(run, overrides=run["overrides"] + run["fallback"])
            record = execute(shaker, workdir, guarded, rerun, reuse_only, env, launcher)
            record["fallback"] = run["fallback"]
        return record

    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        records = list(pool.map(one, plan))
    for run, record in zip(plan, records):
        run["record"] = record
    return plan


# ---- analysis of the runs -------------------------------------------------------------------

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


# ---- claims -----------------------------------------------------------------------------------

def _spread(kind, values):
    values = [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    if len(values) < 2:
        return math.nan
    values = np.array(values, dtype=float)
    if kind == "jackknife":
        n = len(values)
        return float(math.sqrt((n - 1) / n * np.sum((values - values.mean()) ** 2)))
    return float(values.std(ddof=1))


def _as_plain(value):
    if isinstance(value, (quantities.Bound, quantities.Quantized, quantities.Measured)):
        return _as_plain(value.value)
    return value


def _with_rounding(error, value, resolution):
    """The sampling error combined with the rounding error of a quantised value."""
    def one(e, v, r):
        rounding = r / math.sqrt(12.0) if r is not None and quantities.finite(v) else None
        if rounding is None:
            return e
        return rounding if e is None else math.hypot(e, rounding)
    if resolution is None:
        return error
    if isinstance(value, list):
        errors = error if isinstance(error, list) else [None] * len(value)
        return [one(e, v, r) for e, v, r in zip(errors, value, resolution)]
    return one(error, value, resolution)


def measure(quantity, params, cases, solver, views, comparer, partial_cases_ok):
    """Value and uncertainty of one quantity of the given cases in one solver
    ('md_vs_continuum' for pair quantities): dict(value, error, bound, resolution, notes), or
    dict(value=None, status="not measured", reason)."""
    fn = quantities.QUANTITIES[quantity]

    def query(replicate):
        def get_run(case, s):
            view = views.get((case, s))
            if view is None or view.status != "ok" and quantity != "collapse_detected":
                return None
            if replicate is not None and view.replicates:
                return view.replicates[replicate]
            return view
        return quantities.Query(get_run, comparer, solver, cases, params, partial_cases_ok)

    try:
        value = fn(query(None))
    except quantities.NotMeasured as reason:
        missing = [f"{s} {c}: {views[(c, s)].status}" for c in cases
                   for s in SOLVERS if (c, s) in views and views[(c, s)].status != "ok"]
        return dict(value=None, status="not measured", reason=str(reason)
                    + (f" ({'; '.join(missing)})" if missing else ""))
    bound = value.kind if isinstance(value, quantities.Bound) else None
    resolution = value.resolution if isinstance(value, quantities.Quantized) else None
    direct_error = value.error if isinstance(value, quantities.Measured) else None
    value = _as_plain(value)
    # Uncertainty: the same quantity on every replicate of the MD views involved.
    involved = [v for (c, s), v in views.items() if c in cases and v.replicates
                and (solver in (s, "md_vs_continuum"))]
    error = None
    if involved and isinstance(value, (float, list)):
        count = min(len(v.replicates) for v in involved)
        kind = involved[0].replicate_kind
        reps = []
        for b in range(count):
            try:
                reps.append(_as_plain(fn(query(b))))
            except quantities.NotMeasured:
                pass
        if isinstance(value, float):
            error = _spread(kind, reps)
            error = None if math.isnan(error) else error
        elif reps:
            error = [_spread(kind, [r[i] for r in reps if len(r) == len(value)])
                     for i in range(len(value))]
            error = [None if math.isnan(e) else e for e in error]
    if error is None and quantities.finite(direct_error):
        error = direct_error
    notes = sorted({n for (c, s), v in views.items() if c in cases
                    and solver in (s, "md_vs_continuum") for n in v.notes})
    return dict(value=value, error=_with_rounding(error, value, resolution), bound=bound,
                notes=notes)


def evaluate(check_spec, claim, solver, views, comparer, partial_cases_ok):
    """Value, uncertainty and verdict of one check of a claim in one solver: pass (inside the
    band by more than DECISION_ERRORS standard errors), fail (outside by more), unresolved
    (in between: the data cannot decide), inconclusive (a bound that cannot decide) or not
    measured."""
    m = measure(check_spec["quantity"], check_spec.get("parameters", {}), claim["cases"], solver,
                views, comparer, partial_cases_ok)
    if m.get("status") == "not measured":
        return m
    value, error, bound = m["value"], m["error"], m["bound"]
    passed = quantities.check(check_spec["comparison"], check_spec["band"], value)
    inside = quantities.margin(check_spec["comparison"], check_spec["band"], value, error)
    status = quantities.verdict(inside)
    if bound == "lower" and check_spec["comparison"] == "less_than" and passed:
        status = "inconclusive"
    if bound == "lower" and check_spec["comparison"] == "greater_than" and not passed:
        status = "inconclusive"
    return dict(m, status=status, margin=inside)


# A claim's status is the worst of its checks' statuses, in this order.
STATUS_ORDER = ["fail", "not measured", "unresolved", "inconclusive", "pass"]


def worst_status(statuses):
    statuses = list(statuses)
    return next((s for s in STATUS_ORDER if s in statuses), "pass")


def evaluate_claims(claims, views, comparer, partial_cases_ok):
    results = []
    for claim in claims:
        solvers = (["md", "continuum"] if claim["solvers"] == "both" else [claim["solvers"]])
        checks = [dict(quantity=claim["quantity"], parameters=claim.get("parameters", {}),
                       comparison=claim["comparison"], band=claim["band"])]
        checks += claim.get("also", [])
        # The report shows each check's units beside its values and band.
        checks = [dict(c, units=quantities.UNITS[c["quantity"]]) for c in checks]
        per_solver = {}
        for solver in solvers:
            evaluations = [evaluate(c, claim, solver, views, comparer, partial_cases_ok)
                           for c in checks]
            per_solver[solver] = dict(status=worst_status(e["status"] for e in evaluations),
                                      checks=evaluations)
        overall = worst_status(s["status"] for s in per_solver.values())
        results.append(dict(claim, checks=checks, per_solver=per_solver, status=overall))
    return results


# ---- diagnoses of failing claims ----------------------------------------------------------

CATEGORIES = {"a": "the continuum and MD really differ",
              "b": "MD does not reproduce the paper's statement",
              "c": "a defect of the project still to find or fix",
              "d": "the continuum's equations give it, whatever the numerical choices"}


def validate_diagnoses(diagnoses, claims, studies):
    """Problems of validation/diagnoses.toml: a claim id (or 'Fig. N') the claims file has, a
    category a/b/c, a reason, and evidence of known quantities with the parameters they need,
    on cases validation/studies.toml runs with the solvers named."""
    errors = []
    ids = {c["id"] for c in claims}
    runs = {c["name"]: set(c["solvers"]) for c in studies["case"]}
    for d in diagnoses:
        where = f"diagnosis of {d.get('claim')}"
        if d.get("claim") not in ids and not str(d.get("claim", "")).startswith("Fig. "):
            errors.append(f"{where}: no such claim (allowed: C1 .. C20 or 'Fig. N')")
        if d.get("category") not in CATEGORIES:
            errors.append(f"{where}: category must be one of {', '.join(CATEGORIES)}")
        if not str(d.get("reason", "")).strip():
            errors.append(f"{where}: no reason")
        for item in d.get("evidence", []):
            q = item.get("quantity")
            if q not in quantities.QUANTITIES:
                errors.append(f"{where}: unknown quantity {q!r}")
                continue
            missing = [n for n in quantities.REQUIRED_PARAMETERS.get(q, ())
                       if n not in item.get("parameters", {})]
            if missing:
                errors.append(f"{where}: quantity {q!r} needs parameter(s) {missing}")
            solvers = {s for s in item.get("solvers", SOLVERS) if s != "md_vs_continuum"}
            for case in item.get("cases", []):
                if case not in runs:
                    errors.append(f"{where}: case {case!r} is not in validation/studies.toml")
                elif "solvers" in item and not solvers <= runs[case]:
                    errors.append(f"{where}: case {case!r} is not run with "
                                  f"{sorted(solvers - runs[case])}")
            if not item.get("cases"):
                errors.append(f"{where}: evidence {item.get('label')!r} names no case")
    return errors


def load_diagnoses(path, claims, studies):
    """validation/diagnoses.toml; raises ValueError naming every problem."""
    diagnoses = load_toml(path).get("diagnosis", [])
    errors = validate_diagnoses(diagnoses, claims, studies)
    if errors:
        raise ValueError(f"{path}: " + "; ".join(errors))
    return diagnoses


def evidence_solvers(item, views):
    if "solvers" in item:
        return item["solvers"]
    return [s for s in SOLVERS if any((c, s) in views for c in item["cases"])]


def diagnose(diagnoses, results, views, comparer, partial_cases_ok):
    """Measures the evidence of every diagnosis and ties it to its claim's status: a
    diagnosis of a claim that no longer fails is marked stale; a failing claim without one is
    listed as undiagnosed."""
    status = {c["id"]: c["status"] for c in results}
    out = []
    for d in diagnoses:
        evidence = []
        for item in d.get("evidence", []):
            measured = {s: measure(item["quantity"], item.get("parameters", {}), item["cases"], s,
                                   views, comparer, partial_cases_ok)
                        for s in evidence_solvers(item, views)}
            evidence.append(dict(label=item["label"], quantity=item["quantity"],
                                 units=quantities.UNITS[item["quantity"]], measured=measured))
        claim_status = status.get(d["claim"])
        out.append(dict(d, evidence=evidence, claim_status=claim_status,
                        stale=claim_status is not None and claim_status != "fail"))
    diagnosed = {d["claim"] for d in diagnoses}
    undiagnosed = [c["id"] for c in results if c["status"] == "fail" and c["id"] not in diagnosed]
    return out, undiagnosed


# ---- main ------------------------------------------------------------------------------------

def git(*args):
    result = subprocess.run(["git", "-C", ROOT] + list(args), capture_output=True, text=True)
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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--shaker", required=True, help="path of the shaker program")
    parser.add_argument("--quick", action="store_true",
                        help="reduced cycles and resolution, base case only (the ctest subset)")
    parser.add_argument("--cases", help="comma-separated subset of validation/studies.toml")
    parser.add_argument("--workdir", default=os.path.join(HERE, "work"),
                        help="where runs, analyses and derived files go (reused across calls)")
    parser.add_argument("--report", default=os.path.join(ROOT, "reports", "validation.md"))
    parser.add_argument("--claims", default=os.path.join(ROOT, "reference-data", "claims.toml"))
    parser.add_argument("--gci", help="GCI table of the base-case grid study (continuum "
                                      "uncertainty; default: the report generator's)")
    parser.add_argument("--studies", default=os.path.join(HERE, "studies.toml"))
    parser.add_argument("--diagnoses", default=os.path.join(HERE, "diagnoses.toml"))
    parser.add_argument("--jobs", type=int, default=2, help="solver runs at once")
    parser.add_argument("--launcher", default="",
                        help="how MD ensembles (md_pool cases) are started, e.g. "
                        "\"mpirun -np 8\" (default: in one process)")
    parser.add_argument("--require", default="",
                        help="comma-separated claim ids that must pass (else exit status 1); "
                        "ID:SOLVER requires only that solver's check (e.g. C1:md)")
    parser.add_argument("--require-not-failing", default="",
                        help="like --require, but 'unresolved' (within 2 standard errors of "
                        "the band) is accepted too: what a study with few samples can show")
    parser.add_argument("--rerun", action="store_true", help="ignore finished runs")
    parser.add_argument("--reuse-only", action="store_true",
                        help="never start a solver; use finished runs in --workdir only")
    args = parser.parse_args(argv)

    shaker = os.path.abspath(args.shaker)
    workdir = os.path.abspath(args.workdir)
    os.makedirs(os.path.join(workdir, "runs"), exist_ok=True)
    studies = load_studies(args.studies)
    claims = load_toml(args.claims)["claim"]
    try:
        diagnoses = load_diagnoses(args.diagnoses, claims, studies)
    except ValueError as error:
        parser.error(str(error))
    if args.cases:
        names = [c.strip() for c in args.cases.split(",") if c.strip()]
    elif args.quick:
        names = list(studies["quick"]["cases"])
    else:
        names = [c["name"] for c in studies["case"]]
    unknown = [n for n in names if n not in studies["by_name"]]
    if unknown:
        parser.error(f"unknown case(s) {', '.join(unknown)}; known: "
                     + ", ".join(studies["by_name"]))

    started = time.monotonic()
    plan = plan_runs(shaker, studies, names, args.quick)
    if not args.quick:
        plan += resampled_runs(studies, plan)
    plan = execute_all(shaker, workdir, plan, args.jobs,
                       args.rerun, args.reuse_only, shlex.split(args.launcher))
    views = {}
    for name in names:
        for solver in studies["by_name"][name]["solvers"]:
            record = next(r["record"] for r in plan
                          if r["case"] == name and r["solver"] == solver and not r.get("phases"))
            views[(name, solver)] = build_view(shaker, name, solver, record, workdir)
    comparer = Comparer(shaker, os.path.join(workdir, "derived"))
    metrics = {}
    for name in names:
        md, co = views.get((name, "md")), views.get((name, "continuum"))
        if md and co and md.status == "ok" and co.status == "ok":
            try:
                metrics[name] = comparer(co, md)
            except quantities.NotMeasured as reason:
                metrics[name] = {"error": str(reason)}
    partial = bool(args.cases) or args.quick
    results = evaluate_claims(claims, views, comparer, partial)
    diagnosed, undiagnosed = diagnose(diagnoses, results, views, comparer, partial)

    sampling = phase_sampling_results(shaker, plan, views, workdir)
    runs = [dict(case=r["case"], solver=r["solver"], replicas=r["replicas"],
                 phases_per_cycle=r.get("phases"),
                 status=r["record"]["status"], seconds=r["record"]["seconds"],
                 reused=r["record"].get("reused", False), path=r["record"].get("path"),
                 fallback=r["record"].get("fallback"), program=run_program(r["record"]),
                 stderr=r["record"].get("stderr", "")[-600:]) for r in plan]
    summary = dict(
        commit=git("rev-parse", "HEAD"),
        # reports/ is where this study writes: its own outputs do not make the commit dirty
        dirty=bool(git("status", "--porcelain", "--", ".", ":(exclude)reports")),
        date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        quick=args.quick, cases=names, shaker=shaker,
        shaker_version=subprocess.run([shaker, "--version"], capture_output=True,
                                      text=True).stdout.strip(),
        wall_seconds=time.monotonic() - started,
        simulated_seconds=sum(r["seconds"] for r in runs if not r["reused"]),
        runs=runs, metrics=metrics, claims=results, diagnoses=diagnosed, sampling=sampling,
        metric_units={name: comparer.units[name] for m in metrics.values() for name in m},
        undiagnosed=undiagnosed,
        views={f"{c}/{s}": dict(case=c, solver=s, status=v.status, path=v.path,
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
               for (c, s), v in views.items()})
    results_path = os.path.join(workdir, "results.json")
    with open(results_path + ".partial", "w") as f:
        json.dump(plain(summary), f, indent=1)
    os.replace(results_path + ".partial", results_path)

    report = subprocess.run([sys.executable, os.path.join(ROOT, "reports",
                                                          "make_validation_report.py"),
                             "--results", results_path, "--output", args.report]
                            + (["--gci", args.gci] if args.gci else []))
    if report.returncode != 0:
        log("the report generator failed")
        return 1
    failing = required_not_passing(results, args.require, {"pass"})
    failing += required_not_passing(results, args.require_not_failing, {"pass", "unresolved"})
    for c in results:
        log(f"{c['id']}: {c['status']}  " + "; ".join(
            f"{s}: {r['status']} {_format_value(r['checks'][0].get('value'))}"
            for s, r in c["per_solver"].items()))
    if failing:
        log("required claims not passing: " + ", ".join(failing))
        return 1
    return 0


def required_not_passing(results, require, accepted):
    """The entries of a requirement list (ID, or ID:SOLVER for one solver's check of a claim,
    e.g. C1:md) whose status is not among `accepted`, as 'ID (status)' strings; an unknown
    entry counts as failing."""
    failing = []
    for entry in (e.strip() for e in require.split(",") if e.strip()):
        claim_id, _, solver = entry.partition(":")
        claim = next((c for c in results if c["id"] == claim_id), None)
        if claim is None:
            failing.append(f"{entry} (no such claim)")
        elif not solver:
            if claim["status"] not in accepted:
                failing.append(f"{entry} ({claim['status']})")
        elif solver not in claim["per_solver"]:
            failing.append(f"{entry} (not checked for {solver})")
        elif claim["per_solver"][solver]["status"] not in accepted:
            failing.append(f"{entry} ({claim['per_solver'][solver]['status']})")
    return failing


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


def _format_value(value):
    if isinstance(value, list):
        return "[" + ", ".join("nan" if v is None or math.isnan(v) else f"{v:.4g}"
                               for v in value) + "]"
    if isinstance(value, float):
        return f"{value:.4g}"
    return "-"


if __name__ == "__main__":
    sys.exit(main())
