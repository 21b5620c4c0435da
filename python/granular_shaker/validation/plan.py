"""The plan of the validation study: its configuration files (validation/studies.toml, the case
files of validation/cases/) and the solver runs they ask for, each keyed by its effective
configuration (`shaker config CASE --set ...`)."""
import hashlib
import json
import os
import subprocess
import tomllib

SOLVERS = ("md", "continuum")


def load_toml(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def load_studies(path):
    studies = load_toml(path)
    studies["by_name"] = {c["name"]: c for c in studies["case"]}
    return studies


def case_file(repository, name):
    """The case file of a case of validation/studies.toml."""
    return os.path.join(repository, "validation", "cases", f"{name}.toml")


def effective_config(shaker, case_path, overrides):
    """`shaker config` text of a case file with overrides (exit status 2 -> ValueError)."""
    cmd = [shaker, "config", case_path] + [a for o in overrides for a in ("--set", o)]
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise ValueError(f"{' '.join(cmd)} failed ({result.returncode}): {result.stderr.strip()}")
    return result.stdout


def plan_runs(repository, studies, case_names, quick):
    """The list of solver runs: dicts with case, case_file (in `repository`), solver, replicas,
    overrides, timeout, fallback and expect_failure. An MD single-shock case is one ensemble
    of md_pool replicas (md.replicas: replica r starts r cycles later in the periodic state,
    docs/parallel.md)."""
    quick_overrides = studies["quick"]["overrides"] if quick else []
    plan = []
    for name in case_names:
        case = studies["by_name"][name]
        for solver in case["solvers"]:
            pool = case.get("md_pool", 1) if solver == "md" else 1
            if quick:
                pool = min(pool, studies["quick"]["md_pool"])
            overrides = list(quick_overrides) + ([f"md.replicas={pool}"] if pool > 1 else [])
            plan.append(dict(case=name, case_file=case_file(repository, name), solver=solver,
                             replicas=pool, overrides=overrides,
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


# Keys added to the program after runs were first keyed, each with the value that reproduces
# the program as it was before the key existed (bit for bit): at that value the key is left out
# of the hash, so that runs finished before it stay reusable. A new key with such a neutral
# default is added here.
NEUTRAL_VALUES = {("md", "box_depth"): 0.0, ("md", "initial_perturbation"): 0.0,
                  ("continuum", "box_depth"): 0.0}


def run_key(shaker, run):
    """The effective configuration and its key: the hash of the values that can change the
    solver's result (not of the text, so that comments and formatting in `shaker config` do
    not invalidate finished runs; and not the other solver's section, so that a key added
    there does not either: the continuum reads only md.box_width and md.box_depth of [md]; nor
    keys at their NEUTRAL_VALUES)."""
    text = effective_config(shaker, run["case_file"], run["overrides"])
    values = tomllib.loads(text)
    if run["solver"] == "continuum":
        values["md"] = {k: values["md"][k] for k in ("box_width", "box_depth") if k in values["md"]}
    else:
        values.pop("continuum", None)
    for (section, key), neutral in NEUTRAL_VALUES.items():
        if values.get(section, {}).get(key) == neutral:
            del values[section][key]
    canonical = json.dumps(values, sort_keys=True)
    return text, hashlib.sha256(canonical.encode()).hexdigest()
